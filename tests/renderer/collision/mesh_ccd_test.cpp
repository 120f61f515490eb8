// Tests for renderer/collision/mesh_ccd: closed-form first contacts (a cube through a wall,
// face first and edge first), and random moving triangle pairs against a dense sampling of the
// static triangle-triangle test (no meeting before the reported time, a meeting at it, and a
// contact reported whenever the samples see one).
#include "renderer/collision/mesh_ccd.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "renderer/collision/gjk.h"
#include "renderer/collision/mesh_contact.h"
#include "support/box_triangles.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

std::vector<DVec3> moved(const std::vector<DVec3>& p, DVec3 by) {
  std::vector<DVec3> out;
  for (const DVec3& q : p) out.push_back(q + by);
  return out;
}

}  // namespace

TEST_CASE("mesh first contact: a cube through a thin wall, face first and edge first", "[ccd]") {
  std::vector<DVec3> wall, cube;
  std::vector<uint32_t> wt, ct;
  add_box_triangles({-0.05, -2, -2}, {0.05, 2, 2}, wall, wt);
  add_box_triangles({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}, cube, ct);
  const MovingMesh still{wall, wall, wt};
  // From x = -3 to x = 3: both poses miss the wall; its face x = 0.5 reaches -0.05 at
  // u = 2.45 / 6.
  const std::vector<DVec3> c0 = moved(cube, {-3, 0, 0}), c1 = moved(cube, {3, 0, 0});
  const MeshFirstContact f = mesh_first_contact({c0, c1, ct}, still);
  REQUIRE(f.hit);
  CHECK(f.u == Approx(2.45 / 6).margin(1e-12));
  CHECK(f.point.x == Approx(-0.05).margin(1e-9));
  CHECK(std::abs(f.point.y) <= 0.5 + 1e-9);  // on the cube's leading face
  CHECK(std::abs(f.point.z) <= 0.5 + 1e-9);
  CHECK(f.normal.x == Approx(1).margin(1e-9));  // from the cube (a) towards the wall (b)
  CHECK(f.triangle_pairs > 0);
  // The same with the wall as a: b's vertices meet a's face; the point is still on the cube.
  const MeshFirstContact g = mesh_first_contact(still, {c0, c1, ct});
  REQUIRE(g.hit);
  CHECK(g.u == Approx(2.45 / 6).margin(1e-12));
  CHECK(g.point.x == Approx(-0.05).margin(1e-9));
  CHECK(std::abs(g.point.y) <= 0.5 + 1e-9);
  CHECK(std::abs(g.point.z) <= 0.5 + 1e-9);
  CHECK(g.normal.x == Approx(-1).margin(1e-9));
  // Turned 45 degrees about y and sent the same way: its leading edge (x = centre + sqrt(2) / 2,
  // along y) meets the wall's face at x = -0.05.
  std::vector<DVec3> turned;
  const double c = std::sqrt(0.5);
  for (const DVec3& p : cube) turned.push_back({c * (p.x + p.z), p.y, c * (p.z - p.x)});
  const std::vector<DVec3> t0 = moved(turned, {-3, 0, 0}), t1 = moved(turned, {3, 0, 0});
  const MeshFirstContact e = mesh_first_contact({t0, t1, ct}, still);
  REQUIRE(e.hit);
  CHECK(e.u == Approx((3 - 0.05 - c) / 6).margin(1e-12));
  CHECK(std::abs(e.point.y) <= 0.5 + 1e-9);
  CHECK(std::abs(e.point.z) <= 1e-9);  // on the leading edge
  // A budget of one triangle pair: undecided, no contact claimed.
  MeshCcdConfig tight;
  tight.max_triangle_pairs = 1;
  const MeshFirstContact u = mesh_first_contact({c0, c1, ct}, still, tight);
  CHECK_FALSE(u.converged);
  CHECK_FALSE(u.hit);
  CHECK(u.triangle_pairs == 1);
  // Moving away from the wall: no contact.
  CHECK_FALSE(mesh_first_contact({c1, moved(cube, {5, 0, 0}), ct}, still).hit);
}

TEST_CASE("mesh first contact agrees with a dense sampling of the static test", "[ccd]") {
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<double> u(-1, 1);
  auto point = [&] { return DVec3{u(rng), u(rng), u(rng)}; };
  const int samples = 4096;
  int hits = 0, trials = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<DVec3> a0{point(), point(), point()}, b0{point(), point(), point()};
    for (DVec3& p : b0) p = p + DVec3{2.5, 0, 0};
    const DVec3 da = point() + DVec3{2.5, 0, 0};  // a moves towards b, with some spin
    std::vector<DVec3> a1, b1;
    for (const DVec3& p : a0) a1.push_back(p + da + point() * 0.3);
    for (const DVec3& p : b0) b1.push_back(p + point() * 0.3);
    const std::vector<uint32_t> tri{0, 1, 2};
    auto at = [](const std::vector<DVec3>& p0, const std::vector<DVec3>& p1, double s, int k) {
      return p0[size_t(k)] + (p1[size_t(k)] - p0[size_t(k)]) * s;
    };
    auto meet = [&](double s) {
      return triangles_meet(at(a0, a1, s, 0), at(a0, a1, s, 1), at(a0, a1, s, 2), at(b0, b1, s, 0),
                            at(b0, b1, s, 1), at(b0, b1, s, 2));
    };
    if (meet(0)) continue;  // crossing at the start: the static test's case
    ++trials;
    int first = -1;
    for (int k = 1; k <= samples && first < 0; ++k)
      if (meet(double(k) / samples)) first = k;
    const MeshFirstContact f = mesh_first_contact({a0, a1, tri}, {b0, b1, tri});
    CAPTURE(trial, first, f.u);
    if (first >= 0) {
      REQUIRE(f.hit);
      CHECK(f.u <= double(first) / samples + 1e-12);
    }
    if (!f.hit) continue;
    ++hits;
    // At the reported time they touch, and no sample before it sees them meet.
    const DVec3 qa[3] = {at(a0, a1, f.u, 0), at(a0, a1, f.u, 1), at(a0, a1, f.u, 2)};
    const DVec3 qb[3] = {at(b0, b1, f.u, 0), at(b0, b1, f.u, 1), at(b0, b1, f.u, 2)};
    CHECK(gjk_distance({qa, 0}, {qb, 0}).distance <= 1e-7);
    for (int k = 1; double(k) / samples < f.u - 1e-9; ++k) {
      if (!meet(double(k) / samples)) continue;
      FAIL_CHECK("the samples see a meeting before the reported time");
      break;
    }
  }
  CHECK(trials > 300);
  CHECK(hits > 60);
}

TEST_CASE("mesh first contact: millimetre features in a pair a hundred metres across", "[ccd]") {
  // a: a 2 mm triangle in the plane x = 0 moving 2 mm along +x, and a large still triangle
  // 100 m away; b: a 6 mm triangle in the plane x = 1 mm holding a's outline. They touch
  // halfway.
  std::vector<DVec3> a0{{0, 0, 0},       {0, 0.002, 0},   {0, 0, 0.002},
                        {100, 100, 100}, {101, 100, 100}, {100, 101, 100}};
  std::vector<DVec3> a1 = a0;
  for (int k = 0; k < 3; ++k) a1[size_t(k)].x += 0.002;
  const std::vector<uint32_t> at{0, 1, 2, 3, 4, 5};
  const std::vector<DVec3> b{{0.001, -0.002, -0.002}, {0.001, 0.006, -0.002}, {0.001, -0.002, 0.006}};
  const std::vector<uint32_t> bt{0, 1, 2};
  const MeshFirstContact f = mesh_first_contact({a0, a1, at}, {b, b, bt});
  REQUIRE(f.hit);
  CHECK(f.u == Approx(0.5).margin(1e-9));
  CHECK(f.point.x == Approx(0.001).margin(1e-9));
}
