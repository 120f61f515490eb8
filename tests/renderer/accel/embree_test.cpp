// Tests for renderer/accel/embree: the same closest hits as the brute-force oracle on analytic
// cases (single level and instanced), occlusion == hit flag, empty scenes, configuration
// checks and the version string.
#include "renderer/accel/embree.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "renderer/accel/brute.h"
#include "renderer/accel/factory.h"

using namespace penumbra;

namespace {
// A unit quad at z = 0 (two triangles sharing the diagonal) and a triangle at z = -1.
struct Analytic {
  std::vector<Vec3f> quad{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  std::vector<uint32_t> quad_idx{0, 1, 2, 0, 2, 3};
  std::vector<Vec3f> tri{{-1, -1, -1}, {3, -1, -1}, {-1, 3, -1}};
  std::vector<uint32_t> tri_idx{0, 1, 2};
  std::vector<GeometryView> views{{quad, quad_idx}, {tri, tri_idx}};
};

std::vector<Ray> analytic_rays() {
  std::vector<Ray> rays;
  for (float x : {-0.5f, 0.1f, 0.25f, 0.5f, 0.75f, 0.9f, 1.5f})
    for (float y : {-0.5f, 0.2f, 0.5f, 0.8f, 1.5f}) {
      rays.push_back({{x, y, 1}, 0, {0, 0, -1}, kInfinity});  // straight down
      rays.push_back({{x, y, 1}, 0, {0.1f, -0.05f, -1}, kInfinity});
      rays.push_back({{x, y, -3}, 0, {0, 0, 1}, kInfinity});      // from below
      rays.push_back({{x, y, 1}, 0, {0, 0, -1}, 0.5f});           // too short
      rays.push_back({{x, y, 1}, 1.25f, {0, 0, -1}, kInfinity});  // starts between the layers
    }
  return rays;
}

void check_same(const Accelerator& embree, const Accelerator& brute, const Ray& r) {
  Hit he, hb;
  const bool e = embree.intersect(r, he), b = brute.intersect(r, hb);
  INFO("ray org " << r.org.x << "," << r.org.y << "," << r.org.z << " dir " << r.dir.x << "," << r.dir.y
                  << "," << r.dir.z << " tnear " << r.tnear << " tfar " << r.tfar);
  REQUIRE(e == b);
  CHECK(embree.occluded(r) == e);
  if (!e) return;
  CHECK(he.t == Approx(hb.t).epsilon(1e-5));
  CHECK(he.geom_id == hb.geom_id);
  // The diagonal is shared by both quad triangles: either may report it.
  const bool on_diagonal = std::fabs((r.org.x + r.dir.x * hb.t) - (r.org.y + r.dir.y * hb.t)) < 1e-5f;
  if (!on_diagonal) CHECK(he.prim_id == hb.prim_id);
}
}  // namespace

TEST_CASE("embree: the same hits as brute force on analytic cases", "[accel][embree][quick]") {
  Analytic s;
  const auto embree = make_embree_accelerator(s.views);
  const auto brute = make_brute_accelerator(s.views);
  for (const Ray& r : analytic_rays()) check_same(*embree, *brute, r);
  Hit h;
  REQUIRE(embree->intersect({{0.75f, 0.25f, 1}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == Approx(1));
  CHECK(h.geom_id == 0);
  CHECK(h.prim_id == 0);
}

TEST_CASE("embree: instanced placements hit as the brute-force two-level build", "[accel][embree][quick]") {
  Analytic s;
  const std::vector<InstanceView> instances{
      {0, Affine3f{}}, {1, Affine3f{}}, {0, to_affine(translate(0, 0, -0.5))}};
  const auto embree = make_accelerator("embree", s.views, instances);
  const auto brute = make_accelerator("brute", s.views, instances);
  for (const Ray& r : analytic_rays()) check_same(*embree, *brute, r);
  Hit h;  // below the first quad, the translated copy (instance 2) is next
  REQUIRE(embree->intersect({{0.75f, 0.25f, -0.1f}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == Approx(0.4f));
  CHECK(h.geom_id == 2);
}

TEST_CASE("embree: empty scenes miss, invalid settings are refused", "[accel][embree][quick]") {
  const auto empty = make_embree_accelerator({});
  Hit h;
  CHECK_FALSE(empty->intersect({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}, h));
  CHECK_FALSE(empty->occluded({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}));
  CHECK_THROWS_AS(validate(EmbreeConfig{true, 3}), std::invalid_argument);
  CHECK_THROWS_AS(validate(EmbreeConfig{true, -1}), std::invalid_argument);
  CHECK_NOTHROW(validate(EmbreeConfig{false, 2}));
  CHECK_FALSE(embree_version().empty());
}

TEST_CASE("embree: rays whose object-space versions leave Embree's range are restarted, not aborted",
          "[accel][embree][quick]") {
  // A sphere of radius 1e10 scaled by 1e-10 (radius 1 in the world) seen from 1e12 away: the
  // object-space origin (1e22) is beyond Embree's 1.8e18, which its traversal asserts.
  Shape sphere;
  sphere.radius = 1e10f;
  const std::vector<GeometryView> views{{{}, {}, &sphere}};
  const std::vector<InstanceView> instances{{0, to_affine(scale(1e-10, 1e-10, 1e-10))}};
  const auto embree = make_accelerator("embree", views, instances);
  Hit h;
  REQUIRE(embree->intersect({{0, 0, 1e12f}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == Approx(1e12f - 1).epsilon(1e-6));
  CHECK(embree->occluded({{0, 0, 1e12f}, 0, {0, 0, -1}, kInfinity}));
  CHECK_FALSE(embree->occluded({{0, 0, 1e12f}, 0, {0, 0, -1}, 1e11f}));          // ends before the sphere
  CHECK_FALSE(embree->intersect({{0, 3, 1e12f}, 0, {0, 0, -1}, kInfinity}, h));  // passes beside it
  // An unnormalised direction: t stays in the query's units.
  REQUIRE(embree->intersect({{0, 0, 1e12f}, 0, {0, 0, -4}, kInfinity}, h));
  CHECK(h.t == Approx((1e12f - 1) / 4).epsilon(1e-6));
  // An ordinary ray near the sphere is passed unchanged and agrees with brute force.
  const auto brute = make_accelerator("brute", views, instances);
  Hit b;
  REQUIRE(embree->intersect({{0, 0, 5}, 0, {0, 0, -1}, kInfinity}, h));
  REQUIRE(brute->intersect({{0, 0, 5}, 0, {0, 0, -1}, kInfinity}, b));
  CHECK(h.t == Approx(b.t).epsilon(1e-6));
}
