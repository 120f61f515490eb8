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

TEST_CASE("sdf: the displaced Lipschitz bound holds for every noise kind, transform and distortion",
          "[shapes][sdf][noise]") {
  std::mt19937 rng(23);
  Affine3f shear;
  shear.m[0][0] = 0.5f, shear.m[1][1] = 1.5f, shear.m[2][2] = 1, shear.m[0][1] = 0.3f, shear.m[2][0] = -0.2f;
  Affine3f rot_scale;  // a rotation about Y with scale 1.5, moved
  const float c = std::cos(0.4f), s = std::sin(0.4f);
  rot_scale.m[0][0] = 1.5f * c, rot_scale.m[0][2] = 1.5f * s, rot_scale.m[2][0] = -1.5f * s;
  rot_scale.m[2][2] = 1.5f * c, rot_scale.m[1][1] = 1.5f, rot_scale.m[0][3] = 0.2f;
  for (const FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged})
    for (const float distortion : {0.0f, 0.6f}) {
      SdfTree t;
      SdfNode torus = sdf_primitive(SdfKind::Torus, {1, 0, 0}, 0.3f);
      torus.to_local = shear;
      FractalParams params;
      params.kind = kind;
      params.distortion = distortion;
      params.detail = 3.5f;
      const int displaced = add_displace(t, add_node(t, torus), 0.2f, 2.5f, params, 7);
      t.nodes[size_t(displaced)].to_local = rot_scale;
      t.root = displaced;
      const float lip = sdf_lipschitz(t);
      const float child = max_singular_value(shear) * max_singular_value(rot_scale);
      CHECK(lip > child);  // the noise's gradient adds to the child's bound
      double worst = 0;
      for (int i = 0; i < 100000; ++i) {
        const Vec3f x = random_point(rng, 2), y = x + random_point(rng, i % 2 ? 0.02f : 0.4f);
        const float lhs = std::abs(sdf_eval(t, x) - sdf_eval(t, y));
        INFO("noise " << int(kind) << " distortion " << distortion);
        REQUIRE(lhs <= lip * length(x - y) + 1e-5f);
        worst = std::max(worst, double(lhs) / length(x - y));
      }
      INFO("steepest slope seen " << worst << ", bound " << lip);
      CHECK(worst > 0.25 * child);
    }
}

TEST_CASE("sdf: displacement by amplitude 0 gives the child exactly", "[shapes][sdf][noise][quick]") {
  std::mt19937 rng(3);
  const SdfTree plain = single_shape(sdf_primitive(SdfKind::RoundBox, {0.8f, 0.5f, 0.6f}, 0.2f));
  for (const FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged}) {
    SdfTree t = plain;
    FractalParams params;
    params.kind = kind;
    params.distortion = 0.5f;
    t.root = add_displace(t, plain.root, 0, 3, params, 11);
    CHECK(sdf_lipschitz(t) == Approx(sdf_lipschitz(plain)).epsilon(1e-5));  // one more node's rounding
    for (int i = 0; i < 2000; ++i) {
      const Vec3f p = random_point(rng, 1.5f);
      REQUIRE(sdf_eval(t, p) == sdf_eval(plain, p));
      const Vec3f g = sdf_gradient_normal(t, p), g0 = sdf_gradient_normal(plain, p);
      REQUIRE((g.x == g0.x && g.y == g0.y && g.z == g0.z));
    }
  }
}

TEST_CASE("sdf: the displaced sphere's analytic gradient matches central differences",
          "[shapes][sdf][noise][quick]") {
  std::mt19937 rng(9);
  for (const FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged}) {
    SdfTree t = displaced_sphere(1, 0.2f, 2, kind, 5);
    t.nodes[size_t(t.root)].to_local = moved_by({0.1f, 0.2f, -0.3f});
    int checked = 0, off = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3f p = random_point(rng, 1.4f);
      // Where f is smooth: central differences at two steps agree.
      const Vec3f n1 = sdf_normal(t, p, 2e-4f), n2 = sdf_normal(t, p, 4e-4f);
      if (!(dot(n1, n2) > 0.99999f)) continue;
      const Vec3f g = sdf_gradient_normal(t, p);
      INFO("noise " << int(kind) << " at (" << p.x << ", " << p.y << ", " << p.z << ")");
      if (kind == FractalKind::Fbm) REQUIRE(dot(g, n1) > 0.999f);
      off += dot(g, n1) <= 0.999f;
      ++checked;
    }
    // Turbulence and ridged noise fold every octave at |n| = 0, where central differences that
    // straddle the crease differ from the one-sided analytic gradient: a few points only.
    CHECK(checked > 1500);
    CHECK(off <= checked / 100);
  }
}

namespace {

// The first crossing of f along the ray in [t0, t1] by marching with step dt and bisecting the
// bracketing step. `clear` is false when |f| has a local minimum below L dt at a sample without
// a crossing beside it: the ray grazes the surface there and two crossings between samples
// cannot be ruled out. Elsewhere a step whose ends lie farther than L dt / 2 from the surface
// cannot hold a crossing, and |f| falls steadily towards a crossing.
struct BruteHit {
  bool hit = false, clear = true;
  float t = 0;
};

BruteHit brute_force_march(const SdfTree& tree, float lip, const Ray& r, float t0, float t1, float dt) {
  BruteHit out;
  const auto f = [&](float t) { return sdf_eval(tree, r.org + r.dir * t); };
  float prev_t = t0, prev_f = f(t0), before = kInfinity;  // |f| one sample before prev
  for (int i = 1; prev_t < t1; ++i) {
    const float t = std::min(t0 + float(i) * dt, t1), ft = f(t);
    if ((ft < 0) != (prev_f < 0)) {
      float lo = prev_t, hi = t;
      for (int k = 0; k < 60; ++k) {
        const float mid = 0.5f * (lo + hi);
        if (mid == lo || mid == hi) break;
        ((f(mid) < 0) == (prev_f < 0) ? lo : hi) = mid;
      }
      out.hit = true;
      out.t = hi;
      return out;
    }
    if (std::abs(prev_f) <= before && std::abs(prev_f) <= std::abs(ft) && std::abs(prev_f) < lip * dt)
      out.clear = false;
    before = std::abs(prev_f);
    prev_t = t, prev_f = ft;
  }
  return out;
}

}  // namespace

TEST_CASE("sdf: sphere tracing a displaced sphere agrees with a dense brute-force march",
          "[shapes][sdf][noise]") {
  // Features: the top octave of fBm at frequency 2 with detail 4 has period 1 / 32 ~ 0.03; the
  // march steps 5e-4. Tolerance on t: 1e-5 for hits refined to the crossing, 1e-3 beyond the
  // tracer's own for the others (see below).
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-1, 1);
  for (const FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged}) {
    const float amplitude = 0.15f, radius = 1;
    SdfTree t = displaced_sphere(radius, amplitude, 2, kind, 3);
    const float lip = sdf_lipschitz(t);
    const float reach = radius + amplitude;  // |noise| <= 1: every point with f <= 0 lies within
    // Ridged noise's gradient bound makes L ~ 18 here: rays grazing the relief take more than
    // the default 512 steps.
    SphereTraceConfig config;
    config.max_steps = 8192;
    int hits = 0, misses = 0, unclear = 0, refined = 0;
    const int rays = 300;
    for (int i = 0; i < rays; ++i) {
      Ray r;
      r.org = {u(rng) * 0.5f, u(rng) * 0.5f, -3};
      r.dir = normalize(Vec3f{u(rng) * 0.4f, u(rng) * 0.4f, 1});
      // The march runs over the ray's part within `reach` of the origin.
      r.tfar = 10;
      const float mid = -dot(r.org, r.dir), d2 = dot(r.org, r.org) - mid * mid;
      BruteHit brute;  // a ray passing farther than `reach` misses
      if (d2 < reach * reach) {
        const float half = std::sqrt(reach * reach - d2);
        brute = brute_force_march(t, lip, r, mid - half - 1e-3f, mid + half + 1e-3f, 5e-4f);
      }
      if (!brute.clear) {
        ++unclear;
        continue;
      }
      float ts = 0;
      int steps = 0;
      const bool traced = sphere_trace(t, lip, r, config, ts, steps);
      INFO("noise " << int(kind) << " ray " << i << " steps " << steps);
      REQUIRE(traced == brute.hit);
      if (!traced) {
        ++misses;
        continue;
      }
      ++hits;
      const float f_hit = sdf_eval(t, r.org + r.dir * ts);
      REQUIRE(std::abs(f_hit) / lip < 1e-4f);
      if (f_hit <= 0) {  // bisected to just past the crossing, as the march's bisection is
        ++refined;
        REQUIRE(ts == Approx(brute.t).margin(1e-5));
        continue;
      }
      // Otherwise the tracer stopped where |f| / L < eps, up to eps L / slope before the
      // crossing, where slope = |df/dt| there (small on grazing rays).
      const float eps = std::max(config.absolute_epsilon, config.relative_epsilon * ts);
      const float h = 1e-4f;
      const float slope =
          std::abs(sdf_eval(t, r.org + r.dir * (brute.t + h)) - sdf_eval(t, r.org + r.dir * (brute.t - h))) /
          (2 * h);
      REQUIRE(ts == Approx(brute.t).margin(1e-3 + 2 * eps * lip / slope));
    }
    INFO("noise " << int(kind) << ": " << hits << " hits, " << misses << " misses, " << unclear
                  << " unclear");
    CHECK(hits > 100);
    CHECK(misses > 20);
    CHECK(unclear < rays / 10);
    // Although L exceeds the rays' slopes, hits are refined to the crossing (the tracer looks
    // ahead by the secant estimate), not left where |f| / L first fell below the tolerance.
    CHECK(refined >= hits - hits / 50);
  }
}

TEST_CASE("sdf: the displacement-shell march finds the same hits as the full march",
          "[shapes][sdf][noise][quick]") {
  // The same displaced, moved sphere once as the root (marched to its shell with the child's
  // bound first) and once under a union with a far-away sphere (marched with the full bound
  // from the start): the same rays hit, at the same distances.
  SdfTree root = displaced_sphere(1, 0.15f, 2.5f);
  root.nodes[size_t(root.root)].to_local = moved_by({0.2f, -0.1f, 0.3f});
  SdfTree wrapped = root;
  const int far = add_node(wrapped, sdf_primitive(SdfKind::Sphere, {0.1f, 0, 0}));
  wrapped.nodes[size_t(far)].to_local = moved_by({50, 50, 50});
  wrapped.root = add_node(wrapped, sdf_operator(SdfKind::Union, root.root, far));
  const float lr = sdf_lipschitz(root), lw = sdf_lipschitz(wrapped);
  REQUIRE(lr == Approx(lw).epsilon(1e-5));  // the union adds nothing but rounding
  SphereTraceConfig cfg;
  cfg.max_steps = 4096;
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-1, 1);
  int hits = 0, fewer = 0;
  for (int i = 0; i < 400; ++i) {
    Ray r;
    r.org = Vec3f{u(rng), u(rng), u(rng)} * 0.3f + Vec3f{0, 0, 5};
    r.dir = normalize(Vec3f{u(rng) * 0.3f, u(rng) * 0.3f, -1});
    r.tnear = 0;
    r.tfar = 20;
    float tr = 0, tw = 0;
    int sr = 0, sw = 0;
    const bool hr = sphere_trace(root, lr, r, cfg, tr, sr), hw = sphere_trace(wrapped, lw, r, cfg, tw, sw);
    REQUIRE(hr == hw);
    if (!hr) continue;
    ++hits;
    CHECK(tr == Approx(tw).margin(1e-4));
    fewer += sr < sw;
  }
  CHECK(hits > 150);
  CHECK(fewer > hits / 2);  // the shell march saves noise evaluations on most hits
}

TEST_CASE("sdf: grazing rays hit displaced spheres of zero and tiny amplitude as the sphere itself",
          "[shapes][sdf][noise][quick]") {
  // Rays along -z at impact parameters up to 0.999 of a unit sphere: with amplitude 0 the
  // displaced tree is the sphere (hit iff b < 1, at t = 5 - sqrt(1 - b^2)); with amplitude 1e-4
  // the same within the amplitude. Neither may run out of steps in the shell march.
  for (float amplitude : {0.0f, 1e-4f}) {
    const SdfTree t = displaced_sphere(1, amplitude, 3);
    const float lip = sdf_lipschitz(t);
    SphereTraceConfig cfg;
    for (float b : {0.0f, 0.5f, 0.9f, 0.99f, 0.995f, 0.999f, 1.002f, 1.01f}) {
      Ray r;
      r.org = {b, 0, 5};
      r.dir = {0, 0, -1};
      r.tnear = 0;
      r.tfar = 10;
      float th = 0;
      int steps = 0;
      const bool hit = sphere_trace(t, lip, r, cfg, th, steps);
      INFO("amplitude " << amplitude << " b " << b << " steps " << steps);
      REQUIRE(hit == (b < 1));
      if (hit) CHECK(th == Approx(5 - std::sqrt(1 - b * b)).margin(2e-3 + 40 * amplitude));
    }
  }
}

namespace {

void test_vec_near(Vec3f a, Vec3f b, float eps = 1e-5f) {
  CHECK(a.x == Approx(b.x).margin(eps));
  CHECK(a.y == Approx(b.y).margin(eps));
  CHECK(a.z == Approx(b.z).margin(eps));
}

}  // namespace

TEST_CASE("sdf: a polyhedron of a cube mesh gives the box's exact signed distance",
          "[shapes][sdf][polyhedron][quick]") {
  SdfTree t;
  t.root = add_node(t, sdf_polyhedron(t, box_mesh({-1, -1, -1}, {1, 1, 1})));
  // Faces, edges, corners and the inside, against the closed form.
  CHECK(sdf_eval(t, {3, 0, 0}) == Approx(2));
  CHECK(sdf_eval(t, {0, 0, -4}) == Approx(3));
  CHECK(sdf_eval(t, {2, 2, 0}) == Approx(std::sqrt(2.0f)));
  CHECK(sdf_eval(t, {2, 2, 2}) == Approx(std::sqrt(3.0f)));
  CHECK(sdf_eval(t, {0.5f, 0, 0}) == Approx(-0.5f));
  CHECK(sdf_eval(t, {0, 0, 0}) == Approx(-1));
  CHECK(sdf_eval(t, {0, 0.25f, 0.9f}) == Approx(-0.1f));
  CHECK(sdf_lipschitz(t) == Approx(1));
  const Bounds3f b = sdf_tree_bounds(t);
  test_vec_near(b.lo, {-1, -1, -1});
  test_vec_near(b.hi, {1, 1, 1});
  // Everywhere, for the shared, the split (24-vertex) and the inward-wound mesh, moved and turned.
  const SdfTree box = single_shape(sdf_primitive(SdfKind::Box, {1, 1, 1}));
  SdfTree split, inward, moved, moved_box = box;
  split.root = add_node(split, sdf_polyhedron(split, split_box_mesh({-1, -1, -1}, {1, 1, 1})));
  inward.root = add_node(inward, sdf_polyhedron(inward, box_mesh({-1, -1, -1}, {1, 1, 1}).flipped()));
  SdfNode m = sdf_polyhedron(moved, box_mesh({-1, -1, -1}, {1, 1, 1}));
  Affine3f turn = moved_by({0.5f, -1, 2});
  const float c = std::cos(0.4f), s = std::sin(0.4f);
  turn.m[0][0] = c, turn.m[0][1] = -s, turn.m[1][0] = s, turn.m[1][1] = c;
  m.to_local = turn;
  moved.root = add_node(moved, m);
  moved_box.nodes[0].to_local = turn;
  std::mt19937 rng(21);
  int gradients = 0;
  for (int i = 0; i < 5000; ++i) {
    const Vec3f p = random_point(rng, 3);
    const float expected = sdf_eval(box, p);
    REQUIRE(sdf_eval(t, p) == Approx(expected).margin(1e-5));
    REQUIRE(sdf_eval(split, p) == Approx(expected).margin(1e-5));
    REQUIRE(sdf_eval(inward, p) == Approx(expected).margin(1e-5));
    REQUIRE(sdf_eval(moved, p) == Approx(sdf_eval(moved_box, p)).margin(1e-5));
    // The gradient where the box's is unique (central differences at two steps agree).
    const Vec3f n1 = sdf_normal(box, p, 1e-3f), n2 = sdf_normal(box, p, 2e-3f);
    if (!(dot(n1, n2) > 0.99999f)) continue;
    REQUIRE(dot(sdf_gradient_normal(t, p), sdf_gradient_normal(box, p)) > 0.999f);
    ++gradients;
  }
  CHECK(gradients > 4000);
}

TEST_CASE("sdf: polyhedra of concave meshes are Lipschitz 1", "[shapes][sdf][polyhedron][quick]") {
  std::mt19937 rng(22);
  for (const TriMesh& mesh : {l_prism_mesh(), ring_mesh(1, 0.35f, 24, 12), icosphere_mesh(1, 1.8f)}) {
    SdfTree t;
    SdfNode n = sdf_polyhedron(t, mesh);
    n.to_local = moved_by({0.2f, 0.1f, -0.3f});
    t.root = add_node(t, n);
    REQUIRE(sdf_lipschitz(t) == Approx(1));
    int inside = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3f x = random_point(rng, 2.2f), y = x + random_point(rng, 0.3f);
      const float fx = sdf_eval(t, x);
      inside += fx < 0;
      REQUIRE(std::abs(fx - sdf_eval(t, y)) <= length(x - y) + 1e-5f);
    }
    CHECK(inside > 100);
  }
}

TEST_CASE("sdf: sphere tracing a cube mesh minus a sphere agrees with the analytic CSG",
          "[shapes][sdf][polyhedron][quick]") {
  const auto cube_minus_sphere = [](bool mesh) {
    SdfTree t;
    const int cube = add_node(t, mesh ? sdf_polyhedron(t, box_mesh({-1, -1, -1}, {1, 1, 1}))
                                      : sdf_primitive(SdfKind::Box, {1, 1, 1}));
    SdfNode ball = sdf_primitive(SdfKind::Sphere, {1.25f, 0, 0});
    ball.to_local = moved_by({0.3f, 0.2f, 0.1f});
    t.root = add_node(t, sdf_operator(SdfKind::Subtraction, cube, add_node(t, ball)));
    return make_implicit_shape(t);
  };
  const Shape mesh = cube_minus_sphere(true), analytic = cube_minus_sphere(false);
  CHECK(mesh.lipschitz == analytic.lipschitz);
  test_vec_near(mesh.sdf_bounds.lo, analytic.sdf_bounds.lo);
  test_vec_near(mesh.sdf_bounds.hi, analytic.sdf_bounds.hi);
  std::mt19937 rng(23);
  std::normal_distribution<float> g;
  int hits = 0, misses = 0, disagreements = 0, normals = 0;
  for (int i = 0; i < 2000; ++i) {
    Ray r;
    r.org = normalize(Vec3f{g(rng), g(rng), g(rng)}) * 5;
    r.dir = random_point(rng, 1.3f) - r.org;
    ShapeHit hm, ha;
    const bool a = intersect_shape(analytic, r, ha), m = intersect_shape(mesh, r, hm);
    if (a != m) {
      ++disagreements;
      continue;
    }
    if (!a) {
      ++misses;
      continue;
    }
    ++hits;
    REQUIRE(hm.t * length(r.dir) == Approx(ha.t * length(r.dir)).margin(1e-3));
    const Vec3f p = r.org + r.dir * ha.t;
    const Vec3f n1 = sdf_normal(analytic.sdf, p, 1e-3f), n2 = sdf_normal(analytic.sdf, p, 2e-3f);
    if (!(dot(n1, n2) > 0.9999f)) continue;  // an edge of the cube or of the cut
    CHECK(dot(shape_surface(mesh, r.org + r.dir * hm.t, 1e-3f).n, shape_surface(analytic, p, 1e-3f).n) >
          0.99f);
    ++normals;
  }
  CHECK(disagreements <= 2);  // rays grazing an edge within the tracing tolerance
  CHECK(hits > 800);
  CHECK(misses > 100);
  CHECK(normals > 600);
}
