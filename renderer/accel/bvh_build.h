// The BVH builder (accel/bvh_build.cpp) shared by the BVH and other structures over boxes (the instance top
// level of accel/instances.cpp): binned SAH (Wald 2007) over bounds and centroids only, and the
// flattening into 32-byte binary nodes in depth-first order (pbrt-v4's LinearBVHNode).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "renderer/accel/bvh.h"
#include "renderer/accel/common.h"
#include "renderer/core/math.h"

namespace penumbra {

/// One primitive as the builder sees it, 32 bytes: its box and the caller's index. The
/// centroid is the box's centre, recomputed where needed (memory traffic bounds the build).
struct alignas(16) BvhBuildRef {
  Vec3f lo;
  uint32_t index = 0;
  Vec3f hi;
  float pad = 0;

  BvhBuildRef() = default;
  BvhBuildRef(const Bounds3f& b, uint32_t i) : lo(b.lo), index(i), hi(b.hi) {}
  Bounds3f box() const { return {lo, hi}; }
  Vec3f centroid() const { return (lo + hi) * 0.5f; }
};
static_assert(sizeof(BvhBuildRef) == 32);

/// Binary build tree. A leaf (no children) covers refs [first, first + count).
struct BvhBuildNode {
  Bounds3f box;
  std::unique_ptr<BvhBuildNode> child[2];
  uint32_t first = 0, count = 0;
  int axis = 0;  ///< split axis of an interior node
};

/// Flattened node, 32 bytes. Children of an interior node: the first is the next node in the
/// array (depth-first order), the second is at `offset`.
struct alignas(32) BvhNode {
  Vec3f lo;         // 12 bytes: box minimum
  Vec3f hi;         // 12 bytes: box maximum
  uint32_t offset;  //  4 bytes: leaf: first primitive; interior: index of the second child
  uint16_t count;   //  2 bytes: primitives in a leaf; 0 marks an interior node
  uint8_t axis;     //  1 byte : split axis of an interior node (visit order)
  uint8_t pad;      //  1 byte : unused
};
static_assert(sizeof(BvhNode) == 32, "BvhNode must stay 32 bytes");

/// Deepest path of a tree from build_bvh_tree() is below this (SAH depth is capped, then object
/// median splits halve the rest), so fixed traversal stacks of this size never overflow.
inline constexpr int kBvhStackSize = 128;

/// Cuts reference `ref` at the plane x[axis] = pos: `left` and `right` bound the parts of its
/// primitive within ref's box on either side (either may be empty). Used by spatial splits.
using ReferenceClipper =
    std::function<void(const BvhBuildRef& ref, int axis, float pos, Bounds3f& left, Bounds3f& right)>;

/// Builds the tree over `refs` (non-empty; config validated), reordering them so every leaf is
/// a contiguous range. The SAH charges a leaf's intersection cost per block of `block`
/// primitives (4 for the wide layouts, whose leaves hold blocks of four; Embree does the same),
/// and config.width is not read. With a clipper and config.spatial_alpha > 0 it also makes
/// spatial splits, and `refs` may come back longer: a primitive cut by them appears once per
/// leaf it reaches (index repeated, each with the box of its part there), at most
/// spatial_budget times the count more references. The shape never depends on thread
/// scheduling.
std::unique_ptr<BvhBuildNode> build_bvh_tree(std::vector<BvhBuildRef>& refs, const BvhConfig& config,
                                             int block = 1, const ReferenceClipper* clip = nullptr);

/// Frees the tree built by build_bvh_tree, its large subtrees in parallel TBB tasks (a
/// million-triangle tree is some 10^6 separate allocations).
void release_bvh_tree(std::unique_ptr<BvhBuildNode> root);

/// The boxes of the parts of triangle v on either side of x[axis] = pos, within `box`: the
/// triangle's vertices and edge crossings on each side (crossings padded by their rounding
/// error), intersected with `box`.
void split_triangle_bounds(const Vec3f v[3], const Bounds3f& box, int axis, float pos, Bounds3f& left,
                           Bounds3f& right);

/// `box` cut at x[axis] = pos (the clipper of primitives known only by their box).
void split_box_bounds(const Bounds3f& box, int axis, float pos, Bounds3f& left, Bounds3f& right);

/// Appends `b`'s subtree to `nodes` depth first, boxes widened by widen_for_rounding(); returns
/// the index of `b`'s node.
uint32_t flatten_bvh(const BvhBuildNode& b, std::vector<BvhNode>& nodes);

/// Depth-first walk over flattened binary nodes (node 0 the root), nearer child first by the
/// sign of the ray direction along the split axis, culling boxes outside [tnear, best] (`best`
/// may shrink during the walk). Calls on_node() per node visited and on_leaf(first, count) per
/// leaf met until it returns true; returns true iff it did. Never allocates.
template <typename OnNode, typename OnLeaf>
bool walk_bvh(const std::vector<BvhNode>& nodes, const RayBoxQuery& q, float tnear, const float& best,
              OnNode&& on_node, OnLeaf&& on_leaf) {
  if (nodes.empty()) return false;
  uint32_t stack[kBvhStackSize];
  int sp = 0;
  uint32_t idx = 0;
  for (;;) {
    const BvhNode& node = nodes[idx];
    on_node();
    float t0 = tnear, t1 = best;
    if (intersect_box(node.lo, node.hi, q, t0, t1)) {
      if (node.count == 0) {
        const bool far_first = q.dir_neg[node.axis];
        stack[sp++] = far_first ? idx + 1 : node.offset;
        idx = far_first ? node.offset : idx + 1;
        continue;
      }
      if (on_leaf(node.offset, uint32_t(node.count))) return true;
    }
    if (sp == 0) return false;
    idx = stack[--sp];
  }
}

}  // namespace penumbra
