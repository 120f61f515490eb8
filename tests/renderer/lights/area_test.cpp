// Tests for renderer/area_lights: which triangles are lights, selection by power (area,
// emission, sidedness), uniform points on the chosen triangle, and the density it reports.
#include "renderer/lights/area.h"

#include <catch2/catch.hpp>

#include "renderer/core/rng.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

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
  CHECK(area_light_pdf(al, 0, 0) == 0);
  CHECK(area_light_pdf(al, 3, 1) == Approx(al.pmf[5] / 4.0));  // each triangle of the big copy: area 4

  // Samples land on the chosen triangle, uniformly: the mean of the points on the big copy is
  // its centroid, and the chosen shares match the pmf.
  Rng rng;
  int counts[4] = {0, 0, 0, 0};
  Vec3f mean_big{0, 0, 0};
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    AreaLightSample ls;
    REQUIRE(sample_area_light(al, s, 0, rng.next_float(), {rng.next_float(), rng.next_float()}, ls));
    REQUIRE(ls.instance >= 1);
    ++counts[ls.instance];
    REQUIRE(ls.pdf_area == Approx(area_light_pdf(al, ls.instance, ls.prim)));
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
  REQUIRE(sample_area_light(al, s, 0, 0.01f, {0.5f, 0.5f}, ls));
  CHECK(ls.instance == 1);
  check_vec(ls.ng, {0, 0, -1});
}

TEST_CASE("area lights: a scene without emission has none", "[lights][quick]") {
  Scene s;
  add_quad_z(s, 0, 1, 0, 1, 0, add_lambert(s, {1, 1, 1}));
  const AreaLights al = build_area_lights(s);
  CHECK(al.pmf.empty());
  AreaLightSample ls;
  CHECK_FALSE(sample_area_light(al, s, 0, 0.5f, {0.5f, 0.5f}, ls));
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
    REQUIRE(sample_area_light(al, s, 0.5f, rng.next_float(), {rng.next_float(), rng.next_float()}, ls));
    lo = min(lo, ls.p);
    hi = max(hi, ls.p);
    // The density is the pmf over the area at that time, as a ray hitting the light then reports.
    REQUIRE(ls.pdf_area == Approx(al.pmf[ls.prim] / 1.125));
    REQUIRE(area_light_pdf(al, 0, ls.prim, ls.tri) == Approx(ls.pdf_area));
  }
  check_vec(lo, {2, 0, 2}, 0.02f);
  check_vec(hi, {3.5f, 1.5f, 2}, 0.02f);
  // At the frame's time (the scene's own map) the stored triangle and area hold.
  CHECK(area_light_pdf(al, 0, 0) == Approx(al.pmf[0] / 0.5));
}
