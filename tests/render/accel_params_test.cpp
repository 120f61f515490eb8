// Tests for io/accel_params: every documented key sets its field, bad keys and values are
// refused with the key named, defaults listed match the config structs.
#include "render/accel_params.h"

#include <catch2/catch.hpp>

using namespace penumbra;

TEST_CASE("accel params: each key sets its field", "[io][quick]") {
  AccelConfig c;
  for (const char* kv : {"embree.robust=0",
                         "embree.quality=2",
                         "bvh.width=2",
                         "bvh.max_leaf_size=3",
                         "bvh.bin_count=32",
                         "bvh.traversal_cost=2.5",
                         "bvh.intersection_cost=0.5",
                         "bvh.spatial_alpha=1e-4",
                         "bvh.spatial_budget=0.5",
                         "kdtree.traversal_cost=1",
                         "kdtree.intersection_cost=80",
                         "kdtree.empty_bonus=0.5",
                         "kdtree.max_depth=30",
                         "grid.lambda=8",
                         "grid.max_resolution=64",
                         "grid.max_cells=4096",
                         "grid.coarse_lambda=0.5",
                         "grid.max_depth=1",
                         "grid.split_threshold=40",
                         "bvh.refit_max_growth=2",
                         "octree.max_leaf_prims=4",
                         "octree.max_depth=6",
                         "octree.reference_budget=2",
                         "bsp.traversal_cost=3",
                         "bsp.intersection_cost=40",
                         "bsp.empty_bonus=0.1",
                         "bsp.max_depth=20",
                         "bsp.bins=16",
                         "bsp.triangle_planes=0",
                         "bsp.fixed_directions=0"})
    apply_accel_param(c, kv);
  CHECK_FALSE(c.embree.robust);
  CHECK(c.embree.quality == 2);
  CHECK(c.bvh.width == 2);
  CHECK(c.bvh.max_leaf_size == 3);
  CHECK(c.bvh.bin_count == 32);
  CHECK(c.bvh.traversal_cost == 2.5f);
  CHECK(c.bvh.intersection_cost == 0.5f);
  CHECK(c.bvh.spatial_alpha == 1e-4f);
  CHECK(c.bvh.spatial_budget == 0.5f);
  CHECK(c.kdtree.traversal_cost == 1);
  CHECK(c.kdtree.intersection_cost == 80);
  CHECK(c.kdtree.empty_bonus == 0.5f);
  CHECK(c.kdtree.max_depth == 30);
  CHECK(c.grid.lambda == 8);
  CHECK(c.grid.max_resolution == 64);
  CHECK(c.grid.max_cells == 4096);
  CHECK(c.grid.coarse_lambda == 0.5f);
  CHECK(c.grid.max_depth == 1);
  CHECK(c.grid.split_threshold == 40);
  CHECK(c.bvh.refit_max_growth == 2);
  CHECK(c.octree.max_leaf_prims == 4);
  CHECK(c.octree.max_depth == 6);
  CHECK(c.octree.reference_budget == 2);
  CHECK(c.bsp.traversal_cost == 3);
  CHECK(c.bsp.intersection_cost == 40);
  CHECK(c.bsp.empty_bonus == 0.1f);
  CHECK(c.bsp.max_depth == 20);
  CHECK(c.bsp.bins == 16);
  CHECK(c.bsp.triangle_planes == 0);
  CHECK_FALSE(c.bsp.fixed_directions);
  CHECK(accel_param_keys().size() == 30);
}

TEST_CASE("accel params: unknown keys and malformed values are refused", "[io][quick]") {
  AccelConfig c;
  CHECK_THROWS_WITH(apply_accel_param(c, "bvh.leaf=3"),
                    Catch::Contains("unknown key 'bvh.leaf'") && Catch::Contains("bvh.max_leaf_size"));
  CHECK_THROWS_WITH(apply_accel_param(c, "bvh.max_leaf_size"), Catch::Contains("expected key=value"));
  CHECK_THROWS_WITH(apply_accel_param(c, "bvh.max_leaf_size=3.5"), Catch::Contains("bvh.max_leaf_size"));
  CHECK_THROWS_WITH(apply_accel_param(c, "grid.max_cells=-1"), Catch::Contains("grid.max_cells"));
  CHECK_THROWS_WITH(apply_accel_param(c, "grid.lambda=nan"), Catch::Contains("grid.lambda"));
  CHECK_THROWS_WITH(apply_accel_param(c, "grid.lambda="), Catch::Contains("grid.lambda"));
  CHECK_THROWS_WITH(apply_accel_param(c, "embree.robust=2"),
                    Catch::Contains("embree.robust: must be 0 or 1"));
  CHECK_THROWS_WITH(apply_accel_param(c, "bsp.fixed_directions=2"),
                    Catch::Contains("bsp.fixed_directions: must be 0 or 1"));
  CHECK(c.bvh.max_leaf_size == BvhConfig{}.max_leaf_size);  // failed assignments leave it alone
}

TEST_CASE("accel params: listed defaults are the config structs' defaults", "[io][quick]") {
  for (const auto& k : accel_param_keys()) {
    AccelConfig c;
    apply_accel_param(c, k.key + "=" + k.default_value);
    INFO(k.key);
    CHECK(c.embree.robust == EmbreeConfig{}.robust);
    CHECK(c.embree.quality == EmbreeConfig{}.quality);
    CHECK(c.bvh.width == BvhConfig{}.width);
    CHECK(c.bvh.max_leaf_size == BvhConfig{}.max_leaf_size);
    CHECK(c.bvh.bin_count == BvhConfig{}.bin_count);
    CHECK(c.kdtree.empty_bonus == KdTreeConfig{}.empty_bonus);
    CHECK(c.kdtree.max_depth == KdTreeConfig{}.max_depth);
    CHECK(c.grid.lambda == GridConfig{}.lambda);
    CHECK(c.grid.max_cells == GridConfig{}.max_cells);
    CHECK(c.bvh.refit_max_growth == BvhConfig{}.refit_max_growth);
    CHECK(c.octree.max_leaf_prims == OctreeConfig{}.max_leaf_prims);
    CHECK(c.octree.max_depth == OctreeConfig{}.max_depth);
    CHECK(c.bsp.bins == BspConfig{}.bins);
    CHECK(c.bsp.triangle_planes == BspConfig{}.triangle_planes);
    CHECK(c.bsp.fixed_directions == BspConfig{}.fixed_directions);
  }
}
