// Tests for renderer/accel/tree_common: the statistics each tree back end (kD-tree, octree, BSP)
// reports agree with a walk of its flattened nodes from the root (nodes reached, leaves, empty
// leaves, references, largest leaf, depth, records laid out leaf after leaf), and with its node
// size; and the shared size limits and depth rule.
#include "renderer/accel/tree_common.h"

#include <catch2/catch.hpp>
#include <functional>
#include <stdexcept>

#include "io/gltf/loader.h"
#include "renderer/accel/bsp.h"
#include "renderer/accel/kdtree.h"
#include "renderer/accel/octree.h"
#include "renderer/integrators/scene_accel.h"
#include "support/cross_check.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct TreeKind {
  const char* name;
  std::function<std::unique_ptr<Accelerator>(std::span<const GeometryView>)> make;
  std::function<std::optional<TreeWalk>(const Accelerator&)> walk;
  int arity;
  uint64_t node_bytes;  // the node layouts' documented sizes
  double traversal_cost, intersection_cost;
};

std::vector<TreeKind> tree_kinds() {
  OctreeConfig oct;
  oct.max_leaf_prims = 2;  // deep enough to have empty leaves and shared references
  return {
      {"kdtree", [](auto v) { return make_kdtree_accelerator(v); }, walk_kdtree, 2, 8, 15, 20},
      {"octree", [oct](auto v) { return make_octree_accelerator(v, oct); }, walk_octree, 8, 8, 15, 20},
      {"bsp", [](auto v) { return make_bsp_accelerator(v); }, walk_bsp, 2, 20, 15, 20},
  };
}

/// Checks what `accel` reports against a walk of its nodes.
void check_stats_against_walk(const std::string& scene, const TreeKind& kind, const Accelerator& accel) {
  INFO(scene << ", " << kind.name);
  const AccelStats s = accel.stats();
  const std::optional<TreeWalk> walk = kind.walk(accel);
  REQUIRE(walk);
  CHECK(walk->in_range);
  uint64_t empty = 0, refs = 0, largest = 0, depth = 0;
  for (const TreeLeafEntry& leaf : walk->leaves) {
    CHECK(leaf.first == refs);  // each leaf's records right after the previous leaf's
    empty += leaf.count == 0;
    refs += leaf.count;
    largest = std::max<uint64_t>(largest, leaf.count);
    depth = std::max(depth, leaf.depth);
  }
  const uint64_t leaves = walk->leaves.size();
  CHECK(s.nodes == walk->nodes);  // every node is reached from the root, once
  CHECK(s.leaves == leaves);
  CHECK(s.empty_leaves == empty);
  CHECK(s.references == refs);
  CHECK(s.max_leaf_prims == largest);
  CHECK(s.max_depth == depth);
  CHECK(s.avg_leaf_prims == (leaves > empty ? double(refs) / double(leaves - empty) : 0.0));
  if (walk->nodes > 0) CHECK(walk->nodes == 1 + uint64_t(kind.arity) * (walk->nodes - leaves));
  CHECK(s.bytes == s.nodes * kind.node_bytes + refs * sizeof(PrimitiveRecord));
  CHECK(s.name == kind.name);
  CHECK(s.sah_cost ==
        Approx(kind.traversal_cost * s.sah_node_area + kind.intersection_cost * s.sah_leaf_area));
  // sah_leaf_area weighs each leaf's references by at most the root's area.
  CHECK(s.sah_leaf_area <= double(refs) * (1 + 1e-9));
}

}  // namespace

TEST_CASE("tree_common: each tree's statistics agree with a walk of its nodes",
          "[accel][kdtree][octree][bsp]") {
  Soup soup = icosphere(3, 1, {0.1f, 0.2f, 0.3f});
  soup.add_plane(2, -1.5f, -3, 3, 6);
  soup.add({{-3, -3, -1}, {3, 3, 1}, {3, 3.01f, 1}}, {0, 1, 2});  // a sliver across everything
  const auto soup_views = soup.views();
  const LoadedScene def = load_gltf(source_dir() / "scenes/default.gltf");
  const LoadedScene shapes = load_gltf(source_dir() / "scenes/spheres.gltf");
  const auto def_views = mesh_views(def.scene);
  const auto shape_views = mesh_views(shapes.scene);
  const std::vector<GeometryView> none;
  const std::vector<Vec3f> tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2};
  const GeometryView one{tri, idx};
  for (const TreeKind& kind : tree_kinds()) {
    check_stats_against_walk("soup", kind, *kind.make(soup_views));
    check_stats_against_walk("default.gltf", kind, *kind.make(def_views));
    check_stats_against_walk("spheres.gltf", kind, *kind.make(shape_views));
    check_stats_against_walk("one triangle", kind, *kind.make(std::span(&one, 1)));
    const auto empty = kind.make(none);
    check_stats_against_walk("empty", kind, *empty);
    CHECK(empty->stats().nodes == 0);
  }
  // Each walk answers only for its own kind.
  const auto kd = make_kdtree_accelerator(soup_views);
  CHECK_FALSE(walk_octree(*kd));
  CHECK_FALSE(walk_bsp(*kd));
  CHECK_FALSE(walk_kdtree(*make_bsp_accelerator(soup_views)));
}

TEST_CASE("tree_common: size limits and the automatic depth", "[accel][quick]") {
  const TreeFormat f{"tree", 10, "ten"};
  CHECK_NOTHROW(check_primitive_count(f, 10));
  CHECK_THROWS_WITH(check_primitive_count(f, 11), "tree: too many primitives (max ten)");
  CHECK_NOTHROW(check_tree_size(f, 10, 10));
  CHECK_THROWS_WITH(check_tree_size(f, 11, 0), "tree: tree too large (more than ten nodes or references)");
  CHECK_THROWS_AS(check_tree_size(f, 0, 11), std::runtime_error);
  CHECK(tree_max_depth(5, 1000000, 64) == 5);
  CHECK(tree_max_depth(0, 0, 64) == 8);      // 8 + 1.3 log2(1)
  CHECK(tree_max_depth(0, 1024, 64) == 21);  // 8 + 1.3 x 10
  CHECK(tree_max_depth(0, size_t(1) << 60, 64) == 64);
  CHECK(sah_tree_config(15, 20, 0.2f, 22) ==
        "traversal_cost 15, intersection_cost 20, empty_bonus 0.2, max_depth 22");
}
