// Tests for renderer/geometry and the shared watertight triangle test: hand-computed hits.
#include "renderer/core/geometry.h"

#include <catch2/catch.hpp>

#include "renderer/accel/triangle.h"

using namespace penumbra;

TEST_CASE("ray-sphere hits at hand-computed distances", "[geometry][quick]") {
  // Ray from (0,0,-5) along +z hits the unit sphere at the origin at t = 4 and t = 6.
  Ray r{{0, 0, -5}, 0, {0, 0, 1}, kInfinity};
  float t = 0;
  REQUIRE(intersect_sphere(r, {0, 0, 0}, 1, t));
  REQUIRE(t == Approx(4));
  // From inside, the near root is behind: the far one at t = 1 is returned.
  r.org = {0, 0, 0};
  REQUIRE(intersect_sphere(r, {0, 0, 0}, 1, t));
  REQUIRE(t == Approx(1));
  // Offset ray: x = 0.6 -> hits at z = -0.8, i.e. t = 5 - 0.8 = 4.2; normal (0.6, 0, -0.8).
  r.org = {0.6f, 0, -5};
  REQUIRE(intersect_sphere(r, {0, 0, 0}, 1, t));
  REQUIRE(t == Approx(4.2));
  const Vec3f p = r.org + r.dir * t;
  REQUIRE(normalize(p).x == Approx(0.6));
  REQUIRE(normalize(p).z == Approx(-0.8));
  // Miss (discriminant < 0), and a sphere behind the ray.
  r.org = {1.5f, 0, -5};
  REQUIRE_FALSE(intersect_sphere(r, {0, 0, 0}, 1, t));
  r = {{0, 0, 5}, 0, {0, 0, 1}, kInfinity};
  REQUIRE_FALSE(intersect_sphere(r, {0, 0, 0}, 1, t));
  // Non-unit direction: t scales inversely.
  r = {{0, 0, -5}, 0, {0, 0, 2}, kInfinity};
  REQUIRE(intersect_sphere(r, {0, 0, 0}, 1, t));
  REQUIRE(t == Approx(2));
}

TEST_CASE("ray-triangle (Cramer and watertight) agree with hand-computed hits", "[geometry][quick]") {
  const Vec3f a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  // Ray straight down onto (0.25, 0.5): t = 2, barycentrics u (weight of b) = 0.25, v = 0.5.
  const Ray r{{0.25f, 0.5f, 2}, 0, {0, 0, -1}, kInfinity};
  float t, u, v;
  REQUIRE(intersect_triangle_cramer(r, a, b, c, t, u, v));
  CHECK(t == Approx(2));
  CHECK(u == Approx(0.25));
  CHECK(v == Approx(0.5));
  const WatertightRay w = prepare_watertight(r);
  REQUIRE(intersect_triangle_watertight(r, w, a, b, c, r.tfar, t, u, v));
  CHECK(t == Approx(2));
  CHECK(u == Approx(0.25));
  CHECK(v == Approx(0.5));
  // Outside (u + v > 1), behind the origin, and beyond tfar.
  const Ray out{{0.75f, 0.5f, 2}, 0, {0, 0, -1}, kInfinity};
  REQUIRE_FALSE(intersect_triangle_cramer(out, a, b, c, t, u, v));
  REQUIRE_FALSE(intersect_triangle_watertight(out, prepare_watertight(out), a, b, c, kInfinity, t, u, v));
  const Ray behind{{0.25f, 0.25f, -1}, 0, {0, 0, -1}, kInfinity};
  REQUIRE_FALSE(intersect_triangle_cramer(behind, a, b, c, t, u, v));
  REQUIRE_FALSE(
      intersect_triangle_watertight(behind, prepare_watertight(behind), a, b, c, kInfinity, t, u, v));
  REQUIRE_FALSE(intersect_triangle_watertight(r, w, a, b, c, 1.5f, t, u, v));
  // Oblique ray: from (0,0,1) towards (0.2, 0.2, 0): t = 1 with dir (0.2, 0.2, -1).
  const Ray ob{{0, 0, 1}, 0, {0.2f, 0.2f, -1}, kInfinity};
  REQUIRE(intersect_triangle_watertight(ob, prepare_watertight(ob), a, b, c, kInfinity, t, u, v));
  CHECK(t == Approx(1));
  CHECK(u == Approx(0.2));
  CHECK(v == Approx(0.2));
  CHECK(triangle_normal(a, b, c) == Vec3f{0, 0, 1});
}

TEST_CASE("watertight test: a ray through a shared edge hits exactly one side or both", "[geometry][quick]") {
  // Two triangles sharing the diagonal of the unit square; rays along the diagonal must hit.
  const Vec3f p0{0, 0, 0}, p1{1, 0, 0}, p2{1, 1, 0}, p3{0, 1, 0};
  int misses = 0;
  for (int i = 1; i < 1000; ++i) {
    const float s = float(i) / 1000.0f;
    const Ray r{{s, s, 1}, 0, {0, 0, -1}, kInfinity};
    const WatertightRay w = prepare_watertight(r);
    float t, u, v;
    const bool h1 = intersect_triangle_watertight(r, w, p0, p1, p2, kInfinity, t, u, v);
    const bool h2 = intersect_triangle_watertight(r, w, p0, p2, p3, kInfinity, t, u, v);
    misses += !(h1 || h2);
  }
  REQUIRE(misses == 0);
}

TEST_CASE("NaN and degenerate inputs never hit", "[geometry][quick]") {
  const Vec3f a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  float t, u, v;
  const Ray nan_ray{{0.2f, 0.2f, 1}, 0, {std::nanf(""), 0, -1}, kInfinity};
  REQUIRE_FALSE(prepare_watertight(nan_ray).valid);
  const Ray zero_dir{{0.2f, 0.2f, 1}, 0, {0, 0, 0}, kInfinity};
  REQUIRE_FALSE(prepare_watertight(zero_dir).valid);
  const Ray r{{0.2f, 0.2f, 1}, 0, {0, 0, -1}, kInfinity};
  REQUIRE_FALSE(intersect_triangle_watertight(r, prepare_watertight(r), a, a, a, kInfinity, t, u, v));
  REQUIRE(intersect_triangle_watertight(r, prepare_watertight(r), a, b, c, kInfinity, t, u, v));  // control
  CHECK(t == 1.0f);
  REQUIRE_FALSE(intersect_triangle_cramer(r, a, b, b * 2.0f, t, u, v));  // collinear: det 0
}

TEST_CASE("offset ray origins escape their own surface", "[geometry][quick]") {
  // A point on a large plane far from the origin: a ray leaving it must not re-hit the plane.
  for (float scale : {1e-3f, 1.0f, 1e3f, 1e5f}) {
    const Vec3f a{-scale * 10, -scale * 10, scale}, b{scale * 10, -scale * 10, scale},
        c{0, scale * 10, scale};
    const Vec3f p{scale * 0.123f, scale * 0.456f, scale};
    const Vec3f ng{0, 0, 1};
    const Vec3f dir = normalize(Vec3f{0.3f, 0.2f, 1});
    Ray r{offset_ray_origin(p, ng, dir), 0, dir, kInfinity};
    float t, u, v;
    CHECK_FALSE(intersect_triangle_watertight(r, prepare_watertight(r), a, b, c, kInfinity, t, u, v));
    // Leaving through the back side offsets to the other side.
    r = {offset_ray_origin(p, ng, -dir), 0, -dir, kInfinity};
    CHECK_FALSE(intersect_triangle_watertight(r, prepare_watertight(r), a, b, c, kInfinity, t, u, v));
    CHECK(r.org.z < p.z);
  }
}
