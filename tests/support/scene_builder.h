// Test scenes built directly as renderer data (no files): quads and lights at known places.
#pragma once

#include <catch2/catch.hpp>

#include "renderer/integrators/render.h"
#include "renderer/scene/scene.h"
#include "support/sdf_trees.h"

namespace penumbra::test {

/// The cube [-half, half]^3 with 8 shared vertices and 12 triangles facing outwards.
inline Mesh cube_mesh(float half) {
  Mesh m;
  m.name = "cube";
  for (int i = 0; i < 8; ++i)
    m.positions.push_back({i & 1 ? half : -half, i & 2 ? half : -half, i & 4 ? half : -half});
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces)
    for (int k : {0, 1, 2, 0, 2, 3}) m.indices.push_back(uint32_t(f[k]));
  return m;
}

/// Adds an axis-aligned rectangle with normal +z (or -z if `flip`) at height z, spanning
/// [x0, x1] x [y0, y1], made of two triangles; returns its mesh index (== its instance index when every mesh
/// is added this way).
inline int add_quad_z(Scene& s, float x0, float x1, float y0, float y1, float z, int material,
                      bool flip = false) {
  Mesh m;
  m.name = "quad";
  m.positions = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  m.indices = flip ? std::vector<uint32_t>{0, 2, 1, 0, 3, 2} : std::vector<uint32_t>{0, 1, 2, 0, 2, 3};
  m.normals = compute_smooth_normals(m.positions, m.indices);
  m.material = material;
  return add_world_mesh(s, std::move(m));
}

/// Adds a rectangle in the plane x = const facing -x, spanning [y0, y1] x [z0, z1].
inline int add_quad_x(Scene& s, float x, float y0, float y1, float z0, float z1, int material) {
  Mesh m;
  m.name = "wall";
  m.positions = {{x, y0, z0}, {x, y1, z0}, {x, y1, z1}, {x, y0, z1}};
  m.indices = {0, 2, 1, 0, 3, 2};
  m.normals = compute_smooth_normals(m.positions, m.indices);
  m.material = material;
  return add_world_mesh(s, std::move(m));
}

/// The mesh of instance `inst` in world space (positions, normals and tangents mapped, winding
/// reversed for a mirroring placement): the copy the loader makes when it flattens.
inline Mesh world_copy(const Scene& s, const Instance& inst) {
  Mesh m = s.meshes[size_t(inst.mesh)];
  if (inst.identity) return m;
  for (Vec3f& p : m.positions) p = apply_point(inst.to_world, p);
  for (Vec3f& n : m.normals) n = world_normal(inst, n);
  for (Vec4f& t : m.tangents) {
    const Vec3f v = normalize(apply_vector(inst.to_world, {t.x, t.y, t.z}));
    t = {v.x, v.y, v.z, inst.mirrored ? -t.w : t.w};
  }
  if (inst.mirrored)
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) std::swap(m.indices[i + 1], m.indices[i + 2]);
  m.node = inst.node;
  return m;
}

/// Catch checks that a and b agree componentwise within eps (absolute).
inline void check_vec(Vec3f a, Vec3f b, float eps = 1e-6f) {
  CHECK(a.x == Approx(b.x).margin(eps));
  CHECK(a.y == Approx(b.y).margin(eps));
  CHECK(a.z == Approx(b.z).margin(eps));
}

inline int add_material(Scene& s, Vec3f base, float metallic, float roughness, bool unlit = false) {
  Material m;
  m.base_color = base;
  m.metallic = metallic;
  m.roughness = roughness;
  m.unlit = unlit;
  s.materials.push_back(m);
  return int(s.materials.size()) - 1;
}

inline Light point_light(Vec3f position, float intensity, Vec3f color = {1, 1, 1}) {
  Light l;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  l.color = color;
  return l;
}

/// A pure Lambertian material (KHR_materials_specular factor 0: no Fresnel layer), with
/// optional emission; double-sided unless told.
inline int add_lambert(Scene& s, Vec3f albedo, Vec3f emissive = {0, 0, 0}, bool double_sided = true) {
  const int m = add_material(s, albedo, 0, 1);
  s.materials[size_t(m)].specular = 0;
  s.materials[size_t(m)].emissive = emissive;
  s.materials[size_t(m)].double_sided = double_sided;
  return m;
}

/// A closed, flat-shaded sphere of radius r around c: an octahedron subdivided `level` times
/// with its vertices pushed onto the sphere (8 * 4^level triangles, outward counter-clockwise).
inline int add_sphere(Scene& s, Vec3f c, float r, int level, int material) {
  std::vector<Vec3f> tris{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<Vec3f> all;
  for (int sx : {1, -1})
    for (int sy : {1, -1})
      for (int sz : {1, -1}) {
        Vec3f a{float(sx), 0, 0}, b{0, float(sy), 0}, d{0, 0, float(sz)};
        if (sx * sy * sz < 0) std::swap(a, b);  // keep the winding outward
        all.insert(all.end(), {a, b, d});
      }
  for (int l = 0; l < level; ++l) {
    std::vector<Vec3f> next;
    for (size_t i = 0; i < all.size(); i += 3) {
      const Vec3f a = all[i], b = all[i + 1], d = all[i + 2];
      const Vec3f ab = normalize(a + b), bd = normalize(b + d), da = normalize(d + a);
      next.insert(next.end(), {a, ab, da, ab, b, bd, da, bd, d, ab, bd, da});
    }
    all.swap(next);
  }
  Mesh m;
  m.name = "sphere";
  for (const Vec3f& p : all) {
    m.indices.push_back(uint32_t(m.positions.size()));
    m.positions.push_back(c + p * r);
  }
  m.material = material;
  return add_world_mesh(s, std::move(m));
}

/// Appends `shape` with `material`, placed by `to_world`; returns the instance index.
inline int add_shape(Scene& s, Shape shape, const Affine3f& to_world, int material, int node = -1) {
  SceneShape ss;
  ss.name = "shape";
  ss.shape = std::move(shape);
  ss.material = material;
  ss.node = node;
  s.shapes.push_back(std::move(ss));
  s.instances.push_back(make_shape_instance(int(s.shapes.size()) - 1, to_world, node));
  return int(s.instances.size()) - 1;
}

/// An analytic sphere of radius r, or (implicit = true) the sphere traced SDF sphere.
inline Shape sphere_shape(float r, bool implicit = false) {
  if (implicit) return make_implicit_shape(single_shape(sdf_primitive(SdfKind::Sphere, {r, 0, 0})));
  Shape sh;
  sh.kind = ShapeKind::Sphere;
  sh.radius = r;
  return sh;
}

/// The translation by t.
inline Affine3f translation(Vec3f t) {
  Affine3f a;
  a.m[0][3] = t.x, a.m[1][3] = t.y, a.m[2][3] = t.z;
  return a;
}

/// A small render configuration for tests: w x h pixels, spp samples, 8-pixel tiles.
inline RenderConfig small_render_config(int w, int h, int spp, int tile_size = 8) {
  RenderConfig c;
  c.width = w;
  c.height = h;
  c.spp = spp;
  c.tile_size = tile_size;
  return c;
}

}  // namespace penumbra::test
