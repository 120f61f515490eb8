// Penumbra's reference bounding volume hierarchy: binned SAH build (Wald 2007), binary, 4-wide
// (SSE) or 8-wide (AVX2) nodes, front-to-back traversal with a fixed stack.
#pragma once

// The binary build tree is either flattened into 32-byte binary nodes (width 2: the scalar
// reference, one watertight test per triangle) or collapsed into 4-wide nodes (SSE) or 8-wide
// nodes (AVX2) whose boxes are tested at once and whose leaves are blocks of four triangles
// filtered in SSE before the same watertight test (accel/bvh_wide.h). By default the width is
// the widest the CPU runs, checked at run time. It builds from primitive bounds only.

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
  size_t parallel_threshold = 4096;  ///< subtrees with more triangles build in parallel TBB tasks; trees
                                     ///< of 16x as many collapse their subtrees in parallel
  int width = 0;  ///< 0 (8 if the CPU has AVX2, else 4), 2 (binary), 4 (SSE) or 8 (AVX2; refused without it)
  /// [0, 1]: spatial splits (Stich et al. 2009) are tried at nodes whose object split leaves
  /// children overlapping by more than this fraction of the root's surface area; 0 turns them
  /// off (Stich et al. use 1e-5).
  float spatial_alpha = 0.0f;
  /// [0, 4]: references that spatial splits may add, as a fraction of the primitive count.
  float spatial_budget = 1.0f;
  /// 0 or [1, 1000]: the rebuild policy of animation (refit_or_rebuild in accel/factory.h): a
  /// BVH refitted to moved geometry is kept while its SAH cost stays within this factor of its
  /// cost when last built, and built anew past it; 0 never refits.
  float refit_max_growth = 1.5f;
};

/// Throws std::invalid_argument naming the field if a value is out of range.
void validate(const BvhConfig& config);

/// Builds a BVH over copies of the triangles (`meshes` need not outlive it). Throws
/// std::invalid_argument for an invalid config, width 8 on a CPU without AVX2, or more than
/// 2^31 - 1 triangles in a wide layout.
std::unique_ptr<Accelerator> make_bvh_accelerator(std::span<const GeometryView> meshes,
                                                  const BvhConfig& config = {});

}  // namespace penumbra
