// Tests for renderer/lights/area: which triangles and shapes are lights, selection by power
// (area, emission, sidedness), points on the chosen light and the density it reports: uniform
// on triangles; on shapes the density integrates to the world area (or, for a sphere sampled by
// its cone, to the visible cap) and the irradiance it estimates equals the closed forms.
#include "renderer/lights/area.h"

#include <catch2/catch.hpp>

#include "renderer/core/rng.h"
#include "renderer/shapes/shape_sampling.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
// Choice by power, from a point below the scene (where the point is does not matter to it).
const LightChoice kPower{{0, 0, -10}, {}, LightSampler::Power};
}  // namespace

TEST_CASE("area lights: power-proportional choice, uniform points, consistent density", "[lights][quick]") {
  Scene s;
  const int grey = add_lambert(s, {0.5f, 0.5f, 0.5f});
  const int bright = add_lambert(s, {0, 0, 0}, {4, 4, 4}, /*double_sided=*/false);
  const int dim = add_lambert(s, {0, 0, 0}, {1, 1, 1}, /*double_sided=*/true);
  add_quad_z(s, -5, 5, -5, 5, 0, grey);        // instance 0: not a light
  add_quad_z(s, 0, 1, 0, 1, 2, bright, true);  // instance 1: area 1, one-sided, L = 4 -> power 4
  add_quad_z(s, 0, 2, 0, 1, 3, dim);           // instance 2: area 2, two-sided, L = 1 -> power 4
  // An instanced copy of the dim quad scaled by 2 in x and y: area 8, power 16.
  s.instances.push_back(make_instance(2, to_affine(scale(2, 2, 1))));
  const AreaLights al = build_area_lights(s);
  REQUIRE(al.triangles.size() == 6);
  CHECK(al.first[0] == -1);
  CHECK(al.first[1] == 0);
  double sum = 0;
  for (float p : al.pmf) sum += p;
  CHECK(sum == Approx(1));
  // Power shares 4 : 4 : 16 over the three quads, split evenly between their two triangles.
  CHECK(al.pmf[0] + al.pmf[1] == Approx(4.0 / 24));
  CHECK(al.pmf[2] + al.pmf[3] == Approx(4.0 / 24));
  CHECK(al.pmf[4] + al.pmf[5] == Approx(16.0 / 24));
  CHECK(area_light_pdf(al, kPower, 0, 0, world_triangle(s, s.instances[0], 0)) == 0);
  CHECK(area_light_pdf(al, kPower, 3, 1, world_triangle(s, s.instances[3], 1)) ==
        Approx(al.pmf[5] / 4.0));  // each triangle of the big copy: area 4

  // Samples land on the chosen triangle, uniformly: the mean of the points on the big copy is
  // its centroid, and the chosen shares match the pmf.
  Rng rng;
  int counts[4] = {0, 0, 0, 0};
  Vec3f mean_big{0, 0, 0};
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    AreaLightSample ls;
    REQUIRE(sample_area_light(al, s, kPower, 0, rng.next_float(), {rng.next_float(), rng.next_float()}, ls));
    REQUIRE(ls.instance >= 1);
    ++counts[ls.instance];
    REQUIRE(ls.pdf_area == Approx(area_light_pdf(al, kPower, ls.instance, ls.prim, ls.tri)));
    const WorldTriangle tri = world_triangle(s, s.instances[ls.instance], ls.prim);
    check_vec(ls.p, tri.p[0] * (1 - ls.u - ls.v) + tri.p[1] * ls.u + tri.p[2] * ls.v, 1e-5f);
    REQUIRE(ls.u >= 0);
    REQUIRE(ls.v >= 0);
    REQUIRE(ls.u + ls.v <= 1.0001f);
    if (ls.instance == 3) mean_big += ls.p;
  }
  CHECK(double(counts[1]) / n == Approx(4.0 / 24).epsilon(0.02));
  CHECK(double(counts[3]) / n == Approx(16.0 / 24).epsilon(0.02));
  check_vec(mean_big / float(counts[3]), {2, 1, 3}, 0.01f);
  // The quad facing down has its front normal -z.
  AreaLightSample ls;
  REQUIRE(sample_area_light(al, s, kPower, 0, 0.01f, {0.5f, 0.5f}, ls));
  CHECK(ls.instance == 1);
  check_vec(ls.ng, {0, 0, -1});
}

TEST_CASE("area lights: a scene without emission has none", "[lights][quick]") {
  Scene s;
  add_quad_z(s, 0, 1, 0, 1, 0, add_lambert(s, {1, 1, 1}));
  const AreaLights al = build_area_lights(s);
  CHECK(al.pmf.empty());
  AreaLightSample ls;
  CHECK_FALSE(sample_area_light(al, s, kPower, 0, 0.5f, {0.5f, 0.5f}, ls));
}

TEST_CASE("area lights: a moving light is sampled where it is at the sample's time",
          "[lights][quick][motion]") {
  // A unit emissive quad at z = 2 whose instance slides +4 in x and doubles in x and y over the
  // shutter (keys at times 0 and 1): at time 0.5 it spans x in [2, 3.5], y in [0, 1.5] (area 2.25).
  Scene s;
  add_quad_z(s, 0, 1, 0, 1, 2, add_lambert(s, {0, 0, 0}, {1, 1, 1}, /*double_sided=*/true));
  s.instance_motion = {{decompose_motion(to_affine(scale(1, 1, 1))),
                        decompose_motion(to_affine(translate(4, 0, 0) * scale(2, 2, 1)))}};
  const AreaLights al = build_area_lights(s);
  REQUIRE(al.triangles.size() == 2);
  CHECK(al.triangles[0].moves);
  Rng rng;
  Vec3f lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (int i = 0; i < 20000; ++i) {
    AreaLightSample ls;
    REQUIRE(
        sample_area_light(al, s, kPower, 0.5f, rng.next_float(), {rng.next_float(), rng.next_float()}, ls));
    lo = min(lo, ls.p);
    hi = max(hi, ls.p);
    // The density is the pmf over the area at that time, as a ray hitting the light then reports.
    REQUIRE(ls.pdf_area == Approx(al.pmf[ls.prim] / 1.125));
    REQUIRE(area_light_pdf(al, kPower, 0, ls.prim, ls.tri) == Approx(ls.pdf_area));
  }
  check_vec(lo, {2, 0, 2}, 0.02f);
  check_vec(hi, {3.5f, 1.5f, 2}, 0.02f);
  // At the frame's time (the scene's own map) the stored triangle and area hold.
  CHECK(area_light_pdf(al, kPower, 0, 0, al.triangles[0].tri) == Approx(al.pmf[0] / 0.5));
}

namespace {

Shape make_kind(ShapeKind kind) {
  Shape sh;
  sh.kind = kind;
  sh.radius = 0.5f;
  sh.half_height = 0.75f;
  sh.half_size = {0.5f, 0.25f, 1.0f};
  return sh;
}

// A map with rotation, unequal scales and shear, then a translation.
Affine3f skewed(Vec3f t) {
  Affine3f a = translation(t);
  const float l[3][3] = {{1.2f, 0.3f, 0.0f}, {-0.2f, 0.7f, 0.4f}, {0.1f, 0.0f, 1.6f}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a.m[r][c] = l[r][c];
  return a;
}

// Rotation by 0.6 rad about z, uniform scale 1.5, translation t.
Affine3f similar(Vec3f t) {
  Affine3f a = translation(t);
  const float c = std::cos(0.6f) * 1.5f, s = std::sin(0.6f) * 1.5f;
  a.m[0][0] = c, a.m[0][1] = -s, a.m[1][0] = s, a.m[1][1] = c, a.m[2][2] = 1.5f;
  return a;
}

// World area of the shape under `a` by a fine midpoint rule over its object-space surface:
// the mean area scale over uniform object-space points (a regular grid of u) times the area.
double world_area(const Shape& sh, const Affine3f& a) {
  Affine3f inv;
  REQUIRE(inverse(a, inv));
  double sum = 0;
  const int n = 400;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const ShapePoint sp = sample_shape_area(sh, {(float(i) + 0.5f) / n, (float(j) + 0.5f) / n});
      sum += double(area_scale(a, inv, sp.n));
    }
  return sum / (double(n) * n) * double(shape_area(sh));
}

}  // namespace

TEST_CASE("shape lights: object-space areas and uniform points on each analytic shape",
          "[lights][shapes][quick]") {
  for (ShapeKind kind :
       {ShapeKind::Sphere, ShapeKind::Plane, ShapeKind::Disk, ShapeKind::Box, ShapeKind::Capsule}) {
    const Shape sh = make_kind(kind);
    INFO(shape_kind_name(kind));
    // The closed forms of shape_area against the surface the ray test sees: every sampled point
    // lies on it (a ray from outside along -n hits it there) and its normal is the surface's.
    Rng rng;
    Vec3f mean{0, 0, 0};
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const ShapePoint sp = sample_shape_area(sh, {rng.next_float(), rng.next_float()});
      mean += sp.p;
      check_vec(shape_surface(sh, sp.p, 1e-4f).n, sp.n, 1e-4f);
      const Ray r{sp.p + sp.n * 3.0f, 0, -sp.n, kInfinity};
      ShapeHit hit;
      REQUIRE(intersect_shape(sh, r, hit));
      REQUIRE(hit.t == Approx(3.0f).margin(1e-4));
    }
    check_vec(mean / float(n), {0, 0, 0}, 0.02f);  // symmetric shapes: the mean point is the centre
  }
  CHECK(shape_area(make_kind(ShapeKind::Sphere)) == Approx(kPi));
  CHECK(shape_area(make_kind(ShapeKind::Disk)) == Approx(kPi / 4));
  CHECK(shape_area(make_kind(ShapeKind::Plane)) == Approx(2.0));
  CHECK(shape_area(make_kind(ShapeKind::Box)) == Approx(8 * (0.125 + 0.25 + 0.5)));
  CHECK(shape_area(make_kind(ShapeKind::Capsule)) == Approx(4 * kPi * 0.5 * 1.25));
  CHECK(shape_area(sphere_shape(1, true)) == 0);  // implicit shapes are not sampled
}

TEST_CASE("shape lights: the density matches its evaluation and integrates to the world area",
          "[lights][shapes]") {
  const Vec3f ref{0.3f, -6, 0.8f};
  for (ShapeKind kind :
       {ShapeKind::Sphere, ShapeKind::Plane, ShapeKind::Disk, ShapeKind::Box, ShapeKind::Capsule})
    for (bool shear : {false, true}) {
      const Shape sh = make_kind(kind);
      Scene s;
      const Affine3f a = shear ? skewed({0, 1, 0.5f}) : similar({0, 1, 0.5f});
      add_shape(s, sh, a, add_lambert(s, {0, 0, 0}, {1, 1, 1}));
      const AreaLights al = build_area_lights(s);
      REQUIRE(al.shapes.size() == 1);
      REQUIRE(al.first[0] == 0);
      const bool cone = kind == ShapeKind::Sphere && !shear;
      // Expected integral of 1 / pdf: the world area; a sphere sampled by its cone covers the
      // cap visible from ref, 2 pi R^2 (1 - R / d).
      const float radius = 0.5f * 1.5f, d = length(Vec3f{0, 1, 0.5f} - ref);
      const double expected = cone ? 2 * kPi * radius * radius * (1 - radius / d) : world_area(sh, a);
      INFO(shape_kind_name(kind) << (shear ? " sheared" : " similar") << ": expected " << expected);
      Rng rng = make_pixel_rng(0, 0, 0, uint64_t(kind) * 2 + shear);
      double sum = 0;
      const int n = 100000;
      for (int i = 0; i < n; ++i) {
        AreaLightSample ls;
        REQUIRE(sample_area_light(al, s, {ref, {}, LightSampler::Power}, 0, rng.next_float(),
                                  {rng.next_float(), rng.next_float()}, ls));
        REQUIRE(ls.shape);
        REQUIRE(ls.pdf_area > 0);
        REQUIRE(shape_light_pdf(al, s, {ref, {}, LightSampler::Power}, 0, ls.p, 0) ==
                Approx(ls.pdf_area).epsilon(2e-3));
        // The point is on the placed shape.
        Affine3f inv;
        REQUIRE(inverse(a, inv));
        const Vec3f q = apply_point(inv, ls.p);
        check_vec(apply_point(a, snap_to_shape(sh, q)), ls.p, 2e-4f);
        sum += 1.0 / double(ls.pdf_area);
      }
      // 1 / pdf grows without bound at a cone's rim (the area seen edge-on): a looser bound there.
      CHECK(sum / n == Approx(expected).epsilon(cone ? 0.02 : 0.01));
    }
  // An implicit shape emits when hit but is not sampled.
  Scene s;
  add_shape(s, sphere_shape(1, true), translation({0, 2, 0}), add_lambert(s, {0, 0, 0}, {1, 1, 1}));
  const AreaLights al = build_area_lights(s);
  CHECK(al.pmf.empty());
  CHECK(al.first[0] == -1);
  CHECK(shape_light_pdf(al, s, {ref, {}, LightSampler::Power}, 0, {0, 1, 0}, 0) == 0);
}

TEST_CASE("shape lights: irradiance from an emissive sphere and disk equals the closed forms",
          "[lights][shapes]") {
  // A sphere of radius R and radiance L at distance d from a point facing its centre gives
  // E = pi L sin^2(theta) with sin(theta) = R / d; a disk of radius r at height h on its axis
  // gives E = pi L r^2 / (r^2 + h^2). Both estimated by light sampling: mean of
  // L cos(theta_x) / pdf(solid angle).
  const float L = 3;
  struct Case {
    Shape shape;
    Affine3f to_world;
    double expected;
  };
  Shape disk = make_kind(ShapeKind::Disk);
  disk.radius = 1.5f;
  Affine3f flip;  // the disk faces -y, towards the point below it
  flip.m[1][1] = -1, flip.m[2][2] = -1;
  flip.m[1][3] = 2;
  std::vector<Case> cases = {
      {sphere_shape(1), translation({0, 4, 0}), kPi * L / 16},
      {sphere_shape(2), translation({0, 2.1f, 0}), kPi * L * (4 / (2.1 * 2.1))},
      {sphere_shape(0.01f), translation({0, 50, 0}), kPi * L * (0.01 / 50) * (0.01 / 50)},
      {disk, flip, kPi * L * 1.5 * 1.5 / (1.5 * 1.5 + 4)},
  };
  for (const Case& c : cases) {
    Scene s;
    add_shape(s, c.shape, c.to_world, add_lambert(s, {0, 0, 0}, {L, L, L}, /*double_sided=*/false));
    const AreaLights al = build_area_lights(s);
    const Vec3f x{0, 0, 0}, nx{0, 1, 0};
    Rng rng = make_pixel_rng(0, 0, 0, 11);
    double sum = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      AreaLightSample ls;
      REQUIRE(sample_area_light(al, s, {x, nx, LightSampler::Tree}, 0, rng.next_float(),
                                {rng.next_float(), rng.next_float()}, ls));
      const Vec3f d = ls.p - x;
      const float dist2 = dot(d, d);
      const Vec3f wi = d / std::sqrt(dist2);
      const float cos_l = -dot(ls.ng, wi);
      if (!(cos_l > 0)) continue;  // the far side of a sphere sampled by area: not seen
      const double pdf_sa = double(ls.pdf_area) * dist2 / cos_l;
      sum += L * std::max(0.0f, dot(nx, wi)) / pdf_sa;
    }
    INFO("expected " << c.expected);
    CHECK(sum / n == Approx(c.expected).epsilon(0.005));
  }
}
