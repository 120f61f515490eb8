// Tests for renderer/accel/polytope: areas and volumes of boxes cut by axis and diagonal planes
// against their closed forms, degenerate cuts, and split_areas() against built clips.
#include "renderer/accel/polytope.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

using namespace penumbra;

namespace {

const Bounds3f kUnit{{0, 0, 0}, {1, 1, 1}};

/// Both parts of `p` cut by (n, k): their areas from split_areas() equal those of the clips.
void check_split_areas(const Polytope& p, DVec3 n, double k) {
  const double pos[1] = {k};
  double a_neg[1], a_pos[1];
  p.split_areas(n, pos, a_neg, a_pos);
  const Polytope neg = p.clip(n, k, false), posp = p.clip(n, k, true);
  const double scale = p.area();
  CHECK(a_neg[0] == Approx(neg.area()).margin(1e-9 * scale));
  CHECK(a_pos[0] == Approx(posp.area()).margin(1e-9 * scale));
  CHECK(neg.volume() + posp.volume() == Approx(p.volume()).margin(1e-9 * std::pow(scale, 1.5)));
}

}  // namespace

TEST_CASE("polytope: a box's area, volume and extent", "[accel][bsp][quick]") {
  const Polytope box(kUnit);
  CHECK(box.face_count() == 6);
  CHECK(box.area() == Approx(6));
  CHECK(box.volume() == Approx(1));
  double lo, hi;
  box.extent({1, 1, 1}, lo, hi);
  CHECK(lo == 0);
  CHECK(hi == 3);
  const Polytope slab(Bounds3f{{-1, 2, 3}, {1, 2.5f, 7}});
  CHECK(slab.area() == Approx(2 * (2 * 0.5 + 0.5 * 4 + 2 * 4)));
  CHECK(slab.volume() == Approx(2 * 0.5 * 4));
  CHECK(Polytope(Bounds3f{{0, 0, 0}, {1, 0, 1}}).empty());  // flat
  CHECK(Polytope(Bounds3f{}).empty());
  CHECK(Polytope().area() == 0);
}

TEST_CASE("polytope: cuts by axis and diagonal planes have the analytic areas and volumes",
          "[accel][bsp][quick]") {
  const Polytope box(kUnit);
  SECTION("axis plane x = 0.25 (normal of length 2)") {
    const Polytope neg = box.clip({2, 0, 0}, 0.5, false), pos = box.clip({2, 0, 0}, 0.5, true);
    CHECK(neg.face_count() == 6);
    CHECK(neg.area() == Approx(2 * (0.25 + 0.25 + 1)));
    CHECK(neg.volume() == Approx(0.25));
    CHECK(pos.area() == Approx(2 * (0.75 + 0.75 + 1)));
    CHECK(pos.volume() == Approx(0.75));
    check_split_areas(box, {2, 0, 0}, 0.5);
  }
  SECTION("face diagonal x + y = 1: two triangular prisms") {
    const double r = std::sqrt(0.5);
    const Polytope neg = box.clip({r, r, 0}, r, false), pos = box.clip({r, r, 0}, r, true);
    CHECK(neg.face_count() == 5);
    CHECK(pos.face_count() == 5);
    // Two half squares, two unit squares and the cap sqrt(2) x 1.
    CHECK(neg.area() == Approx(1 + 2 + std::sqrt(2.0)));
    CHECK(pos.area() == Approx(1 + 2 + std::sqrt(2.0)));
    CHECK(neg.volume() == Approx(0.5));
    CHECK(pos.volume() == Approx(0.5));
    check_split_areas(box, {r, r, 0}, r);
  }
  SECTION("body diagonal x + y + z = 1: a corner tetrahedron") {
    const Polytope neg = box.clip({1, 1, 1}, 1, false), pos = box.clip({1, 1, 1}, 1, true);
    const double cap = std::sqrt(3.0) / 2;  // equilateral, side sqrt(2)
    CHECK(neg.face_count() == 4);
    CHECK(neg.area() == Approx(1.5 + cap));
    CHECK(neg.volume() == Approx(1.0 / 6));
    CHECK(pos.face_count() == 7);
    CHECK(pos.area() == Approx(6 - 1.5 + cap));
    CHECK(pos.volume() == Approx(5.0 / 6));
    check_split_areas(box, {1, 1, 1}, 1);
  }
  SECTION("body diagonal through the centre: a hexagonal cap") {
    const Polytope neg = box.clip({1, 1, 1}, 1.5, false);
    const double cap = 3 * std::sqrt(3.0) / 4;  // regular hexagon, side sqrt(2) / 2
    CHECK(neg.face_count() == 7);
    CHECK(neg.area() == Approx(3 + cap));
    CHECK(neg.volume() == Approx(0.5));
    check_split_areas(box, {1, 1, 1}, 1.5);
  }
}

TEST_CASE("polytope: cutting away everything or nothing", "[accel][bsp][quick]") {
  const Polytope box(kUnit);
  // A plane outside the box.
  CHECK(box.clip({1, 0, 0}, 2, true).empty());
  CHECK(box.clip({1, 0, 0}, 2, false).area() == Approx(6));
  CHECK(box.clip({1, 0, 0}, 2, false).face_count() == 6);
  // The plane of a face: the box lies on one side of it.
  CHECK(box.clip({1, 0, 0}, 0, false).empty());
  CHECK(box.clip({1, 0, 0}, 0, true).area() == Approx(6));
  // Touching an edge or a corner only.
  CHECK(box.clip({1, 1, 0}, 0, false).empty());
  CHECK(box.clip({1, 1, 1}, 3, true).empty());
  CHECK(box.clip({1, 1, 1}, 3, false).volume() == Approx(1));
  // split_areas() agrees: a side without volume has no area.
  const double ks[3] = {-1, 0, 3};
  double neg[3], pos[3];
  box.split_areas({1, 1, 1}, ks, neg, pos);
  CHECK(neg[0] == 0);
  CHECK(pos[0] == Approx(6));
  CHECK(neg[1] == 0);
  CHECK(neg[2] == Approx(6));
  CHECK(pos[2] == 0);
  CHECK(Polytope().clip({1, 0, 0}, 0, true).empty());
}

TEST_CASE("polytope: repeated oblique cuts keep areas and volumes consistent", "[accel][bsp]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  Polytope p(Bounds3f{{-1, -2, -3}, {4, 5, 6}});
  for (int i = 0; i < 40; ++i) {
    DVec3 n{u(rng), u(rng), u(rng)};
    const double len = std::sqrt(dot(n, n));
    if (len < 0.1) continue;
    n = n * (1 / len);
    double lo, hi;
    p.extent(n, lo, hi);
    const double k = lo + (hi - lo) * (0.5 + 0.4 * u(rng));
    check_split_areas(p, n, k);
    // Several positions at once equal one at a time.
    const double ks[3] = {lo + 0.3 * (hi - lo), k, lo + 0.9 * (hi - lo)};
    double neg[3], pos[3];
    p.split_areas(n, ks, neg, pos);
    for (int j = 0; j < 3; ++j) CHECK(neg[j] + pos[j] > p.area() - 1e-9);  // the cap counts twice
    const Polytope next = p.clip(n, k, i % 2 == 0);
    REQUIRE_FALSE(next.empty());
    CHECK(next.volume() < p.volume());
    CHECK(next.volume() > 0);
    // Every vertex of the part lies on its side of the plane (to rounding).
    for (const DVec3& v : next.vertices()) CHECK((i % 2 == 0 ? dot(n, v) - k : k - dot(n, v)) >= -1e-9);
    p = next;
  }
  // A convex body's area is at least that of the ball of its volume (isoperimetric inequality).
  CHECK(p.area() >= std::cbrt(36 * M_PI * p.volume() * p.volume()) * (1 - 1e-9));
}
