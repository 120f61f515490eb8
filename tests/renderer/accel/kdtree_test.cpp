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
  const auto brute = make_accelerator("brute", std::span(&view, 1));
  const Bounds3f b = brute->bounds();
  const Reference ref = reference(*brute, all_rays(*brute, std::span(&view, 1), b, lights_around(b), 1, 5));
  const auto r = cross_check(*kd, ref, std::span(&view, 1), length(b.extent()), true, 0.0f);
  INFO(summary("sliver", r));
  CHECK(r.failures() == 0);
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
