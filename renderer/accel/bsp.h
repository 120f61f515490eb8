// Penumbra's BSP tree with arbitrary planes (I. Ize, I. Wald and S. G. Parker, "Ray Tracing with
// the BSP Tree", IEEE Symposium on Interactive Ray Tracing 2008): a binary space partition whose
// interior nodes split along any plane (the three axes, the ten diagonal directions of a k-DOP-26
// and the planes of the node's own triangles), chosen by the SAH over the exact surface areas of
// the convex polytope regions; each leaf's primitives stored contiguously; front-to-back
// traversal with a per-ray mailbox. Leaves call the shared watertight triangle test.
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// BSP build parameters; the cost constants default to the kD-tree's (Wald & Havran 2006).
///
/// The build, per node (its region a convex polytope: the root the primitives' bounding box
/// widened by the rounding band, each child its parent's cut by the plane):
///  - Directions: the 3 axes, the 10 diagonals of the k-DOP-26 (`fixed_directions`), and the
///    normals of the node's `triangle_planes` largest triangles, each also tried through its
///    triangle ("autopartition").
///  - Positions: nodes with more than 32 primitives try `bins` + 1 evenly spaced positions over
///    the primitives' extent within the region; smaller nodes try the two ends of every
///    primitive's part (the events of a kD-tree's sweep), which cut between primitives.
///  - Cost: the SAH with the surface areas of the two child polytopes (exact faces). The empty
///    bonus needs a cut removing at least 10% of the node's surface area (so that shaving slivers
///    off a node's corners along 13 directions never looks cheap). A node stays a leaf if no
///    plane beats K_I x N, at max_depth, or with at most one primitive.
///  - Primitives: what a node holds of a triangle is the triangle clipped by the ancestors'
///    planes that cut it, so it is referenced only where that part reaches. A part goes to
///    each side it reaches more than a rounding band into; a part within the band of the plane
///    (lying in it, or a mesh cut exactly at a vertex) to one side only. Traversal widens both
///    sides of every plane by more than that band, so answers never depend on the side chosen.
///  - Reference budget: splits together may add at most 3 x the primitive count references
///    (the root holds the whole budget; a split passes what it did not use to its children in
///    proportion to their counts, so the tree never depends on scheduling); a candidate plane
///    duplicating more than its node's share is not taken.
struct BspConfig {
  float traversal_cost = 15.0f;      ///< > 0: K_T, cost of one traversal step
  float intersection_cost = 20.0f;   ///< > 0: K_I, cost of one primitive test
  float empty_bonus = 0.2f;          ///< [0, 1): a split with an empty side costs (1 - bonus) x
  int max_depth = 0;                 ///< [0, 64]; 0 = automatic, 8 + 1.3 log2(N) capped at 64
  int bins = 8;                      ///< [2, 64]: positions per direction in nodes of > 32 primitives
  int triangle_planes = 4;           ///< [0, 16]: directions from the node's largest triangles
  bool fixed_directions = true;      ///< the 10 diagonal directions; false: axes + triangle planes only
  size_t parallel_threshold = 4096;  ///< nodes with more primitives build their children in parallel
};

/// Throws std::invalid_argument naming the field and its value if a value is out of range.
void validate(const BspConfig& config);

/// Builds a BSP tree over copies of the primitives (`views` need not outlive it). Throws
/// std::invalid_argument for an invalid config, std::runtime_error past 2^31 - 1 nodes or
/// references.
std::unique_ptr<Accelerator> make_bsp_accelerator(std::span<const GeometryView> views,
                                                  const BspConfig& config = {});

/// A split plane as a BSP node stores it: dot(n, p) - k >= 0 is its positive side.
struct BspPlane {
  Vec3f n;  ///< unit (to float rounding)
  float k = 0;
};

/// The root's split plane of a BSP tree made by make_bsp_accelerator(); nullopt if the root is a
/// leaf or `accel` is not such a tree. For tests and tools.
std::optional<BspPlane> bsp_root_plane(const Accelerator& accel);

}  // namespace penumbra
