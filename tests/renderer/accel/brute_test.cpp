// Tests for renderer/accel/brute, the oracle of every accelerator test: closest hits, ids and
// barycentrics against hand-computed values, the [tnear, tfar] range, occlusion == hit flag,
// empty scenes and invalid (NaN, infinite, zero-direction) rays.
#include "renderer/accel/brute.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

using namespace penumbra;

namespace {
// Triangle (-1,-1,z) (1,-1,z) (0,1,z): the ray down the z axis meets it at x = y = 0, where
// p = (1-u-v) a + u b + v c gives v = 1/2, u = 1/4.
struct TwoLayers {
  std::vector<Vec3f> near_pos{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  std::vector<Vec3f> far_pos{{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}, {5, 5, -2}, {6, 5, -2}, {5, 6, -2}};
  std::vector<uint32_t> one{0, 1, 2};
  std::vector<uint32_t> two{3, 4, 5, 0, 1, 2};  // the hit triangle is prim 1
  std::vector<GeometryView> views{{near_pos, one}, {far_pos, two}};
};
}  // namespace

TEST_CASE("brute: the closest hit with hand-computed t, ids and barycentrics", "[accel][quick]") {
  TwoLayers s;
  const auto accel = make_brute_accelerator(s.views);
  Hit h;
  REQUIRE(accel->intersect({{0, 0, 1}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == Approx(1));
  CHECK(h.geom_id == 0);
  CHECK(h.prim_id == 0);
  CHECK(h.u == Approx(0.25f));
  CHECK(h.v == Approx(0.5f));

  // A direction of length 2 halves t; starting below the near layer finds the far one.
  Hit h2;
  REQUIRE(accel->intersect({{0, 0, 1}, 0, {0, 0, -2}, kInfinity}, h2));
  CHECK(h2.t == Approx(0.5f));
  Hit h3;
  REQUIRE(accel->intersect({{0, 0, -1}, 0, {0, 0, -1}, kInfinity}, h3));
  CHECK(h3.t == Approx(1));
  CHECK(h3.geom_id == 1);
  CHECK(h3.prim_id == 1);
}

TEST_CASE("brute: tnear and tfar bound the hits, occluded() agrees with intersect()", "[accel][quick]") {
  TwoLayers s;
  const auto accel = make_brute_accelerator(s.views);
  struct Case {
    Ray ray;
    bool hit;
    float t;
    uint32_t geom;
  };
  const Case cases[] = {
      {{{0, 0, 1}, 0, {0, 0, -1}, 0.5f}, false, 0, 0},         // ends before the near layer
      {{{0, 0, 1}, 0, {0, 0, -1}, 1.0f}, true, 1, 0},          // ends exactly on it
      {{{0, 0, 1}, 1.5f, {0, 0, -1}, kInfinity}, true, 3, 1},  // starts past it
      {{{0, 0, 1}, 3.5f, {0, 0, -1}, kInfinity}, false, 0, 0},
      {{{0, 0, 1}, 0, {0, 0, 1}, kInfinity}, false, 0, 0},   // away from both
      {{{3, 3, 1}, 0, {0, 0, -1}, kInfinity}, false, 0, 0},  // beside both
      {{{5.25f, 5.25f, 1}, 0, {0, 0, -1}, kInfinity}, true, 3, 1},
  };
  for (const Case& c : cases) {
    Hit h;
    const bool hit = accel->intersect(c.ray, h);
    CHECK(hit == c.hit);
    CHECK(accel->occluded(c.ray) == hit);
    if (hit && c.hit) {
      CHECK(h.t == Approx(c.t));
      CHECK(h.geom_id == c.geom);
    }
  }
}

TEST_CASE("brute: empty scenes and invalid rays miss", "[accel][quick]") {
  const auto empty = make_brute_accelerator({});
  Hit h;
  CHECK_FALSE(empty->intersect({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}, h));
  CHECK_FALSE(empty->occluded({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}));
  CHECK(empty->stats().triangles == 0);
  CHECK(empty->bounds().empty());

  TwoLayers s;
  const auto accel = make_brute_accelerator(s.views);
  const float nan = std::nanf("");
  for (const Ray& r :
       {Ray{{nan, 0, 1}, 0, {0, 0, -1}, kInfinity}, Ray{{0, 0, 1}, 0, {0, nan, -1}, kInfinity},
        Ray{{0, 0, 1}, 0, {0, 0, 0}, kInfinity}, Ray{{0, 0, kInfinity}, 0, {0, 0, -1}, kInfinity},
        Ray{{0, 0, 1}, 0, {0, 0, -kInfinity}, kInfinity}, Ray{{0, 0, 1}, nan, {0, 0, -1}, kInfinity},
        Ray{{0, 0, 1}, 0, {0, 0, -1}, nan}, Ray{{0, 0, 1}, 2, {0, 0, -1}, 1}}) {
    Hit miss;
    CHECK_FALSE(accel->intersect(r, miss));
    CHECK_FALSE(accel->occluded(r));
  }
}

TEST_CASE("brute: statistics count the triangles given", "[accel][quick]") {
  TwoLayers s;
  const auto accel = make_brute_accelerator(s.views);
  const AccelStats st = accel->stats();
  CHECK(st.name == "brute");
  CHECK(st.triangles == 3);
}
