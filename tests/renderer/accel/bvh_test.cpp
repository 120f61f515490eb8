// Tests for renderer/accel/bvh: structural invariants of the binned-SAH build, its
// configuration, and exact agreement with brute force under non-default settings.
#include "renderer/accel/bvh.h"

#include <catch2/catch.hpp>
#include <tbb/task_arena.h>

#include "cross_check.h"
#include "io/gltf_loader.h"
#include "renderer/scene.h"
#include "test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
std::vector<Ray> scene_rays(const LoadedScene& l, const Accelerator& ref, std::span<const TriangleMeshView> views) {
  const Bounds3f b = compute_bounds(l.scene);
  return all_rays(ref, views, b, lights_around(b), 1, 99);
}
}  // namespace

TEST_CASE("bvh: leaves respect max_leaf_size, every triangle is referenced once, a binary tree", "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  for (int leaf : {1, 4, 8}) {
    BvhConfig c;
    c.max_leaf_size = leaf;
    const AccelStats s = make_bvh_accelerator(views, c)->stats();
    INFO("max_leaf_size " << leaf);
    CHECK(s.max_leaf_prims <= uint64_t(leaf));
    CHECK(s.references == s.triangles);  // a BVH partitions: no duplicates
    CHECK(s.nodes == 2 * s.leaves - 1);  // binary
    CHECK(s.empty_leaves == 0);
    CHECK(s.avg_leaf_prims == Approx(double(s.triangles) / double(s.leaves)));
    CHECK(s.max_depth >= uint64_t(std::ceil(std::log2(double(s.triangles) / leaf))));
    CHECK(s.bytes == s.nodes * 32 + s.triangles * 44);
    // SAH cost of the tree is below that of one leaf holding everything.
    CHECK(s.sah_cost > 0);
    CHECK(s.sah_cost < double(s.triangles));
  }
}

TEST_CASE("bvh: any leaf size and bin count gives brute force's answers", "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  const auto brute = make_accelerator("brute", views);
  const Reference ref = reference(*brute, scene_rays(l, *brute, views));
  const float scale = length(compute_bounds(l.scene).extent());
  for (auto [leaf, bins] : {std::pair{1, 2}, std::pair{2, 7}, std::pair{255, 256}}) {
    BvhConfig c;
    c.max_leaf_size = leaf;
    c.bin_count = bins;
    c.parallel_threshold = 64;  // exercise the parallel build on a small scene
    const auto bvh = make_bvh_accelerator(views, c);
    const auto r = cross_check(*bvh, ref, views, scale, true, 0.0f);
    INFO(summary("bvh leaf " + std::to_string(leaf) + " bins " + std::to_string(bins), r));
    CHECK(r.failures() == 0);
  }
}

TEST_CASE("bvh: the build is the same for 1 and 2 threads", "[accel][bvh]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  BvhConfig c;
  c.parallel_threshold = 16;
  AccelStats s1, s2;
  tbb::task_arena(1).execute([&] { s1 = make_bvh_accelerator(views, c)->stats(); });
  tbb::task_arena(2).execute([&] { s2 = make_bvh_accelerator(views, c)->stats(); });
  CHECK(s1.nodes == s2.nodes);
  CHECK(s1.max_depth == s2.max_depth);
  CHECK(s1.sah_cost == s2.sah_cost);
}

TEST_CASE("bvh: identical centroids and huge leaves fall back to median splits", "[accel][bvh]") {
  // 1000 copies of one triangle: SAH cannot separate them; leaves must still be small.
  std::vector<Vec3f> pos{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  std::vector<uint32_t> idx;
  for (int i = 0; i < 1000; ++i) idx.insert(idx.end(), {0, 1, 2});
  const TriangleMeshView view{pos, idx};
  const auto bvh = make_bvh_accelerator(std::span(&view, 1));
  CHECK(bvh->stats().max_leaf_prims <= 8);
  Hit h;
  REQUIRE(bvh->intersect({{0.2f, 0.2f, 1}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == 1);
}

TEST_CASE("bvh: configuration is validated", "[accel][bvh][quick]") {
  BvhConfig c;
  c.bin_count = 1;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("bin_count"));
  c = {};
  c.max_leaf_size = 256;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_leaf_size"));
  c = {};
  c.traversal_cost = 0;
  CHECK_THROWS_AS(validate(c), std::invalid_argument);
  CHECK_NOTHROW(validate(BvhConfig{}));
}
