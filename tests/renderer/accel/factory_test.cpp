// Tests for renderer/accel/factory: every name builds, unknown names and bad configurations are
// refused, and the interface contract holds for each back end (bad rays miss, empty scenes work,
// statistics are filled in). The per-ray cross-check is in cross_check_test.cpp.
#include "renderer/accel/factory.h"

#include <catch2/catch.hpp>

using namespace penumbra;

TEST_CASE("NaN, infinite and zero-direction rays miss in every back end", "[accel][quick]") {
  const std::vector<Vec3f> pos{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2};
  const GeometryView view{pos, idx};
  for (const auto& name : accelerator_names()) {
    const auto accel = make_accelerator(name, std::span(&view, 1));
    const float nan = std::nanf("");
    for (const Ray& r :
         {Ray{{0, 0, 1}, 0, {nan, 0, -1}, kInfinity}, Ray{{nan, 0, 1}, 0, {0, 0, -1}, kInfinity},
          Ray{{0, 0, 1}, 0, {0, 0, 0}, kInfinity}, Ray{{0, 0, 1}, 0, {kInfinity, 0, -1}, kInfinity},
          Ray{{0, 0, 1}, nan, {0, 0, -1}, kInfinity}}) {
      Hit h;
      CHECK_FALSE(accel->intersect(r, h));
      CHECK_FALSE(accel->occluded(r));
    }
    Hit h;  // and a sane ray still hits at t = 1
    REQUIRE(accel->intersect({{0, 0, 1}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.t == Approx(1));
    CHECK(h.prim_id == 0);
    CHECK(h.geom_id == 0);
  }
}

TEST_CASE("empty scenes build and miss", "[accel][quick]") {
  for (const auto& name : accelerator_names()) {
    const auto accel = make_accelerator(name, {});
    Hit h;
    CHECK_FALSE(accel->intersect({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}, h));
    CHECK_FALSE(accel->occluded({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}));
    CHECK(accel->stats().triangles == 0);
  }
  CHECK_THROWS_AS(make_accelerator("octree-of-dreams", {}), std::invalid_argument);
}

TEST_CASE("the factory knows its back ends, embree first, and refuses bad configurations", "[accel][quick]") {
  CHECK(accelerator_names() ==
        std::vector<std::string>{"embree", "bvh", "kdtree", "grid", "octree", "bsp", "brute"});
  AccelConfig bad_bvh;
  bad_bvh.bvh.max_leaf_size = 0;
  CHECK_THROWS_AS(make_accelerator("bvh", {}, bad_bvh), std::invalid_argument);
  AccelConfig bad_kd;
  bad_kd.kdtree.empty_bonus = 1.5f;
  CHECK_THROWS_AS(make_accelerator("kdtree", {}, bad_kd), std::invalid_argument);
  AccelConfig bad_grid;
  bad_grid.grid.lambda = 0;
  CHECK_THROWS_AS(make_accelerator("grid", {}, bad_grid), std::invalid_argument);
  AccelConfig bad_octree;
  bad_octree.octree.max_depth = 21;
  CHECK_THROWS_WITH(make_accelerator("octree", {}, bad_octree),
                    Catch::Contains("octree: max_depth must be in [1, 20], got 21"));
  AccelConfig bad_bsp;
  bad_bsp.bsp.bins = 1;
  CHECK_THROWS_WITH(make_accelerator("bsp", {}, bad_bsp),
                    Catch::Contains("bsp: bins must be in [2, 64], got 1"));
  AccelConfig bad_embree;
  bad_embree.embree.quality = 3;
  CHECK_THROWS_WITH(make_accelerator("embree", {}, bad_embree), Catch::Contains("embree: quality"));
}

TEST_CASE("every back end reports its statistics", "[accel][quick]") {
  // Two clusters of 8 triangles far apart: every hierarchy must separate them (with two lone
  // triangles and bvh.traversal_cost=3, the BVH's SAH would rightly keep one leaf).
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (float x0 : {0.0f, 10.0f})
    for (int i = 0; i < 8; ++i) {
      const float y = float(i) / 8.0f;
      idx.insert(idx.end(), {uint32_t(pos.size()), uint32_t(pos.size() + 1), uint32_t(pos.size() + 2)});
      pos.insert(pos.end(), {{x0, y, 0}, {x0 + 1, y, 0}, {x0, y + 0.125f, 0}});
    }
  const GeometryView view{pos, idx};
  for (const auto& name : accelerator_names()) {
    const auto accel = make_accelerator(name, std::span(&view, 1));
    const AccelStats s = accel->stats();
    INFO(name);
    CHECK(s.name == name);
    CHECK(s.triangles == 16);
    CHECK(s.build_seconds >= 0);
    const Bounds3f b = accel->bounds();
    CHECK(b.lo.x == 0);
    CHECK(b.hi.x == 11);
    CHECK(b.hi.y == 1.0f);
    if (name == "bvh" || name == "kdtree" || name == "grid") {
      CHECK(s.bytes > 0);
      CHECK(s.leaves >= 2);
      CHECK(s.references >= 2);
      CHECK(s.max_leaf_prims >= 1);
      CHECK(!s.config.empty());
    }
    if (name == "bvh" || name == "kdtree") {
      CHECK(s.max_depth >= 1);
      CHECK(s.sah_cost > 0);
    }
  }
}
