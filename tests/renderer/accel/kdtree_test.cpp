// Tests for renderer/accel/kdtree: perfect splits, the SAH termination and depth limit, its
// configuration, and exact agreement with brute force under non-default settings.
#include "renderer/accel/kdtree.h"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>

#include "io/gltf/loader.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/scene.h"
#include "support/cross_check.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// Checks `kd` against brute force over the rays of all_rays(scale, seed): hit/miss and t exact.
void check_against_brute(const std::string& what, const Accelerator& kd, const GeometryView& view, int scale,
                         uint32_t seed) {
  const auto brute = make_accelerator("brute", std::span(&view, 1));
  const Bounds3f b = brute->bounds();
  const Reference ref =
      reference(*brute, all_rays(*brute, std::span(&view, 1), b, lights_around(b), scale, seed));
  const auto r = cross_check(kd, ref, std::span(&view, 1), length(b.extent()), true, 0.0f);
  INFO(summary(what, r));
  CHECK(r.failures() == 0);
}

}  // namespace

TEST_CASE("kdtree: splits off empty space and respects max_depth", "[accel][kdtree]") {
  // Two small triangles far apart in a big box: the tree must cut the empty space between them.
  const std::vector<Vec3f> pos{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {100, 0, 0}, {101, 0, 0}, {100, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2, 3, 4, 5};
  const GeometryView view{pos, idx};
  const AccelStats s = make_kdtree_accelerator(std::span(&view, 1))->stats();
  CHECK(s.empty_leaves >= 1);
  CHECK(s.max_leaf_prims == 1);
  CHECK(s.references == 2);
  KdTreeConfig c;
  c.max_depth = 1;
  const AccelStats s1 = make_kdtree_accelerator(std::span(&view, 1), c)->stats();
  CHECK(s1.max_depth <= 1);
  CHECK(s1.nodes <= 3);
}

TEST_CASE("kdtree: perfect splits keep a long diagonal triangle out of cells it only bounds",
          "[accel][kdtree]") {
  // A thin diagonal sliver across a cloud of small triangles: its bounding box covers the whole
  // scene, but with clipping it is referenced only in leaves along the diagonal.
  std::vector<Vec3f> pos{{0, 0, 0}, {10, 10, 0}, {10, 10.01f, 0}};
  std::vector<uint32_t> idx{0, 1, 2};
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      const uint32_t b = uint32_t(pos.size());
      const Vec3f o{x + 0.2f, y + 0.6f, 0.0f};
      if (x == y) continue;
      pos.insert(pos.end(), {o, o + Vec3f{0.2f, 0, 0}, o + Vec3f{0, 0.2f, 0}});
      idx.insert(idx.end(), {b, b + 1, b + 2});
    }
  const GeometryView view{pos, idx};
  const auto kd = make_kdtree_accelerator(std::span(&view, 1));
  const AccelStats s = kd->stats();
  // Leaves overall: the sliver would be in nearly all of them without clipping.
  CHECK(s.references < s.triangles + s.leaves / 2);
  // And it still answers like brute force.
  check_against_brute("sliver", *kd, view, 1, 5);
}

TEST_CASE("kdtree: other cost constants give brute force's answers, and the build is thread-independent",
          "[accel][kdtree]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  const auto brute = make_accelerator("brute", views);
  const Bounds3f b = compute_bounds(l.scene);
  const Reference ref = reference(*brute, all_rays(*brute, views, b, lights_around(b), 1, 3));
  for (auto [kt, ki, bonus] :
       {std::tuple{1.0f, 1.0f, 0.0f}, std::tuple{15.0f, 20.0f, 0.5f}, std::tuple{80.0f, 1.0f, 0.2f}}) {
    KdTreeConfig c;
    c.traversal_cost = kt;
    c.intersection_cost = ki;
    c.empty_bonus = bonus;
    c.parallel_threshold = 64;
    const auto kd = make_kdtree_accelerator(views, c);
    const auto r = cross_check(*kd, ref, views, length(b.extent()), true, 0.0f);
    INFO(summary("kdtree K_T " + std::to_string(kt) + " K_I " + std::to_string(ki), r));
    CHECK(r.failures() == 0);
    CHECK(kd->stats().sah_cost > 0);
  }
  KdTreeConfig c;
  c.parallel_threshold = 16;
  AccelStats s1, s2;
  tbb::task_arena(1).execute([&] { s1 = make_kdtree_accelerator(views, c)->stats(); });
  tbb::task_arena(2).execute([&] { s2 = make_kdtree_accelerator(views, c)->stats(); });
  CHECK(s1.nodes == s2.nodes);
  CHECK(s1.references == s2.references);
  CHECK(s1.sah_cost == s2.sah_cost);
}

TEST_CASE("kdtree: configuration is validated", "[accel][kdtree][quick]") {
  KdTreeConfig c;
  c.max_depth = 65;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_depth"));
  c = {};
  c.empty_bonus = 1;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("empty_bonus"));
  c = {};
  c.intersection_cost = -1;
  CHECK_THROWS_AS(validate(c), std::invalid_argument);
  CHECK_NOTHROW(validate(KdTreeConfig{}));
}

TEST_CASE("kdtree: triangles referenced by many leaves answer like brute force", "[accel][kdtree]") {
  // Large overlapping and coplanar triangles over a grid of small ones: the large ones are clipped
  // into many leaves, so a ray meets the same triangle in several leaves in a row (each tested
  // once), and coplanar pairs tie on t.
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  const auto add = [&](Vec3f a, Vec3f b, Vec3f c) {
    const uint32_t base = uint32_t(pos.size());
    pos.insert(pos.end(), {a, b, c});
    idx.insert(idx.end(), {base, base + 1, base + 2});
  };
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 12; ++x) {
      const Vec3f o{float(x), float(y), float((x * 7 + y * 3) % 5) * 0.25f};
      add(o, o + Vec3f{0.3f, 0, 0}, o + Vec3f{0, 0.3f, 0.1f});
    }
  add({-1, -1, 0.5f}, {13, -1, 0.5f}, {-1, 13, 0.5f});  // a plane through the grid
  add({-1, -1, 0.5f}, {13, -1, 0.5f}, {-1, 13, 0.5f});  // the same triangle again
  add({13, 13, 0.5f}, {13, -1, 0.5f}, {-1, 13, 0.5f});  // coplanar, sharing an edge
  add({-1, 6, -1}, {13, 6, -1}, {6, 6, 3});             // a wall crossing everything
  add({0, 0, 0}, {12, 12, 1}, {12, 12.01f, 1});         // a long sliver
  const GeometryView view{pos, idx};
  const auto kd = make_kdtree_accelerator(std::span(&view, 1));
  const AccelStats s = kd->stats();
  CHECK(s.references > s.triangles);
  // Each leaf stores its triangles' records (44 bytes) contiguously; nodes are 8 bytes.
  CHECK(s.bytes == s.nodes * 8 + s.references * 44);
  check_against_brute("many references", *kd, view, 3, 20);
}
