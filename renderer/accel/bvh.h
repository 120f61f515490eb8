// Penumbra's reference bounding volume hierarchy: binned SAH build (Wald 2007), binary or
// 4-wide SSE nodes, front-to-back traversal with a fixed stack.
#pragma once

// The binary build tree is either flattened into 32-byte binary nodes (width 2) or collapsed
// into 4-wide nodes whose four boxes are tested at once with SSE (width 4, the default). It
// builds from triangle bounds only and calls the shared watertight triangle test in its leaves.

#include <cstddef>
#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// BVH build parameters. Costs are relative; only their ratio matters.
struct BvhConfig {
  int max_leaf_size = 8;        ///< [1, 255]: nodes with more triangles are always split
  int bin_count = 16;           ///< [2, 256]: SAH bins per axis (Wald 2007 uses 16-32)
  float traversal_cost = 1.0f;  ///< > 0: cost of visiting one node (3 suits big dense meshes, see RESULTS.md)
  float intersection_cost = 1.0f;    ///< > 0: cost of one triangle test
  size_t parallel_threshold = 4096;  ///< subtrees with more triangles build in parallel TBB tasks
  int width = 4;                     ///< 2 (binary nodes) or 4 (4-wide nodes, SSE box tests)
};

/// Throws std::invalid_argument naming the field if a value is out of range.
void validate(const BvhConfig& config);

/// Builds a BVH over copies of the triangles (`meshes` need not outlive it).
std::unique_ptr<Accelerator> make_bvh_accelerator(std::span<const GeometryView> meshes,
                                                  const BvhConfig& config = {});

}  // namespace penumbra
