// Implicit shapes to world-space meshes: see shape_mesh.h.
#include "renderer/scene/shape_mesh.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace penumbra {

namespace {

bool selected(const Instance& inst, const ShapeMeshConfig& config) {
  return inst.shape >= 0 && (config.node < 0 || inst.node == config.node);
}

std::invalid_argument too_large(const SceneShape& s, int resolution, uint64_t needed, uint64_t left) {
  return std::invalid_argument(s.name + ": meshing at resolution " + std::to_string(resolution) + " needs " +
                               std::to_string(needed) + " bytes, more than the " + std::to_string(left) +
                               " bytes left of the memory budget");
}

uint64_t saturating_add(uint64_t a, uint64_t b) {
  return b > UINT64_MAX - a ? UINT64_MAX : a + b;
}

// The instance's mesh of the shape, moved into the world (remembering the shape's frame).
Mesh place(IsosurfaceMesh&& iso, const SceneShape& s, const Instance& inst) {
  Mesh m;
  m.name = s.name;
  m.material = s.material;
  m.node = inst.node;
  m.positions = std::move(iso.positions);
  m.normals = std::move(iso.normals);
  m.indices = std::move(iso.indices);
  if (!inst.identity) {
    for (Vec3f& p : m.positions) p = apply_point(inst.to_world, p);
    for (Vec3f& n : m.normals) n = normalize(apply_normal(inst.to_object, n));
    m.object_from_world = inst.to_object;  // object-space procedural textures keep the shape's frame
  }
  if (inst.mirrored)
    for (size_t t = 0; t < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
  return m;
}

}  // namespace

ShapeMeshes mesh_implicit_shapes(const Scene& scene, const ShapeMeshConfig& config) {
  // Before anything is allocated: every selected shape's grid and mesh estimate fits, and so do
  // the mesh estimates of all placements together with the largest grid (grids are freed after
  // each placement, meshes are kept).
  std::vector<uint64_t> shape_bytes(scene.shapes.size()), shape_placements(scene.shapes.size());
  uint64_t meshes = 0, largest_work = 0;
  for (const Instance& inst : scene.instances) {
    if (!selected(inst, config)) continue;
    const SceneShape& s = scene.shapes[size_t(inst.shape)];
    if (s.shape.kind != ShapeKind::Implicit) continue;
    if (s.shape.sdf_bounds.empty())
      throw std::invalid_argument(s.name + ": the implicit shape is unbounded and cannot be meshed");
    const uint64_t bytes = marching_cubes_bytes(s.shape.sdf_bounds, config.resolution, config.marching_cubes);
    if (bytes > config.max_bytes) throw too_large(s, config.resolution, bytes, config.max_bytes);
    const uint64_t work =
        marching_cubes_work_bytes(s.shape.sdf_bounds, config.resolution, config.marching_cubes);
    largest_work = std::max(largest_work, work);
    meshes = saturating_add(meshes, bytes - work);
    shape_bytes[size_t(inst.shape)] = saturating_add(shape_bytes[size_t(inst.shape)], bytes - work);
    ++shape_placements[size_t(inst.shape)];
  }
  const uint64_t total = saturating_add(meshes, largest_work);
  if (total > config.max_bytes) {
    const size_t most =
        size_t(std::max_element(shape_bytes.begin(), shape_bytes.end()) - shape_bytes.begin());
    throw std::invalid_argument(scene.shapes[most].name + ": meshing its " +
                                std::to_string(shape_placements[most]) + " placements at resolution " +
                                std::to_string(config.resolution) + " needs " + std::to_string(total) +
                                " bytes with every selected shape, more than the " +
                                std::to_string(config.max_bytes) + " bytes left of the memory budget");
  }
  ShapeMeshes out;
  out.scene.materials = scene.materials;
  uint64_t used = 0;  // the meshes made so far
  for (const Instance& inst : scene.instances) {
    if (!selected(inst, config)) continue;
    const SceneShape& s = scene.shapes[size_t(inst.shape)];
    if (s.shape.kind != ShapeKind::Implicit) {
      ++out.skipped_analytic;
      continue;
    }
    const Bounds3f& box = s.shape.sdf_bounds;
    const uint64_t bytes = marching_cubes_bytes(box, config.resolution, config.marching_cubes);
    const uint64_t left = config.max_bytes - used;
    if (bytes > left) throw too_large(s, config.resolution, bytes, left);
    MarchingCubesConfig mc = config.marching_cubes;
    mc.max_output_bytes =
        std::min(mc.max_output_bytes, left - marching_cubes_work_bytes(box, config.resolution, mc));
    IsosurfaceMesh iso;
    try {
      iso = extract_isosurface(s.shape.sdf, box, config.resolution, mc);
    } catch (const std::length_error& e) {
      throw std::invalid_argument(s.name + ": " + e.what() + " (memory budget)");
    }
    used += mesh_bytes(iso.positions.size(), iso.indices.size() / 3);
    add_world_mesh(out.scene, place(std::move(iso), s, inst));
  }
  return out;
}

}  // namespace penumbra
