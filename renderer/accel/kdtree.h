// Penumbra's reference kD-tree: SAH build in O(N log N) with perfect splits (Wald & Havran 2006),
// 8-byte nodes with sibling children adjacent, each leaf's triangles stored contiguously,
// front-to-back traversal with early exit and a per-ray mailbox (pbrt-v3 style). Builds from
// triangle bounds (and, for perfect splits, clips triangles to node boxes); leaves call the
// shared watertight triangle test.
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// kD-tree build parameters; defaults are the constants of Wald & Havran (2006).
struct KdTreeConfig {
  float traversal_cost = 15.0f;      ///< > 0: K_T, cost of one traversal step
  float intersection_cost = 20.0f;   ///< > 0: K_I, cost of one triangle test
  float empty_bonus = 0.2f;          ///< [0, 1): a split with an empty side costs (1 - bonus) x
  int max_depth = 0;                 ///< [0, 64]; 0 = automatic, 8 + 1.3 log2(N) capped at 64
  size_t parallel_threshold = 8192;  ///< nodes with more triangles build children in parallel
};

/// Throws std::invalid_argument naming the field if a value is out of range.
void validate(const KdTreeConfig& config);

/// Builds a kD-tree over copies of the triangles (`meshes` need not outlive it).
std::unique_ptr<Accelerator> make_kdtree_accelerator(std::span<const GeometryView> meshes,
                                                     const KdTreeConfig& config = {});

}  // namespace penumbra
