// Shapes for tests: SDF node builders and the named trees the marching-cubes and mesh-command
// tests share (primitives, the classic CSG part, a smooth-union blob, a displaced sphere), and
// analytic shapes.
#pragma once

#include "renderer/shapes/sdf.h"
#include "renderer/shapes/shape.h"

namespace penumbra::test {

/// An analytic shape of `kind` with the given radius, half extents and half height.
inline Shape analytic_shape(ShapeKind kind, float radius = 1, Vec3f half = {1, 1, 1},
                            float half_height = 0.5f) {
  Shape s;
  s.kind = kind;
  s.radius = radius;
  s.half_size = half;
  s.half_height = half_height;
  return s;
}

inline int add_node(SdfTree& t, SdfNode n) {
  t.nodes.push_back(n);
  return int(t.nodes.size()) - 1;
}

inline SdfNode sdf_primitive(SdfKind k, Vec3f size, float radius = 0) {
  SdfNode n;
  n.kind = k;
  n.size = size;
  n.radius = radius;
  return n;
}

inline SdfNode sdf_operator(SdfKind k, int a, int b = -1, float radius = 0) {
  SdfNode n;
  n.kind = k;
  n.a = a;
  n.b = b;
  n.radius = radius;
  return n;
}

/// A Displace node over `child` adding amplitude x fractal_noise(frequency x p) with `params` and
/// the table of `seed`; its noise is appended to t.displacements. Returns the node's index.
inline int add_displace(SdfTree& t, int child, float amplitude, float frequency,
                        const FractalParams& params = {}, uint32_t seed = 0) {
  SdfDisplacement d;
  d.table = make_perlin_table(seed);
  d.params = params;
  d.amplitude = amplitude;
  d.frequency = frequency;
  t.displacements.push_back(d);
  SdfNode n = sdf_operator(SdfKind::Displace, child);
  n.displacement = int(t.displacements.size()) - 1;
  return add_node(t, n);
}

/// The parent-to-local map of a shape moved by d.
inline Affine3f moved_by(Vec3f d) {
  Affine3f a;
  a.m[0][3] = -d.x, a.m[1][3] = -d.y, a.m[2][3] = -d.z;
  return a;
}

inline SdfTree single_shape(SdfNode n) {
  SdfTree t;
  t.root = add_node(t, n);
  return t;
}

/// The classic CSG part: a sphere of radius 1.35 intersected with the cube [-1, 1]^3, minus three
/// cylinders of radius 0.5 along X, Y and Z through the centre. The solid deformation-retracts
/// to the cube's edge graph (8 corner blocks joined by 12 edge bars: every bar survives since
/// its middle, e.g. (0, 0.6, 0.6), lies in the sphere and outside all three cylinders), so its
/// genus is 1 - (8 - 12) = 5 and its surface's Euler characteristic 2 - 2 * 5 = -8.
inline SdfTree csg_part() {
  SdfTree t;
  const int sphere = add_node(t, sdf_primitive(SdfKind::Sphere, {1.35f, 0, 0}));
  const int cube = add_node(t, sdf_primitive(SdfKind::Box, {1, 1, 1}));
  const int body = add_node(t, sdf_operator(SdfKind::Intersection, sphere, cube));
  SdfNode cy = sdf_primitive(SdfKind::Cylinder, {0, 1.5f, 0}, 0.5f);
  const int along_y = add_node(t, cy);
  cy.to_local.m[0][0] = 0, cy.to_local.m[0][1] = 1;  // local y = x, local x = y, local z = -z
  cy.to_local.m[1][0] = 1, cy.to_local.m[1][1] = 0;
  cy.to_local.m[2][2] = -1;
  const int along_x = add_node(t, cy);
  cy.to_local = Affine3f{};
  cy.to_local.m[1][1] = 0, cy.to_local.m[1][2] = 1;  // local y = z, local z = -y
  cy.to_local.m[2][1] = -1, cy.to_local.m[2][2] = 0;
  const int along_z = add_node(t, cy);
  const int holes = add_node(
      t, sdf_operator(SdfKind::Union, along_x, add_node(t, sdf_operator(SdfKind::Union, along_y, along_z))));
  t.root = add_node(t, sdf_operator(SdfKind::Subtraction, body, holes));
  return t;
}

/// Two spheres of radius `r` at x = -d and x = +d, joined by a smooth union of blend radius k
/// (k = 0: a plain union).
inline SdfTree sphere_pair(float r, float d, float k = 0) {
  SdfTree t;
  SdfNode s = sdf_primitive(SdfKind::Sphere, {r, 0, 0});
  s.to_local = moved_by({-d, 0, 0});
  const int a = add_node(t, s);
  s.to_local = moved_by({d, 0, 0});
  const int b = add_node(t, s);
  t.root = add_node(t, sdf_operator(k > 0 ? SdfKind::SmoothUnion : SdfKind::Union, a, b, k));
  return t;
}

/// A sphere of radius `r` at the origin displaced by noise of `kind` (the other parameters at
/// their defaults) with the given amplitude and frequency.
inline SdfTree displaced_sphere(float r, float amplitude, float frequency,
                                FractalKind kind = FractalKind::Fbm, uint32_t seed = 0) {
  SdfTree t;
  const int sphere = add_node(t, sdf_primitive(SdfKind::Sphere, {r, 0, 0}));
  FractalParams params;
  params.kind = kind;
  t.root = add_displace(t, sphere, amplitude, frequency, params, seed);
  return t;
}

/// An indexed triangle mesh for the solid-BSP and polyhedron tests.
struct TriMesh {
  std::vector<Vec3f> positions;
  std::vector<uint32_t> indices;
  /// Two triangles a b c, a c d (counter-clockwise seen from the side they face).
  void quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    indices.insert(indices.end(), {a, b, c, a, c, d});
  }
  /// Every triangle's winding reversed.
  TriMesh flipped() const {
    TriMesh m = *this;
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
    return m;
  }
  /// `other` appended (its indices offset).
  void append(const TriMesh& other) {
    const uint32_t base = uint32_t(positions.size());
    positions.insert(positions.end(), other.positions.begin(), other.positions.end());
    for (uint32_t i : other.indices) indices.push_back(base + i);
  }
};

/// The box [lo, hi]: vertex i at (i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z),
/// 12 outward triangles, the faces in the order -x, +x, -y, +y, -z, +z (two triangles each).
inline TriMesh box_mesh(Vec3f lo, Vec3f hi) {
  TriMesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  m.quad(0, 4, 6, 2);
  m.quad(1, 3, 7, 5);
  m.quad(0, 1, 5, 4);
  m.quad(2, 6, 7, 3);
  m.quad(0, 2, 3, 1);
  m.quad(4, 5, 7, 6);
  return m;
}

/// The same box with 4 vertices of its own per face (24, as glTF files split them for normals).
inline TriMesh split_box_mesh(Vec3f lo, Vec3f hi) {
  const TriMesh shared = box_mesh(lo, hi);
  TriMesh m;
  for (size_t t = 0; t < shared.indices.size(); t += 6) {
    const uint32_t base = uint32_t(m.positions.size());
    for (size_t k : {0, 1, 2, 5}) m.positions.push_back(shared.positions[shared.indices[t + k]]);
    m.quad(base, base + 1, base + 2, base + 3);
  }
  return m;
}

/// The simple polygon `outline` (counter-clockwise seen from +z, star-shaped around `centre`)
/// extruded from z0 to z1, its caps fanned from the centre.
inline TriMesh prism_mesh(const std::vector<Vec2f>& outline, Vec2f centre, float z0, float z1) {
  TriMesh m;
  const uint32_t n = uint32_t(outline.size());
  for (float z : {z0, z1})
    for (const Vec2f& p : outline) m.positions.push_back({p.x, p.y, z});
  m.positions.push_back({centre.x, centre.y, z0});
  m.positions.push_back({centre.x, centre.y, z1});
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = (i + 1) % n;
    m.quad(i, j, n + j, n + i);
    m.indices.insert(m.indices.end(), {2 * n + 1, n + i, n + j, 2 * n, j, i});
  }
  return m;
}

/// An L-shaped prism: the cube [-1, 1]^3 without the notch x > 0, y > 0.
inline TriMesh l_prism_mesh() {
  return prism_mesh({{-1, -1}, {1, -1}, {1, 0}, {0, 0}, {0, 1}, {-1, 1}}, {-0.5f, -0.5f}, -1, 1);
}

/// A five-pointed star (outer radius 1, inner 0.4) extruded over z in [-0.5, 0.5].
inline TriMesh star_prism_mesh() {
  std::vector<Vec2f> outline;
  for (int k = 0; k < 10; ++k) {
    const float a = 0.3f + float(k) * kPi / 5, r = k % 2 ? 0.4f : 1.0f;
    outline.push_back({r * std::cos(a), r * std::sin(a)});
  }
  return prism_mesh(outline, {0, 0}, -0.5f, 0.5f);
}

/// A unit icosphere subdivided `level` times (shared vertices, outward); with `spike` > 1 its 12
/// original vertices are pushed out to that radius, a star-shaped concave polyhedron.
inline TriMesh icosphere_mesh(int level, float spike = 1) {
  const float t = (1 + std::sqrt(5.0f)) / 2;
  TriMesh m;
  m.positions = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : m.positions) p = normalize(p);
  m.indices = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
               4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
               6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  for (int l = 0; l < level; ++l) {
    std::vector<std::pair<std::pair<uint32_t, uint32_t>, uint32_t>> mids;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      const std::pair<uint32_t, uint32_t> key{std::min(a, b), std::max(a, b)};
      for (const auto& [k, v] : mids)
        if (k == key) return v;
      m.positions.push_back(normalize((m.positions[a] + m.positions[b]) * 0.5f));
      mids.push_back({key, uint32_t(m.positions.size() - 1)});
      return uint32_t(m.positions.size() - 1);
    };
    std::vector<uint32_t> g;
    for (size_t i = 0; i < m.indices.size(); i += 3) {
      const uint32_t a = m.indices[i], b = m.indices[i + 1], c = m.indices[i + 2];
      const uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      g.insert(g.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    m.indices.swap(g);
  }
  for (int i = 0; i < 12; ++i) m.positions[size_t(i)] = m.positions[size_t(i)] * spike;
  return m;
}

/// A torus-like ring around +Y: major radius R, minor radius r, nu x nv quads (outward).
inline TriMesh ring_mesh(float major, float minor, int nu, int nv) {
  TriMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float u = 2 * kPi * float(i) / float(nu), v = 2 * kPi * float(j) / float(nv);
      const float a = major + minor * std::cos(v);
      m.positions.push_back({a * std::cos(u), minor * std::sin(v), a * std::sin(u)});
    }
  const auto at = [&](int i, int j) { return uint32_t((i % nu) * nv + j % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) m.quad(at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
  return m;
}

/// The box [-1, 1]^3 with the cavity [-0.5, 0.5]^3 (an inner box wound inwards).
inline TriMesh hollow_box_mesh() {
  TriMesh m = box_mesh({-1, -1, -1}, {1, 1, 1});
  m.append(box_mesh({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}).flipped());
  return m;
}

/// A Polyhedron node over `mesh` (built with build_solid_mesh, appended to t.polyhedra).
inline SdfNode sdf_polyhedron(SdfTree& t, const TriMesh& mesh) {
  t.polyhedra.push_back(build_solid_mesh(mesh.positions, mesh.indices));
  SdfNode n;
  n.kind = SdfKind::Polyhedron;
  n.polyhedron = int(t.polyhedra.size()) - 1;
  return n;
}

}  // namespace penumbra::test
