// Scene helpers: instances, bounds, counts, world triangles, normals and tangents.
#include "renderer/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "renderer/core/geometry.h"

namespace penumbra {

namespace {

// `inst` placed by to_world: the inverse, identity and mirroring flags filled in. Throws
// std::invalid_argument naming `what` if the map is singular or not finite.
Instance placed(Instance inst, const Affine3f& to_world, int node, const std::string& what) {
  inst.node = node;
  inst.to_world = to_world;
  inst.identity = is_identity(to_world);
  if (!inverse(to_world, inst.to_object))
    throw std::invalid_argument("instance of " + what + ": transform is singular or not finite");
  inst.mirrored = determinant3x3(to_transform(to_world)) < 0;
  return inst;
}

}  // namespace

const Instance& instance_at(const Scene& scene, uint32_t index, float time, Instance& storage) {
  const Instance& inst = scene.instances[index];
  if (index >= scene.instance_motion.size() || scene.instance_motion[index].empty()) return inst;
  storage = inst;
  storage.identity = false;  // moving: mapped at every time, whatever its frame's map
  storage.to_world = interpolate_motion(scene.instance_motion[index], time);
  if (!inverse(storage.to_world, storage.to_object)) storage.to_object = inst.to_object;
  return storage;
}

const Light& light_at(const Scene& scene, size_t index, float time, Light& storage) {
  const Light& light = scene.lights[index];
  if (index >= scene.light_motion.size() || scene.light_motion[index].size() < 2) return light;
  const std::vector<Light>& keys = scene.light_motion[index];
  const MotionSegment s = motion_segment(time, uint32_t(keys.size()));
  const Light &a = keys[s.k], &b = keys[s.k + 1];
  const float wa = 1.0f - s.a, wb = s.a;
  storage = a;
  storage.position = a.position * wa + b.position * wb;
  storage.color = a.color * wa + b.color * wb;
  storage.intensity = a.intensity * wa + b.intensity * wb;
  const Vec3f d = a.direction * wa + b.direction * wb;
  if (dot(d, d) > 0) storage.direction = normalize(d);
  return storage;
}

Instance make_instance(int mesh, const Affine3f& to_world, int node) {
  Instance inst;
  inst.mesh = mesh;
  return placed(inst, to_world, node, "mesh " + std::to_string(mesh));
}

Instance make_shape_instance(int shape, const Affine3f& to_world, int node) {
  Instance inst;
  inst.mesh = -1;
  inst.shape = shape;
  return placed(inst, to_world, node, "shape " + std::to_string(shape));
}

int add_world_mesh(Scene& scene, Mesh mesh) {
  const int index = int(scene.meshes.size());
  Instance inst;
  inst.mesh = index;
  inst.node = mesh.node;
  scene.meshes.push_back(std::move(mesh));
  scene.instances.push_back(inst);
  return index;
}

Mesh make_point_set(std::vector<Vec3f> points, std::string name) {
  Mesh m;
  m.name = std::move(name);
  m.points = true;
  m.indices.resize(points.size() * 3);
  for (size_t i = 0; i < points.size(); ++i)
    m.indices[3 * i] = m.indices[3 * i + 1] = m.indices[3 * i + 2] = uint32_t(i);
  m.normals.assign(points.size(), Vec3f{0, 0, 1});
  m.positions = std::move(points);
  return m;
}

Bounds3f compute_bounds(const Scene& scene, uint64_t exact_vertex_limit) {
  std::vector<Bounds3f> mesh_bounds(scene.meshes.size());
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const Mesh& m = scene.meshes[i];
    for (Vec3f p : m.positions) mesh_bounds[i] = merge(mesh_bounds[i], p);
    // Spheres and capsules reach past their axes: by the file's radii (radii a render set from
    // its camera do not move the bounds a camera is framed on).
    if (renders_as_curves(m) && m.file_radii && !mesh_bounds[i].empty()) {
      float r = 0;
      for (float x : m.radii)
        if (std::isfinite(x)) r = std::max(r, x);
      mesh_bounds[i] = {mesh_bounds[i].lo - Vec3f{r, r, r}, mesh_bounds[i].hi + Vec3f{r, r, r}};
    }
  }
  // Placed meshes: every vertex mapped (exact) while that stays cheap, else the mapped corners
  // of the mesh's box (conservative), so a million placements of a big mesh cost no more
  // than a million boxes.
  uint64_t placed_vertices = 0;
  for (const Instance& inst : scene.instances)
    if (!inst.identity && inst.shape < 0) placed_vertices += scene.meshes[size_t(inst.mesh)].positions.size();
  const bool exact = placed_vertices <= exact_vertex_limit;
  Bounds3f b;
  for (const Instance& inst : scene.instances) {
    if (inst.shape >= 0) {
      const Bounds3f sb = shape_bounds(scene.shapes[size_t(inst.shape)].shape);
      if (!sb.empty()) b = merge(b, transform_bounds(inst.to_world, sb));
      continue;
    }
    const Mesh& m = scene.meshes[size_t(inst.mesh)];
    if (inst.identity) {
      b = merge(b, mesh_bounds[size_t(inst.mesh)]);
    } else if (exact && !(renders_as_curves(m) && m.file_radii)) {
      for (Vec3f p : m.positions) b = merge(b, apply_point(inst.to_world, p));
    } else {
      b = merge(b, transform_bounds(inst.to_world, mesh_bounds[size_t(inst.mesh)]));
    }
  }
  // Splats: their centres, placed (the boxes of their kernels would let one wide splat of a
  // capture decide the framing).
  std::vector<Bounds3f> cloud_bounds(scene.splat_clouds.size());
  for (size_t c = 0; c < scene.splat_clouds.size(); ++c)
    for (Vec3f p : scene.splat_clouds[c].positions) cloud_bounds[c] = merge(cloud_bounds[c], p);
  for (const SplatInstance& si : scene.splat_instances)
    if (!cloud_bounds[size_t(si.cloud)].empty())
      b = merge(b, transform_bounds(si.to_world, cloud_bounds[size_t(si.cloud)]));
  return b;
}

namespace {
// Triangles (degenerate ones for point and line sets) of the mesh instances `keep` accepts.
template <typename Keep>
uint64_t count_placed(const Scene& scene, Keep keep) {
  uint64_t n = 0;
  for (const Instance& inst : scene.instances)
    if (inst.shape < 0 && keep(scene.meshes[size_t(inst.mesh)]))
      n += scene.meshes[size_t(inst.mesh)].indices.size() / 3;
  return n;
}
}  // namespace

uint64_t count_triangles(const Scene& scene) {
  return count_placed(scene, [](const Mesh& m) { return !m.points && !m.lines; });
}

uint64_t count_line_segments(const Scene& scene) {
  return count_placed(scene, [](const Mesh& m) { return m.lines; });
}

uint64_t count_points(const Scene& scene) {
  return count_placed(scene, [](const Mesh& m) { return m.points; });
}

uint64_t count_shape_instances(const Scene& scene) {
  uint64_t n = 0;
  for (const Instance& inst : scene.instances) n += inst.shape >= 0;
  return n;
}

uint64_t scene_memory_bytes(const Scene& scene) {
  auto bytes = [](const auto& v) { return uint64_t(v.capacity()) * sizeof(v[0]); };
  uint64_t total = bytes(scene.instances) + bytes(scene.materials) + bytes(scene.lights);
  for (const Mesh& m : scene.meshes)
    total += bytes(m.positions) + bytes(m.normals) + bytes(m.tangents) + bytes(m.uvs) + bytes(m.uvs1) +
             bytes(m.colors) + bytes(m.indices) + bytes(m.motion_positions) + bytes(m.motion_normals) +
             bytes(m.radii);
  total += bytes(scene.shapes);
  for (const SceneShape& s : scene.shapes) {
    total += bytes(s.shape.sdf.nodes) + bytes(s.shape.sdf.planes) + bytes(s.shape.sdf.displacements);
    for (const SolidMesh& solid : s.shape.sdf.polyhedra) total += solid_mesh_bytes(solid);
  }
  for (const Texture& t : scene.textures)
    for (const MipLevel& level : t.levels) total += bytes(level.texels);
  total += bytes(scene.procedurals) + bytes(scene.splat_clouds) + bytes(scene.splat_instances);
  for (const SplatCloud& c : scene.splat_clouds)
    total += bytes(c.positions) + bytes(c.rotations) + bytes(c.scales) + bytes(c.opacities) + bytes(c.sh);
  for (const ProceduralTexture& p : scene.procedurals) total += bytes(p.base_color.stops);
  return total;
}

uint64_t count_stored_triangles(const Scene& scene) {
  uint64_t n = 0;
  for (const auto& m : scene.meshes) n += m.indices.size() / 3;
  return n;
}

WorldTriangle world_triangle(const Scene& scene, const Instance& inst, uint32_t prim) {
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const size_t base = size_t(prim) * 3;
  WorldTriangle t;
  for (int k = 0; k < 3; ++k) {
    t.index[k] = mesh.indices[base + size_t(k)];
    const Vec3f p = mesh.positions[t.index[k]];
    t.p[k] = inst.identity ? p : apply_point(inst.to_world, p);
  }
  t.ng = triangle_normal(t.p[0], t.p[1], t.p[2]);
  if (inst.mirrored) t.ng = -t.ng;
  return t;
}

WorldTriangle world_triangle(const Scene& scene, const Instance& inst, uint32_t prim, float time) {
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  if (mesh.motion_steps < 2) return world_triangle(scene, inst, prim);
  const size_t base = size_t(prim) * 3;
  WorldTriangle t;
  for (int k = 0; k < 3; ++k) {
    t.index[k] = mesh.indices[base + size_t(k)];
    const Vec3f p = interpolate_vertex(mesh.motion_positions.data(), mesh.positions.size(), mesh.motion_steps,
                                       t.index[k], time);
    t.p[k] = inst.identity ? p : apply_point(inst.to_world, p);
  }
  t.ng = triangle_normal(t.p[0], t.p[1], t.p[2]);
  if (inst.mirrored) t.ng = -t.ng;
  return t;
}

Vec3f mesh_normal(const Mesh& mesh, uint32_t i, float time) {
  if (mesh.motion_steps < 2 || mesh.motion_normals.empty()) return mesh.normals[i];
  const Vec3f n = normalize(
      interpolate_vertex(mesh.motion_normals.data(), mesh.normals.size(), mesh.motion_steps, i, time));
  return dot(n, n) > 0 ? n : mesh.normals[i];
}

std::vector<Vec3f> compute_smooth_normals(std::span<const Vec3f> positions,
                                          std::span<const uint32_t> indices) {
  std::vector<Vec3f> n(positions.size());
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    // |cross| = 2 x area, so summing unnormalised cross products weights by area.
    const Vec3f face = cross(positions[b] - positions[a], positions[c] - positions[a]);
    n[a] += face;
    n[b] += face;
    n[c] += face;
  }
  for (auto& v : n) {
    v = normalize(v);
    if (!(dot(v, v) > 0)) v = {0, 0, 1};
  }
  return n;
}

std::vector<Vec4f> compute_tangents(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                                    std::span<const Vec2f> uvs, std::span<const uint32_t> indices) {
  std::vector<Vec3f> tu(positions.size()), tv(positions.size());
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    const Vec3f e1 = positions[b] - positions[a], e2 = positions[c] - positions[a];
    const float du1 = uvs[b].x - uvs[a].x, dv1 = uvs[b].y - uvs[a].y;
    const float du2 = uvs[c].x - uvs[a].x, dv2 = uvs[c].y - uvs[a].y;
    const float r = du1 * dv2 - du2 * dv1;
    if (!(std::fabs(r) > 0) || !std::isfinite(r)) continue;
    // dp/du and dp/dv of the triangle, weighted by its area.
    const float area = length(cross(e1, e2));
    const Vec3f dpdu = normalize((e1 * dv2 - e2 * dv1) / r) * area;
    const Vec3f dpdv = normalize((e2 * du1 - e1 * du2) / r) * area;
    for (uint32_t v : {a, b, c}) {
      tu[v] += dpdu;
      tv[v] += dpdv;
    }
  }
  std::vector<Vec4f> out(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) {
    const Vec3f n = normals[v];
    Vec3f t = normalize(tu[v] - n * dot(n, tu[v]));
    if (!(dot(t, t) > 0)) {  // no UV gradient here: any tangent orthogonal to n
      const Vec3f axis = std::fabs(n.x) < 0.9f ? Vec3f{1, 0, 0} : Vec3f{0, 1, 0};
      t = normalize(cross(axis, n));
    }
    const float w = dot(cross(n, t), tv[v]) > 0 ? -1.0f : 1.0f;
    out[v] = {t.x, t.y, t.z, w};
  }
  return out;
}

}  // namespace penumbra
