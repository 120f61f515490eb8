// Tests for renderer/accel/bvh_build: the cuts of triangles and boxes at a plane that spatial
// splits make, and the invariants of a build with spatial splits (every part of every
// primitive inside the box of a leaf that references it, the duplication budget).
#include "renderer/accel/bvh_build.h"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>
#include <random>

#include "renderer/accel/common.h"

using namespace penumbra;

namespace {
bool contains(const Bounds3f& b, Vec3f p, float tol) {
  for (int k = 0; k < 3; ++k)
    if (p[k] < b.lo[k] - tol || p[k] > b.hi[k] + tol) return false;
  return true;
}

bool inside(const Bounds3f& inner, const Bounds3f& outer) {
  for (int k = 0; k < 3; ++k)
    if (inner.lo[k] < outer.lo[k] || inner.hi[k] > outer.hi[k]) return false;
  return true;
}

Vec3f random_point(std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  return {u(rng), u(rng), u(rng)};
}

/// A point of triangle v from barycentrics (b1, b2).
Vec3f on_triangle(const Vec3f v[3], float b1, float b2) {
  return v[0] * (1 - b1 - b2) + v[1] * b1 + v[2] * b2;
}
}  // namespace

TEST_CASE("bvh_build: a triangle cut at a plane: each side's box holds that side's points within the box",
          "[accel][bvh][quick]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0, 1);
  int both = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3f v[3] = {random_point(rng, -5, 5), random_point(rng, -5, 5), random_point(rng, -5, 5)};
    const Bounds3f tri = merge(merge(Bounds3f{v[0], v[0]}, v[1]), v[2]);
    // A box that clips the triangle too (a reference already cut before).
    const Bounds3f box = intersect(tri, {random_point(rng, -6, 0), random_point(rng, 0, 6)});
    if (box.empty()) continue;
    const int axis = trial % 3;
    const float pos = box.lo[axis] + (box.hi[axis] - box.lo[axis]) * u01(rng);
    Bounds3f l, r;
    split_triangle_bounds(v, box, axis, pos, l, r);
    INFO("trial " << trial);
    if (!l.empty()) CHECK((inside(l, box) && l.hi[axis] <= pos));
    if (!r.empty()) CHECK((inside(r, box) && r.lo[axis] >= pos));
    both += !l.empty() && !r.empty();
    for (int s = 0; s < 200; ++s) {
      float b1 = u01(rng), b2 = u01(rng);
      if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
      const Vec3f p = on_triangle(v, b1, b2);
      if (!contains(box, p, 0)) continue;
      const float tol = 1e-5f;  // the sample's own rounding
      if (p[axis] <= pos) CHECK(contains(l, p, tol));
      if (p[axis] >= pos) CHECK(contains(r, p, tol));
    }
  }
  CHECK(both > 500);  // the planes do cut most triangles
}

TEST_CASE("bvh_build: a cut through a triangle's edges gives the analytic boxes", "[accel][bvh][quick]") {
  // Triangle (0,0,0), (4,0,0), (0,4,0) cut at x = 1: the left part spans y in [0, 4], the
  // right part is the triangle (1,0), (4,0), (1,3).
  const Vec3f v[3] = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
  const Bounds3f box{{-1, -1, -1}, {5, 5, 1}};
  Bounds3f l, r;
  split_triangle_bounds(v, box, 0, 1.0f, l, r);
  // Crossings are padded by their rounding bound, (|a| + |b|) 2^-20 on the uncut axes.
  const auto near = [](Vec3f p, Vec3f q) { return length(p - q) < 1e-5f; };
  CHECK(near(l.lo, {0, 0, 0}));
  CHECK(near(l.hi, {1, 4, 0}));
  CHECK(near(r.lo, {1, 0, 0}));
  CHECK(near(r.hi, {4, 3, 0}));
  CHECK((l.hi.x == 1 && r.lo.x == 1));  // the cut axis is exact
  // A plane beyond the triangle leaves one side empty.
  split_triangle_bounds(v, box, 0, 4.5f, l, r);
  CHECK(r.empty());
  CHECK(l.hi.x == 4);
  split_box_bounds(box, 2, 0.25f, l, r);
  CHECK(l.hi.z == 0.25f);
  CHECK(r.lo.z == 0.25f);
  CHECK(l.lo == box.lo);
  CHECK(r.hi == box.hi);
}

TEST_CASE("bvh_build: spatial splits keep every primitive's parts inside its leaves and the budget",
          "[accel][bvh]") {
  // Long diagonal slivers: their boxes overlap everywhere, so spatial splits pay.
  std::mt19937 rng(3);
  std::vector<std::array<Vec3f, 3>> tris;
  for (int i = 0; i < 3000; ++i) {
    const Vec3f a = random_point(rng, -10, 10), d = Vec3f{6, 6, 6}, w = random_point(rng, -0.05f, 0.05f);
    tris.push_back({a, a + d, a + d + w});
  }
  std::vector<BvhBuildRef> refs;
  for (uint32_t i = 0; i < tris.size(); ++i)
    refs.emplace_back(merge(merge(Bounds3f{tris[i][0], tris[i][0]}, tris[i][1]), tris[i][2]), i);
  const ReferenceClipper clip = [&](const BvhBuildRef& ref, int axis, float pos, Bounds3f& l, Bounds3f& r) {
    split_triangle_bounds(tris[ref.index].data(), ref.box(), axis, pos, l, r);
  };
  for (float budget : {0.0f, 1.0f, 4.0f}) {
    BvhConfig c;
    c.spatial_alpha = 1e-5f;
    c.spatial_budget = budget;
    c.parallel_threshold = 256;
    std::vector<BvhBuildRef> out = refs;
    const auto root = build_bvh_tree(out, c, 4, &clip);
    INFO("budget " << budget);
    CHECK(out.size() <= size_t(double(tris.size()) * (1 + double(budget))));
    if (budget > 0) CHECK(out.size() > tris.size());
    if (budget == 0) CHECK(out.size() == tris.size());
    // Walk the leaves: each reference's box lies in its leaf's box; sample points of every
    // triangle each fall in some referencing leaf's box.
    std::vector<std::vector<Bounds3f>> leaf_boxes(tris.size());
    size_t covered = 0;
    const std::function<void(const BvhBuildNode&)> walk = [&](const BvhBuildNode& b) {
      if (b.child[0]) {
        CHECK(inside(b.child[0]->box, b.box));
        CHECK(inside(b.child[1]->box, b.box));
        walk(*b.child[0]);
        walk(*b.child[1]);
        return;
      }
      for (uint32_t i = b.first; i < b.first + b.count; ++i) {
        CHECK(inside(out[i].box(), b.box));
        leaf_boxes[out[i].index].push_back(b.box);
        ++covered;
      }
    };
    walk(*root);
    CHECK(covered == out.size());
    std::uniform_real_distribution<float> u01(0, 1);
    int missing = 0;
    for (size_t t = 0; t < tris.size(); ++t)
      for (int s = 0; s < 20; ++s) {
        float b1 = u01(rng), b2 = u01(rng);
        if (b1 + b2 > 1) b1 = 1 - b1, b2 = 1 - b2;
        const Vec3f p = on_triangle(tris[t].data(), b1, b2);
        bool found = false;
        // Within the margin traversal adds to a leaf's box, the sample's own rounding aside.
        for (const Bounds3f& lb : leaf_boxes[t]) found = found || contains(lb, p, rounding_band(lb) * 0.5f);
        missing += !found;
      }
    CHECK(missing == 0);
  }
}

TEST_CASE("bvh_build: spatial splits order leaves and references the same for 1 and 2 threads",
          "[accel][bvh]") {
  std::mt19937 rng(5);
  std::vector<std::array<Vec3f, 3>> tris;
  for (int i = 0; i < 4000; ++i) {
    const Vec3f a = random_point(rng, -10, 10);
    tris.push_back({a, a + Vec3f{5, 4, 6}, a + random_point(rng, -1, 1)});
  }
  std::vector<BvhBuildRef> refs;
  for (uint32_t i = 0; i < tris.size(); ++i)
    refs.emplace_back(merge(merge(Bounds3f{tris[i][0], tris[i][0]}, tris[i][1]), tris[i][2]), i);
  const ReferenceClipper clip = [&](const BvhBuildRef& ref, int axis, float pos, Bounds3f& l, Bounds3f& r) {
    split_triangle_bounds(tris[ref.index].data(), ref.box(), axis, pos, l, r);
  };
  BvhConfig c;
  c.spatial_alpha = 1e-5f;
  c.parallel_threshold = 64;
  std::vector<BvhBuildRef> out1 = refs, out2 = refs;
  std::vector<BvhNode> nodes1, nodes2;
  tbb::task_arena(1).execute([&] { flatten_bvh(*build_bvh_tree(out1, c, 4, &clip), nodes1); });
  tbb::task_arena(2).execute([&] { flatten_bvh(*build_bvh_tree(out2, c, 4, &clip), nodes2); });
  REQUIRE(out1.size() == out2.size());
  CHECK(out1.size() > refs.size());
  bool same_refs = true, same_nodes = nodes1.size() == nodes2.size();
  for (size_t i = 0; i < out1.size(); ++i)
    same_refs =
        same_refs && out1[i].index == out2[i].index && out1[i].lo == out2[i].lo && out1[i].hi == out2[i].hi;
  for (size_t i = 0; same_nodes && i < nodes1.size(); ++i)
    same_nodes = nodes1[i].lo == nodes2[i].lo && nodes1[i].hi == nodes2[i].hi &&
                 nodes1[i].offset == nodes2[i].offset && nodes1[i].count == nodes2[i].count;
  CHECK(same_refs);
  CHECK(same_nodes);
}
