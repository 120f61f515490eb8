// The wide layouts of Penumbra's BVH: nodes of 4 children (float boxes slab-tested at once with
// SSE) or 8 (boxes quantised to 8 bits per plane, decoded and tested at once with AVX2), whose
// leaves are runs of four-triangle blocks (accel/triangle_block.h). After Wald, Benthin & Boulos,
// "Getting Rid of Packets", IEEE RT 2008; Dammertz, Hanika & Keller, "Shallow Bounding Volume
// Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays", EGSR 2008; and for the quantised
// boxes Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed
// Wide BVHs", HPG 2017. Traversal lives in accel/bvh_traverse.inl, compiled once per
// instruction set. Also the region walk (Accelerator::visit_region) every BVH layout shares,
// binary nodes included.
#pragma once

#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

#include "renderer/accel/triangle_block.h"

namespace penumbra {

/// 4-wide node, 128 bytes, boxes in structure-of-arrays form so one SSE register holds the
/// same bound of all four children. Unused slots have an empty box (lo = +inf, hi = -inf),
/// which no ray meets.
struct alignas(64) Node4 {
  float lo[3][4];     // 48 bytes: lo[axis][child]
  float hi[3][4];     // 48 bytes: hi[axis][child]
  uint32_t child[4];  // 16 bytes: interior child: node index; leaf: first block
  uint8_t count[4];   //  4 bytes: 0 = interior child (or unused slot), else blocks in the leaf
};
static_assert(sizeof(Node4) == 128, "4-wide nodes are two cache lines");

/// 8-wide node, 128 bytes. Child i's box on axis k is [dequantize(k, qlo[k][i]),
/// dequantize(k, qhi[k][i])]: 8-bit offsets from the node's origin in steps of `scale`, rounded
/// outward when built and checked with the traversal's own float operations, so every decoded
/// box contains its child. Unused slots have no bit in `valid`.
struct alignas(64) QuantizedNode8 {
  float origin[3];    // 12 bytes
  float scale[3];     // 12 bytes
  uint8_t qlo[3][8];  // 24 bytes
  uint8_t qhi[3][8];  // 24 bytes
  uint32_t child[8];  // 32 bytes: interior child: node index; leaf: first block
  uint8_t count[8];   //  8 bytes: 0 = interior child (or unused slot), else blocks in the leaf
  uint8_t valid;      //  1 byte : bit i set iff slot i is used
  uint8_t pad[15];    // 15 bytes
  float dequantize(int axis, uint8_t q) const { return origin[axis] + float(q) * scale[axis]; }
};
static_assert(sizeof(QuantizedNode8) == 128, "8-wide nodes are two cache lines");

/// The node of width W.
template <int W>
using WideNode = std::conditional_t<W == 8, QuantizedNode8, Node4>;

/// std::allocator, except that resize() leaves new elements default-initialised: for arrays of
/// plain data a build writes in full (in parallel, so the pages are first touched there).
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// The leaf blocks of a wide BVH.
using BlockArray = std::vector<TriangleBlock4, DefaultInitAllocator<TriangleBlock4>>;

/// A collapsed BVH: node 0 is the root; the interior children of a node are stored next to
/// each other; every leaf is a run of blocks.
template <int W>
struct WideBvh {
  std::vector<WideNode<W>> nodes;
  BlockArray blocks;
};

/// Writes the boxes of children [0, n) into `node` (boxes already widened for rounding);
/// slots n and above become unused.
void set_child_boxes(Node4& node, const Bounds3f* boxes, int n);
void set_child_boxes(QuantizedNode8& node, const Bounds3f* boxes, int n);

/// Bound on a wide traversal stack: each level pushes at most W - 1 entries beyond the one it
/// pops, and the collapsed tree is no deeper than the binary one (< kBvhStackSize levels).
template <int W>
inline constexpr int kWideStackSize = (W - 1) * 128 + W;

/// Child i's box; empty for an unused slot.
inline Bounds3f child_box(const Node4& n, int i) {
  return {{n.lo[0][i], n.lo[1][i], n.lo[2][i]}, {n.hi[0][i], n.hi[1][i], n.hi[2][i]}};
}

/// Child i's box decoded with QuantizedNode8::dequantize (the float operations the build checks
/// and the traversal repeats), so it contains the child; empty for an unused slot.
inline Bounds3f child_box(const QuantizedNode8& n, int i) {
  if (!((n.valid >> i) & 1)) return {};
  return {{n.dequantize(0, n.qlo[0][i]), n.dequantize(1, n.qlo[1][i]), n.dequantize(2, n.qlo[2][i])},
          {n.dequantize(0, n.qhi[0][i]), n.dequantize(1, n.qhi[1][i]), n.dequantize(2, n.qhi[2][i])}};
}

/// A node or leaf waiting on a region walk's stack: two words its layout reads (a node index,
/// or a leaf's first block and block count) and the squared distance of its box from a ball's
/// centre (0 for a box region), which orders the walk and is tested again when popped.
struct RegionEntry {
  uint32_t index = 0, count = 0;
  float d2 = 0;
};

/// region_meets(region, box), also giving the box's squared distance `d2` from a ball's centre
/// (0 for a box region).
inline bool region_key(const QueryRegion& region, const Bounds3f& box, float& d2) {
  d2 = 0;
  if (region.is_box || box.empty()) return region_meets(region, box);
  d2 = distance2(region.centre, box);
  return d2 <= region.radius2 * kRegionPad;
}

/// The walk of Accelerator::visit_region over a tree of at most W children per node, shared by
/// every BVH layout (binary nodes are W = 2). Depth first from `root` (whose box meets the
/// region): expand(entry, children, boxes) offers a leaf entry's primitives to the visitor and
/// returns 0, or writes the entries and conservative boxes of an interior node's children and
/// returns their number. Children whose box does not meet the region are dropped, the others
/// pushed far to near (insertion sort on the stack), so a ball's nearest child is popped first
/// and ties keep the children's order. A popped entry is tested again, as the visitor may have
/// shrunk the ball since its push. Adds each entry expanded to cost->nodes when `cost` is
/// non-null. Never allocates: the stack has the ray traversal's bound (each level adds at most
/// W - 1 entries).
template <int W, typename Expand>
void walk_region(QueryRegion& region, TraversalCost* cost, RegionEntry root, Expand&& expand) {
  RegionEntry stack[kWideStackSize<W>];
  int sp = 0;
  stack[sp++] = root;
  RegionEntry kids[W];
  Bounds3f boxes[W];
  while (sp > 0) {
    const RegionEntry e = stack[--sp];
    if (!region.is_box && !(e.d2 <= region.radius2 * kRegionPad)) continue;
    if (cost) ++cost->nodes;
    const int n = expand(e, kids, boxes);
    const int base = sp;
    for (int i = n - 1; i >= 0; --i) {
      if (!region_key(region, boxes[i], kids[i].d2)) continue;
      int j = sp++;
      for (; j > base && stack[j - 1].d2 < kids[i].d2; --j) stack[j] = stack[j - 1];
      stack[j] = kids[i];
    }
  }
}

/// walk_region over flattened binary nodes (BvhNode of accel/bvh_build.h, node 0 the root:
/// boxes in the nodes, an interior node's first child next in the array and its second at
/// `offset`, a leaf's primitives [offset, offset + count)). on_leaf(first, count) offers a
/// leaf's primitives to the visitor.
template <typename BinaryNodes, typename OnLeaf>
void walk_region_binary(const BinaryNodes& nodes, QueryRegion& region, TraversalCost* cost,
                        OnLeaf&& on_leaf) {
  if (nodes.empty()) return;
  const auto box = [&](uint32_t i) { return Bounds3f{nodes[i].lo, nodes[i].hi}; };
  RegionEntry root;
  if (!region_key(region, box(0), root.d2)) return;
  walk_region<2>(region, cost, root, [&](const RegionEntry& e, RegionEntry* kids, Bounds3f* boxes) {
    const auto& node = nodes[e.index];
    if (node.count > 0) {
      on_leaf(uint32_t(node.offset), uint32_t(node.count));
      return 0;
    }
    kids[0].index = e.index + 1;
    kids[1].index = node.offset;
    boxes[0] = box(kids[0].index);
    boxes[1] = box(kids[1].index);
    return 2;
  });
}

/// Whether this CPU (and its operating system) runs AVX2 code: the 8-wide traversal's
/// requirement, checked once at run time so one binary serves farm nodes of every generation.
bool cpu_has_avx2();

}  // namespace penumbra
