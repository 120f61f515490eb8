// The skeleton the spatial-subdivision trees (kD-tree, octree, BSP) share: the build node their
// builders make, the flat layout they keep (an interior node's children adjacent, each leaf's
// records contiguous), the start of a build (primitives, bounds, rounding band), its end
// (flattening with the statistics pass and the size checks), stats(), and the entry of a ray and
// the leaf loop of their traversals. Each back end keeps its own node format, split search and
// traversal step; nothing here knows planes.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "renderer/accel/clip.h"
#include "renderer/accel/common.h"
#include "renderer/accel/stats.h"

namespace penumbra {

/// A tree back end's name (its AccelStats::name and the prefix of its error messages) and the
/// largest count its node format can index.
struct TreeFormat {
  const char* name = "";
  uint64_t max_index = 0;           ///< most primitives, nodes and leaf references
  const char* max_index_text = "";  ///< max_index as the error messages print it ("2^30 - 1")
};

/// The SAH constants of the statistics flatten_tree() gathers: K_T per interior node, K_I per
/// reference, each weighted by the node's area over the root's.
struct TreeCosts {
  double traversal = 0;
  double intersection = 0;
};

/// A node of a tree under construction, before flatten_tree() lays it out. `Split` is what the
/// back end's interior node stores (an axis and position, a plane, or nothing).
template <int Arity, typename Split>
struct TreeBuildNode {
  std::array<std::unique_ptr<TreeBuildNode>, Arity> child;  ///< interior only
  std::vector<uint32_t> prims;  ///< leaf only: indices into the build's records, in storage order
  Split split{};                ///< interior only
  double area = 0;              ///< surface area of the node's region (box or polytope)
  bool leaf = true;
};

/// What a tree back end keeps of its build, besides its configuration and its shapes.
template <typename Node>
struct FlatTree {
  /// Node 0 is the root (no nodes for an empty scene); the children of an interior node are
  /// adjacent, placed after every node written before them (depth first).
  std::vector<Node> nodes;
  std::vector<PrimitiveRecord> leaf_prims;  ///< each leaf's records, contiguous, in leaf order
  Bounds3f bounds;                          ///< exact bounds of the primitives
  Bounds3f clip;                            ///< `bounds` widened by `band`: rays are clipped to it
  float band = 0;                           ///< rounding_band(bounds)
  uint64_t input_triangles = 0;             ///< count_input_triangles() of the views
  AccelStats stats;                         ///< depth, leaf tally and SAH, from flatten_tree()
  double build_seconds = 0;
};

/// The depth limit of a build over `primitives` records: `configured` when > 0, else
/// 8 + 1.3 log2(primitives), rounded (pbrt-v3's KdTreeAccel), at most `cap`.
int tree_max_depth(int configured, size_t primitives, int cap);

/// Throws std::runtime_error "<name>: too many primitives (max <max_index_text>)" when `count`
/// exceeds format.max_index.
void check_primitive_count(const TreeFormat& format, size_t count);

/// Throws std::runtime_error "<name>: tree too large (more than <max_index_text> nodes or
/// references)" when either count exceeds format.max_index.
void check_tree_size(const TreeFormat& format, size_t nodes, size_t references);

/// The build parameters the SAH trees report in AccelStats::config: "traversal_cost K_T,
/// intersection_cost K_I, empty_bonus B, max_depth D" (numbers as %g prints them).
std::string sah_tree_config(float traversal_cost, float intersection_cost, float empty_bonus, int max_depth);

/// The start of a tree build: the primitives of `views` (gather_primitives(), which appends the
/// shapes to `shapes`), with tree.bounds, clip, band and input_triangles set from them (empty
/// bounds and a zero band when there are none). Throws std::runtime_error past
/// format.max_index primitives.
template <typename Node>
std::vector<PrimitiveRecord> gather_tree_primitives(std::span<const GeometryView> views,
                                                    const TreeFormat& format, std::vector<Shape>& shapes,
                                                    FlatTree<Node>& tree) {
  std::vector<PrimitiveRecord> prims = gather_primitives(views, shapes);
  tree.input_triangles = count_input_triangles(views);
  check_primitive_count(format, prims.size());
  for (const PrimitiveRecord& p : prims) tree.bounds = merge(tree.bounds, primitive_bounds(p));
  tree.clip = widen_for_rounding(tree.bounds);
  tree.band = rounding_band(tree.bounds);
  return prims;
}

namespace tree_detail {

/// The depth-first writer behind flatten_tree().
template <typename Node, int Arity, typename Split, typename LeafNode, typename InteriorNode>
struct Flattener {
  const std::vector<PrimitiveRecord>& prims;
  TreeCosts costs;
  double root_area;
  FlatTree<Node>& tree;
  LeafNode& leaf_node;
  InteriorNode& interior_node;
  LeafTally tally;

  /// Writes `b` into tree.nodes[idx] (already allocated), an interior node's children as one
  /// block after every node written so far, a leaf's records at the end of tree.leaf_prims.
  void write(const TreeBuildNode<Arity, Split>& b, uint32_t idx, uint64_t depth) {
    AccelStats& s = tree.stats;
    s.max_depth = std::max(s.max_depth, depth);
    const double rel = root_area > 0 ? b.area / root_area : 1.0;
    if (b.leaf) {
      const uint32_t n = uint32_t(b.prims.size());
      tally.add(n);
      s.sah_cost += rel * costs.intersection * n;
      s.sah_leaf_area += rel * n;
      tree.nodes[idx] = leaf_node(uint32_t(tree.leaf_prims.size()), n);
      for (const uint32_t p : b.prims) tree.leaf_prims.push_back(prims[p]);
      return;
    }
    s.sah_cost += rel * costs.traversal;
    s.sah_node_area += rel;
    const uint32_t first = uint32_t(tree.nodes.size());
    tree.nodes.resize(tree.nodes.size() + Arity);
    tree.nodes[idx] = interior_node(first, b.split);
    for (int c = 0; c < Arity; ++c) write(*b.child[size_t(c)], first + uint32_t(c), depth + 1);
  }
};

}  // namespace tree_detail

/// The end of a tree build: lays out `root`'s subtree in tree.nodes (root at 0; an interior
/// node's Arity children as one block after every node written so far, depth first, children in
/// order) and each leaf's records, prims[i] for each of its indices, contiguously in
/// tree.leaf_prims; fills tree.stats' depth, leaf tally and SAH terms with `costs`.
/// leaf_node(first_record, count) and interior_node(first_child, split) return the back end's
/// node. Throws std::runtime_error past format.max_index nodes or references.
template <typename Node, int Arity, typename Split, typename LeafNode, typename InteriorNode>
void flatten_tree(const TreeBuildNode<Arity, Split>& root, const std::vector<PrimitiveRecord>& prims,
                  const TreeCosts& costs, const TreeFormat& format, FlatTree<Node>& tree,
                  LeafNode&& leaf_node, InteriorNode&& interior_node) {
  tree_detail::Flattener<Node, Arity, Split, LeafNode, InteriorNode> f{
      prims, costs, root.area, tree, leaf_node, interior_node, {}};
  tree.nodes.emplace_back();
  f.write(root, 0, 0);
  check_tree_size(format, tree.nodes.size(), tree.leaf_prims.size());
  f.tally.fill(tree.stats);
}

/// A whole tree build, timed into tree.build_seconds: gather_tree_primitives(), then
/// make_root(prims), the back end's builder (called also without primitives, when it returns
/// null), then flatten_tree() of the root it returns. Throws as those do.
template <typename Node, typename MakeRoot, typename LeafNode, typename InteriorNode>
void build_tree(std::span<const GeometryView> views, const TreeFormat& format, const TreeCosts& costs,
                std::vector<Shape>& shapes, FlatTree<Node>& tree, MakeRoot&& make_root, LeafNode&& leaf_node,
                InteriorNode&& interior_node) {
  const BuildTimer timer;
  const std::vector<PrimitiveRecord> prims = gather_tree_primitives(views, format, shapes, tree);
  const auto root = make_root(prims);
  if (root) flatten_tree(*root, prims, costs, format, tree, leaf_node, interior_node);
  tree.build_seconds = timer.seconds();
}

/// AccelStats of a tree: what flatten_tree() gathered, completed with the format's name,
/// `config`, the input triangles, the bytes of the nodes and leaf records, the build time, the
/// node count and `shapes`.
template <typename Node>
AccelStats tree_stats(const FlatTree<Node>& tree, const TreeFormat& format, std::string config,
                      uint64_t shapes) {
  AccelStats s =
      make_stats(tree.stats, format.name, std::move(config), tree.input_triangles,
                 tree.nodes.size() * sizeof(Node) + tree.leaf_prims.size() * sizeof(PrimitiveRecord),
                 tree.build_seconds);
  s.nodes = tree.nodes.size();
  s.shapes = shapes;
  return s;
}

// ---- Walking a built tree (tests and tools) -------------------------------------------------------

/// A node as its back end decodes it: a leaf with `count` records from leaf_prims[index], or an
/// interior node whose Arity children start at nodes[index].
struct TreeNodeView {
  bool leaf = true;
  uint32_t index = 0;
  uint32_t count = 0;
};

/// A leaf as a walk from the root meets it.
struct TreeLeafEntry {
  uint64_t depth = 0;  ///< root = 0
  uint32_t first = 0;  ///< its first record in leaf_prims
  uint32_t count = 0;  ///< its records
};

/// What a walk of a flat tree from its root finds, counted apart from the statistics the build
/// gathered.
struct TreeWalk {
  uint64_t nodes = 0;                 ///< nodes reached
  std::vector<TreeLeafEntry> leaves;  ///< in depth-first order, children in order
  bool in_range = true;               ///< false if a child index or a leaf's records lie outside the arrays
};

/// Walks `tree` from node 0, decoding each node with describe(node) -> TreeNodeView. Allocates;
/// not for traversal.
template <int Arity, typename Node, typename Describe>
TreeWalk walk_flat_tree(const FlatTree<Node>& tree, Describe&& describe) {
  TreeWalk walk;
  if (tree.nodes.empty()) return walk;
  std::vector<std::pair<uint64_t, uint64_t>> stack{{0, 0}};  // (node, depth)
  while (!stack.empty()) {
    const auto [idx, depth] = stack.back();
    stack.pop_back();
    ++walk.nodes;
    const TreeNodeView v = describe(tree.nodes[size_t(idx)]);
    if (v.leaf) {
      walk.in_range = walk.in_range && uint64_t(v.index) + v.count <= tree.leaf_prims.size();
      walk.leaves.push_back({depth, v.index, v.count});
      continue;
    }
    for (int c = Arity - 1; c >= 0; --c) {
      const uint64_t child = uint64_t(v.index) + uint64_t(c);
      if (child >= tree.nodes.size()) {
        walk.in_range = false;
        continue;
      }
      stack.push_back({child, depth + 1});
    }
  }
  return walk;
}

/// The walks of trees made by make_kdtree_accelerator(), make_octree_accelerator() and
/// make_bsp_accelerator(); nullopt if `accel` is not of that kind.
std::optional<TreeWalk> walk_kdtree(const Accelerator& accel);
std::optional<TreeWalk> walk_octree(const Accelerator& accel);
std::optional<TreeWalk> walk_bsp(const Accelerator& accel);

// ---- Traversal ----------------------------------------------------------------------------------

/// A ray entering a tree: the per-ray constants of the watertight triangle test and of the slab
/// test, and [t0, t1], the ray's range within the tree's clip box.
struct TreeRay {
  WatertightRay w;
  RayBoxQuery q;
  float t0 = 0, t1 = 0;
};

/// Fills `r` for `ray`. Returns false when the ray meets nothing: an invalid ray, an empty tree,
/// or a ray missing tree.clip.
template <typename Node>
inline bool enter_tree(const FlatTree<Node>& tree, const Ray& ray, TreeRay& r) {
  r.w = prepare_watertight(ray);
  if (!r.w.valid || tree.nodes.empty()) return false;
  r.q = prepare_box_query(ray);
  r.t0 = r.w.tnear;
  r.t1 = ray.tfar;
  return intersect_box(tree.clip.lo, tree.clip.hi, r.q, r.t0, r.t1);
}

/// Offers each of the `count` records of a leaf, from tree.leaf_prims[first], that `mailbox` has
/// not seen to visit(w, record), until it returns true; returns true iff it did.
template <typename Node, typename Visit>
inline bool visit_leaf(const FlatTree<Node>& tree, uint32_t first, uint32_t count, const WatertightRay& w,
                       Mailbox& mailbox, Visit& visit) {
  const PrimitiveRecord* recs = tree.leaf_prims.data() + first;
  for (uint32_t i = 0; i < count; ++i)
    if (!mailbox.seen(recs[i]) && visit(w, recs[i])) return true;
  return false;
}

}  // namespace penumbra
