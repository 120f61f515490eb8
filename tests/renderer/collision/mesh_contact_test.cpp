// Tests for renderer/collision/mesh_contact: the triangle-triangle test against GJK on the two
// triangles (random pairs, and coplanar pairs built to overlap or not), and the trees' contacts
// against the test over every pair of two triangle soups, both ways round, and after Embree's
// rtcCollide broad phase.
#include "renderer/collision/mesh_contact.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/accel/embree.h"
#include "renderer/collision/gjk.h"
#include "support/box_triangles.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

DVec3 random_point(std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  return {u(rng), u(rng), u(rng)};
}

// `n` triangles of size about `size` scattered in a cube of half side `spread`.
void soup(std::mt19937_64& rng, int n, double size, double spread, std::vector<DVec3>& pts,
          std::vector<uint32_t>& tris) {
  for (int i = 0; i < n; ++i) {
    const DVec3 c = random_point(rng, spread);
    for (int k = 0; k < 3; ++k) {
      tris.push_back(uint32_t(pts.size()));
      pts.push_back(c + random_point(rng, size));
    }
  }
}

// Each triangle's box in single precision, rounded outwards.
std::vector<Bounds3f> triangle_boxes(const std::vector<DVec3>& p, const std::vector<uint32_t>& t) {
  std::vector<Bounds3f> boxes;
  auto down = [](double v) { return std::nextafter(float(v), -INFINITY); };
  auto up = [](double v) { return std::nextafter(float(v), INFINITY); };
  for (size_t i = 0; i < t.size(); i += 3) {
    Bounds3f b;
    for (int k = 0; k < 3; ++k) {
      const DVec3 q = p[t[i + size_t(k)]];
      b = merge(b, Vec3f{down(q.x), down(q.y), down(q.z)});
      b = merge(b, Vec3f{up(q.x), up(q.y), up(q.z)});
    }
    boxes.push_back(b);
  }
  return boxes;
}

}  // namespace

TEST_CASE("triangle-triangle: equals GJK on random and coplanar pairs", "[contact]") {
  std::mt19937_64 rng(5);
  int met = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    DVec3 t1[3], t2[3];
    for (auto& p : t1) p = random_point(rng, 1);
    for (auto& p : t2) p = random_point(rng, 1) + DVec3{0.8, 0, 0};
    if (trial % 4 == 0)  // coplanar: every corner at z = 0.25
      for (auto* t : {&t1, &t2})
        for (auto& p : *t) p.z = 0.25;
    const ConvexDistance d = gjk_distance({t1, 0}, {t2, 0});
    if (!d.intersect && d.distance < 1e-9) continue;  // touching to rounding: either answer holds
    const bool want = d.intersect;
    met += want;
    INFO("trial " << trial);
    CHECK(triangles_meet(t1[0], t1[1], t1[2], t2[0], t2[1], t2[2]) == want);
    CHECK(triangles_meet(t2[0], t2[1], t2[2], t1[0], t1[1], t1[2]) == want);
  }
  CHECK(met > 400);
  CHECK(met < 3600);
  // Touching at a shared corner, and a shared edge, counts.
  CHECK(triangles_meet({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {-1, 0, 0}, {0, 0, 1}));
  CHECK(triangles_meet({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, -1, 0}));
}

TEST_CASE("mesh contacts: the trees find exactly the pairs brute force finds", "[contact]") {
  std::mt19937_64 rng(6);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<DVec3> pa, pb;
    std::vector<uint32_t> ta, tb;
    soup(rng, 400 + 100 * trial, 0.15, 2, pa, ta);
    soup(rng, 300, 0.15, 2, pb, tb);
    const ContactMesh a{pa, ta}, b{pb, tb};
    const ContactTree tra = build_contact_tree(a), trb = build_contact_tree(b);
    const MeshContacts found = mesh_contacts(a, tra, b, trb);
    std::vector<std::pair<uint32_t, uint32_t>> want;
    for (uint32_t s = 0; s < ta.size() / 3; ++s)
      for (uint32_t t = 0; t < tb.size() / 3; ++t)
        if (triangles_meet(pa[ta[3 * s]], pa[ta[3 * s + 1]], pa[ta[3 * s + 2]], pb[tb[3 * t]],
                           pb[tb[3 * t + 1]], pb[tb[3 * t + 2]]))
          want.push_back({s, t});
    CHECK(found.pairs == want);
    CHECK(!want.empty());
    CHECK(found.triangle_pairs < uint64_t(ta.size() / 3) * (tb.size() / 3) / 10);  // the trees pruned
    const MeshContacts back = mesh_contacts(b, trb, a, tra);
    std::vector<std::pair<uint32_t, uint32_t>> swapped;
    for (const auto& [s, t] : back.pairs) swapped.push_back({t, s});
    std::sort(swapped.begin(), swapped.end());
    CHECK(swapped == want);

    // Embree's rtcCollide as the broad phase, the same exact test after it: the same pairs.
    std::vector<std::pair<uint32_t, uint32_t>> embree;
    for (const auto& [s, t] : embree_collide(triangle_boxes(pa, ta), triangle_boxes(pb, tb)))
      if (triangles_meet(pa[ta[3 * s]], pa[ta[3 * s + 1]], pa[ta[3 * s + 2]], pb[tb[3 * t]],
                         pb[tb[3 * t + 1]], pb[tb[3 * t + 2]]))
        embree.push_back({s, t});
    CHECK(embree == want);
  }
  const std::vector<DVec3> none;
  const ContactMesh empty{none, {}};
  CHECK(build_contact_tree(empty).nodes.empty());
}

namespace {

// The distance from p to the surface of the box [lo, hi].
double box_surface_distance(DVec3 p, DVec3 lo, DVec3 hi) {
  const double dx = std::max({lo.x - p.x, 0.0, p.x - hi.x}), dy = std::max({lo.y - p.y, 0.0, p.y - hi.y}),
               dz = std::max({lo.z - p.z, 0.0, p.z - hi.z});
  if (dx > 0 || dy > 0 || dz > 0) return std::sqrt(dx * dx + dy * dy + dz * dz);
  return std::min({p.x - lo.x, hi.x - p.x, p.y - lo.y, hi.y - p.y, p.z - lo.z, hi.z - p.z});
}

}  // namespace

TEST_CASE("mesh winding and closest point: two overlapping boxes", "[contact]") {
  const DVec3 lo1{-1, -1, -1}, hi1{1, 1, 1}, lo2{0.5, -0.5, -0.5}, hi2{2, 0.5, 0.5};
  std::vector<DVec3> pts;
  std::vector<uint32_t> tris;
  add_box_triangles(lo1, hi1, pts, tris);
  add_box_triangles(lo2, hi2, pts, tris);
  const ContactMesh mesh{pts, tris};
  const ContactTree tree = build_contact_tree(mesh);
  // The second box wound inward, its orientation -1, counts as the first does.
  std::vector<uint32_t> flipped = tris;
  for (size_t t = 36; t < flipped.size(); t += 3) std::swap(flipped[t + 1], flipped[t + 2]);
  std::vector<int8_t> orientation(24, 1);
  std::fill(orientation.begin() + 12, orientation.end(), int8_t(-1));
  const ContactMesh mesh_flipped{pts, flipped};
  const ContactTree tree_flipped = build_contact_tree(mesh_flipped);
  auto in = [](DVec3 p, DVec3 lo, DVec3 hi) {
    return p.x > lo.x && p.x < hi.x && p.y > lo.y && p.y < hi.y && p.z > lo.z && p.z < hi.z;
  };
  std::mt19937_64 rng(4);
  int decided = 0, inside_both = 0;
  for (int i = 0; i < 4000; ++i) {
    // Random points, and points on a grid of the boxes' own coordinates (rays from them would
    // run along faces and through edges in axis directions).
    const DVec3 p =
        i % 2 ? random_point(rng, 2.5) : DVec3{-2.5 + 0.25 * (i % 21), -1.5 + 0.25 * (i / 21 % 13), 0.25};
    int w = 0;
    const bool ok = mesh_winding(mesh, tree, {}, p, w);
    const bool on_surface = box_surface_distance(p, lo1, hi1) == 0 || box_surface_distance(p, lo2, hi2) == 0;
    if (on_surface) continue;
    REQUIRE(ok);
    ++decided;
    CHECK(w == int(in(p, lo1, hi1)) + int(in(p, lo2, hi2)));
    int wf = 0;
    REQUIRE(mesh_winding(mesh_flipped, tree_flipped, orientation, p, wf));
    CHECK(wf == w);
    inside_both += w == 2;
    const MeshClosest c = mesh_closest(mesh, tree, p);
    CHECK(
        c.distance ==
        Approx(std::min(box_surface_distance(p, lo1, hi1), box_surface_distance(p, lo2, hi2))).margin(1e-12));
    CHECK(std::abs(length(c.point - p) - c.distance) <= 1e-12);
  }
  CHECK(decided > 3500);
  CHECK(inside_both > 20);
}
