// The wide layouts of Penumbra's BVH: nodes of 4 children (float boxes slab-tested at once with
// SSE) or 8 (boxes quantised to 8 bits per plane, decoded and tested at once with AVX2), whose
// leaves are runs of four-triangle blocks (accel/triangle_block.h). After Wald, Benthin & Boulos,
// "Getting Rid of Packets", IEEE RT 2008; Dammertz, Hanika & Keller, "Shallow Bounding Volume
// Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays", EGSR 2008; and for the quantised
// boxes Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed
// Wide BVHs", HPG 2017. Traversal lives in accel/bvh_traverse.inl, compiled once per
// instruction set.
#pragma once

#include <cstdint>
#include <type_traits>
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

/// A collapsed BVH: node 0 is the root; the interior children of a node are stored next to
/// each other; every leaf is a run of blocks.
template <int W>
struct WideBvh {
  std::vector<WideNode<W>> nodes;
  std::vector<TriangleBlock4> blocks;
};

/// Writes the boxes of children [0, n) into `node` (boxes already widened for rounding);
/// slots n and above become unused.
void set_child_boxes(Node4& node, const Bounds3f* boxes, int n);
void set_child_boxes(QuantizedNode8& node, const Bounds3f* boxes, int n);

/// Bound on a wide traversal stack: each level pushes at most W - 1 entries beyond the one it
/// pops, and the collapsed tree is no deeper than the binary one (< kBvhStackSize levels).
template <int W>
inline constexpr int kWideStackSize = (W - 1) * 128 + W;

/// Whether this CPU (and its operating system) runs AVX2 code: the 8-wide traversal's
/// requirement, checked once at run time so one binary serves farm nodes of every generation.
bool cpu_has_avx2();

}  // namespace penumbra
