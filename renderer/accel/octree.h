// Penumbra's octree: regular 8-way subdivision of the scene box with triangles clipped to each
// child (Sutherland-Hodgman bounds), 8-byte nodes with the eight children of a node adjacent,
// each leaf's primitives stored contiguously, and front-to-back traversal with the parametric
// algorithm of Revelles, Urena & Lastra (WSCG 2000), early exit and a per-ray mailbox. Leaves
// call the shared watertight triangle test and the shapes' own tests.
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// Octree build parameters.
///
/// | field              | default | range     | meaning                                              |
/// |--------------------|---------|-----------|------------------------------------------------------|
/// | max_leaf_prims     | 8       | [1, 1024] | a node with more primitives is subdivided            |
/// | max_depth          | 10      | [1, 20]   | nodes at this depth are leaves (root = depth 0)      |
/// | reference_budget   | 4       | [0, 64]   | extra references splits may add, x the primitive count |
/// | parallel_threshold | 8192    | any       | nodes with more primitives build children in parallel |
///
/// A node is also a leaf when subdividing it makes no progress: every child would hold either
/// all of its primitives or none, and more than one child would hold them all (slivers spanning
/// the box, or primitives sharing a line, would otherwise be copied into up to 8^depth leaves;
/// a single full child is still made, as it cuts off empty space), or when its box is too small
/// to split: an axis is split only where it is wider than 4 rounding bands (common.h's
/// rounding_band of the scene box; children are widened by one band before clipping), so a flat
/// scene is never split across its thickness. A max_leaf_prims below the number of triangles
/// meeting along a mesh edge makes the tree follow that edge down to max_depth (2^depth leaves
/// along it).
struct OctreeConfig {
  int max_leaf_prims = 8;  ///< [1, 1024]: a node with more primitives is subdivided
  int max_depth = 10;      ///< [1, 20]: depth limit (root = 0)
  /// [0, 64]: references that splits may add beyond one per primitive, as a multiple of the
  /// primitive count. The root holds the whole budget; a split must fit its added references
  /// in its node's share and passes the rest to its children in proportion to their counts
  /// (a node that cannot split stays a leaf). Bounds memory at (1 + budget) references per
  /// primitive where slivers would otherwise be copied into every cell they cross.
  float reference_budget = 4.0f;
  size_t parallel_threshold = 8192;  ///< nodes with more primitives build their children in parallel
};

/// Throws std::invalid_argument naming the field and the value if one is out of range.
void validate(const OctreeConfig& config);

/// Builds an octree over copies of the primitives (`views` need not outlive it, apart from what
/// the shapes reference). The structure, statistics and answers do not depend on the number of
/// threads. An empty scene has empty bounds and every query misses.
/// Throws std::invalid_argument for a bad config, std::runtime_error past 2^32 - 2 primitives,
/// nodes or references.
std::unique_ptr<Accelerator> make_octree_accelerator(std::span<const GeometryView> views,
                                                     const OctreeConfig& config = {});

}  // namespace penumbra
