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

}  // namespace penumbra::test
