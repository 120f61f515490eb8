// Tests for renderer/shapes/sdf: every primitive's distance against closed forms, CSG identities,
// the Lipschitz bound on random pairs for every operator and transform, and sphere tracing against
// the analytic ray-sphere and ray-plane tests.
#include "renderer/shapes/sdf.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

Vec3f random_point(std::mt19937& rng, float extent) {
  std::uniform_real_distribution<float> u(-extent, extent);
  return {u(rng), u(rng), u(rng)};
}

}  // namespace

TEST_CASE("sdf: primitive distances match closed forms", "[shapes][sdf][quick]") {
  const auto d = [](SdfNode n, Vec3f p) { return sdf_eval(single_shape(n), p); };
  // Sphere of radius 2.
  CHECK(d(sdf_primitive(SdfKind::Sphere, {2, 0, 0}), {5, 0, 0}) == Approx(3));
  CHECK(d(sdf_primitive(SdfKind::Sphere, {2, 0, 0}), {0, 0, 0}) == Approx(-2));
  // Box of half extents (1, 2, 3): faces, an edge, a corner, inside.
  const SdfNode box = sdf_primitive(SdfKind::Box, {1, 2, 3});
  CHECK(d(box, {3, 0, 0}) == Approx(2));
  CHECK(d(box, {0, 0, -4}) == Approx(1));
  CHECK(d(box, {2, 3, 0}) == Approx(std::sqrt(2.0f)));
  CHECK(d(box, {2, 3, 4}) == Approx(std::sqrt(3.0f)));
  CHECK(d(box, {0.5f, 0, 0}) == Approx(-0.5f));
  // Round box: the corner is rounded by the radius.
  const SdfNode rbox = sdf_primitive(SdfKind::RoundBox, {1, 1, 1}, 0.25f);
  CHECK(d(rbox, {2, 0, 0}) == Approx(1));
  CHECK(d(rbox, {2, 2, 2}) == Approx(std::sqrt(3.0f) * 1.25f - 0.25f));
  // Capsule: segment y in [-1, 1], radius 0.5.
  const SdfNode cap = sdf_primitive(SdfKind::Capsule, {0, 1, 0}, 0.5f);
  CHECK(d(cap, {2, 0.3f, 0}) == Approx(1.5f));
  CHECK(d(cap, {0, 3, 0}) == Approx(1.5f));
  // Cylinder radius 1, half height 2.
  const SdfNode cyl = sdf_primitive(SdfKind::Cylinder, {0, 2, 0}, 1);
  CHECK(d(cyl, {3, 0, 0}) == Approx(2));
  CHECK(d(cyl, {0, 5, 0}) == Approx(3));
  CHECK(d(cyl, {4, 6, 0}) == Approx(5));  // the rim at (1, 2): distance to the edge circle
  CHECK(d(cyl, {0, 0, 0}) == Approx(-1));
  // Cone: base radius 1 at y = -1, apex at y = +1.
  const SdfNode cone = sdf_primitive(SdfKind::Cone, {0, 1, 0}, 1);
  CHECK(d(cone, {0, 3, 0}) == Approx(2));                     // above the apex
  CHECK(d(cone, {0, -3, 0}) == Approx(2));                    // below the base
  CHECK(d(cone, {0, 0, 0}) == Approx(-1 / std::sqrt(5.0f)));  // to the slanted side
  // Torus: major 2, minor 0.5.
  const SdfNode torus = sdf_primitive(SdfKind::Torus, {2, 0, 0}, 0.5f);
  CHECK(d(torus, {2, 0, 0}) == Approx(-0.5f));
  CHECK(d(torus, {0, 0, 0}) == Approx(1.5f));
  CHECK(d(torus, {0, 0, 2}) == Approx(-0.5f));
  CHECK(d(torus, {2, 3, 0}) == Approx(2.5f));
  // Half-space y <= 1.
  SdfNode hs = sdf_primitive(SdfKind::HalfSpace, {});
  hs.normal = {0, 1, 0};
  hs.offset = 1;
  CHECK(d(hs, {7, 4, -3}) == Approx(3));
  CHECK(d(hs, {0, -1, 0}) == Approx(-2));
  // A convex polyhedron of six planes is the unit cube: equal to the box on its faces' normals.
  SdfTree poly;
  for (const Vec3f n : {Vec3f{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}})
    poly.planes.push_back({n.x, n.y, n.z, 1});
  SdfNode pn = sdf_primitive(SdfKind::ConvexPolyhedron, {});
  pn.plane_count = 6;
  poly.root = add_node(poly, pn);
  CHECK(sdf_eval(poly, {3, 0, 0}) == Approx(2));
  CHECK(sdf_eval(poly, {0.25f, 0.5f, 0}) == Approx(-0.5f));
}

TEST_CASE("sdf: CSG identities hold pointwise", "[shapes][sdf][quick]") {
  SdfTree t;
  const int a = add_node(t, sdf_primitive(SdfKind::Sphere, {1, 0, 0}));
  SdfNode bn = sdf_primitive(SdfKind::Box, {0.7f, 0.7f, 0.7f});
  bn.to_local = moved_by({0.6f, 0.2f, 0});
  const int b = add_node(t, bn);
  const int aua = add_node(t, sdf_operator(SdfKind::Union, a, a));
  const int aia = add_node(t, sdf_operator(SdfKind::Intersection, a, a));
  const int ama = add_node(t, sdf_operator(SdfKind::Subtraction, a, a));
  const int not_union =
      add_node(t, sdf_operator(SdfKind::Complement, add_node(t, sdf_operator(SdfKind::Union, a, b))));
  const int inter_of_not =
      add_node(t, sdf_operator(SdfKind::Intersection, add_node(t, sdf_operator(SdfKind::Complement, a)),
                               add_node(t, sdf_operator(SdfKind::Complement, b))));
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const Vec3f p = random_point(rng, 2.5f);
    const float fa = sdf_eval(t, a, p);
    REQUIRE(sdf_eval(t, aua, p) == fa);
    REQUIRE(sdf_eval(t, aia, p) == fa);
    REQUIRE(sdf_eval(t, ama, p) >= 0);                                   // A - A is empty
    REQUIRE(sdf_eval(t, not_union, p) == sdf_eval(t, inter_of_not, p));  // De Morgan
  }
}

TEST_CASE("sdf: the Lipschitz bound holds for every operator and transform", "[shapes][sdf][quick]") {
  std::mt19937 rng(11);
  // Transforms: identity, rotation with uniform scale, non-uniform scale and shear.
  Affine3f rot_scale;
  const float c = std::cos(0.7f), s = std::sin(0.7f);
  rot_scale.m[0][0] = 2 * c, rot_scale.m[0][2] = 2 * s, rot_scale.m[2][0] = -2 * s, rot_scale.m[2][2] = 2 * c,
  rot_scale.m[1][1] = 2;
  Affine3f shear;
  shear.m[0][0] = 0.5f, shear.m[1][1] = 3, shear.m[2][2] = 1, shear.m[0][1] = 0.8f, shear.m[2][0] = -0.4f;
  for (const Affine3f& xf : {Affine3f{}, rot_scale, shear})
    for (SdfKind k : {SdfKind::Union, SdfKind::Intersection, SdfKind::Subtraction, SdfKind::Complement,
                      SdfKind::SmoothUnion, SdfKind::SmoothIntersection, SdfKind::SmoothSubtraction}) {
      SdfTree t;
      SdfNode torus = sdf_primitive(SdfKind::Torus, {1, 0, 0}, 0.3f);
      torus.to_local = xf;
      const int a = add_node(t, torus);
      const int b = add_node(t, sdf_primitive(SdfKind::RoundBox, {0.8f, 0.4f, 0.6f}, 0.1f));
      SdfNode root = sdf_operator(k, a, b, 0.35f);
      root.to_local = moved_by({0.1f, -0.2f, 0.3f});
      t.root = add_node(t, root);
      const float lip = sdf_lipschitz(t);
      CHECK(lip >= 1.0f);
      for (int i = 0; i < 3000; ++i) {
        const Vec3f x = random_point(rng, 2), y = x + random_point(rng, 0.3f);
        const float lhs = std::abs(sdf_eval(t, x) - sdf_eval(t, y));
        REQUIRE(lhs <= lip * length(x - y) + 1e-5f);
      }
    }
  CHECK(max_singular_value(Affine3f{}) == Approx(1));
  CHECK(max_singular_value(rot_scale) == Approx(2));
}

TEST_CASE(
    "sdf: the analytic gradient matches central differences for every primitive, operator and transform",
    "[shapes][sdf][quick]") {
  std::mt19937 rng(5);
  Affine3f shear;
  shear.m[0][0] = 0.5f, shear.m[1][1] = 1.5f, shear.m[2][2] = 1, shear.m[0][1] = 0.3f, shear.m[2][0] = -0.2f;
  SdfNode half;
  half.kind = SdfKind::HalfSpace;
  half.normal = normalize(Vec3f{0.3f, 1, -0.2f});
  SdfTree base;
  base.planes = {{1, 0, 0, 0.6f},  {-1, 0, 0, 0.6f}, {0, 1, 0, 0.5f},
                 {0, -1, 0, 0.5f}, {0, 0, 1, 0.4f},  {0, 0, -1, 0.4f}};
  SdfNode poly;
  poly.kind = SdfKind::ConvexPolyhedron;
  poly.plane_count = 6;
  const std::vector<SdfNode> primitives{sdf_primitive(SdfKind::Sphere, {0.7f, 0, 0}),
                                        sdf_primitive(SdfKind::Box, {0.6f, 0.4f, 0.5f}),
                                        sdf_primitive(SdfKind::RoundBox, {0.6f, 0.4f, 0.5f}, 0.15f),
                                        sdf_primitive(SdfKind::Capsule, {0, 0.4f, 0}, 0.3f),
                                        sdf_primitive(SdfKind::Cylinder, {0, 0.5f, 0}, 0.4f),
                                        sdf_primitive(SdfKind::Cone, {0, 0.5f, 0}, 0.5f),
                                        sdf_primitive(SdfKind::Torus, {0.6f, 0, 0}, 0.2f),
                                        half,
                                        poly};
  int checked = 0;
  for (const SdfNode& p0 : primitives)
    for (SdfKind k : {SdfKind::Union, SdfKind::Intersection, SdfKind::Subtraction, SdfKind::Complement,
                      SdfKind::SmoothUnion, SdfKind::SmoothIntersection, SdfKind::SmoothSubtraction}) {
      SdfTree t = base;
      SdfNode a = p0;
      a.to_local = shear;
      const int ia = add_node(t, a);
      SdfNode b = sdf_primitive(SdfKind::Sphere, {0.45f, 0, 0});
      b.to_local = moved_by({0.3f, 0.2f, 0});
      const int ib = add_node(t, b);
      t.root = add_node(t, sdf_operator(k, ia, ib, 0.25f));
      for (int i = 0; i < 400; ++i) {
        const Vec3f x = random_point(rng, 1.2f);
        // Compare only where f is smooth: central differences at two step sizes agree.
        const Vec3f n1 = sdf_normal(t, x, 1e-3f), n2 = sdf_normal(t, x, 2e-3f);
        if (!(dot(n1, n2) > 0.99999f)) continue;
        const Vec3f g = sdf_gradient_normal(t, x);
        INFO("primitive " << int(p0.kind) << " operator " << int(k) << " at (" << x.x << ", " << x.y << ", "
                          << x.z << ")");
        REQUIRE(dot(g, n1) > 0.999f);
        ++checked;
      }
    }
  CHECK(checked > 10000);
}

TEST_CASE("sdf: sphere tracing hits where the analytic tests hit", "[shapes][sdf][quick]") {
  SdfTree t;
  SdfNode sphere = sdf_primitive(SdfKind::Sphere, {1.5f, 0, 0});
  const Vec3f centre{0.3f, -0.2f, 4};
  sphere.to_local = moved_by(centre);
  t.root = add_node(t, sphere);
  const float lip = sdf_lipschitz(t);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0, misses = 0;
  for (int i = 0; i < 4000; ++i) {
    Ray r;
    r.org = {0, 0, 0};
    r.dir = Vec3f{u(rng) * 0.6f, u(rng) * 0.6f, 1} * (0.5f + (u(rng) + 1));  // any length
    float ta = 0, ts = 0;
    int steps = 0;
    const bool analytic = intersect_sphere(r, centre, 1.5f, ta);
    const bool traced = sphere_trace(t, lip, r, {}, ts, steps);
    // Grazing rays within the tolerance band may go either way; elsewhere they must agree.
    const Vec3f d = normalize(r.dir);
    const float miss_distance = length(centre - d * dot(centre, d));
    if (std::abs(miss_distance - 1.5f) < 1e-3f) continue;
    REQUIRE(traced == analytic);
    if (analytic) {
      REQUIRE(ts * length(r.dir) == Approx(ta * length(r.dir)).margin(1e-3));
      ++hits;
    } else {
      ++misses;
    }
  }
  CHECK(hits > 500);
  CHECK(misses > 500);
  // From inside, the ray finds the exit; a ray pointing away misses; tfar is respected.
  Ray inside;
  inside.org = centre;
  inside.dir = {1, 0, 0};
  float t_in = 0;
  int steps = 0;
  REQUIRE(sphere_trace(t, lip, inside, {}, t_in, steps));
  CHECK(t_in == Approx(1.5f).margin(1e-4));
  Ray away;
  away.dir = {0, 0, -1};
  CHECK_FALSE(sphere_trace(t, lip, away, {}, t_in, steps));
  Ray short_ray;
  short_ray.dir = {0, 0, 1};
  short_ray.tfar = 2;
  CHECK_FALSE(sphere_trace(t, lip, short_ray, {}, t_in, steps));
  // A plane seen at a grazing angle: t = distance / cos.
  SdfNode ground = sdf_primitive(SdfKind::HalfSpace, {});
  ground.normal = {0, 1, 0};
  ground.offset = -1;
  const SdfTree plane = single_shape(ground);
  Ray glancing;
  glancing.org = {0, 0, 0};
  glancing.dir = normalize(Vec3f{1, -0.05f, 0});
  float tp = 0;
  REQUIRE(sphere_trace(plane, sdf_lipschitz(plane), glancing, {}, tp, steps));
  CHECK(tp == Approx(1 / 0.05f * length(Vec3f{1, -0.05f, 0})).epsilon(1e-3));
}
