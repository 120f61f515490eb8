// Enclosed volumes: of a closed triangle mesh by the divergence theorem, of the analytic shapes
// by their closed forms, and of an implicit shape by adaptive cell classification with its
// distance bound, which gives a rigorous interval; per instance in world space.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/scene/scene.h"

namespace penumbra {

/// A triangle mesh's enclosed volume and whether it encloses one.
struct MeshVolume {
  /// Some triangle is not degenerate, and every edge, with vertices welded by equal positions,
  /// is shared by exactly two triangles that traverse it in opposite directions (a closed,
  /// consistently oriented surface).
  bool closed = false;
  /// Sum over triangles of a . (b x c) / 6 (in double, relative to the first vertex): the
  /// enclosed volume, positive when the triangles face outwards; meaningful when closed.
  double signed_volume = 0;
  uint64_t open_edges = 0;  ///< welded edges with one triangle
  uint64_t bad_edges = 0;   ///< welded edges with more than two, or two in the same direction
  uint64_t degenerate = 0;  ///< triangles with two welded vertices equal (ignored)
};

/// The volume of triangles `indices` (3 per triangle, each < positions.size()) over `positions`.
MeshVolume mesh_volume(std::span<const Vec3f> positions, std::span<const uint32_t> indices);

/// How implicit shapes are measured.
struct VolumeConfig {
  int base_cells = 32;              ///< cells along the longest side of the shape's bounds at the top level
  int refine_levels = 5;            ///< halvings of the cells the surface may cross
  uint64_t max_cells = 1ull << 24;  ///< most cells classified per shape (refinement stops there)
};

/// A volume with its error bound: the true volume lies in [volume - error, volume + error].
struct ShapeVolume {
  bool closed = false;  ///< false for the flat shapes (plane, disk) and unbounded implicit ones
  double volume = 0;
  double error = 0;    ///< 0 for the closed forms
  uint64_t cells = 0;  ///< implicit: cells classified
};

/// The object-space volume of `shape`: sphere 4/3 pi r^3, box 8 hx hy hz, capsule
/// pi r^2 (2 h) + 4/3 pi r^3, the flat shapes 0 (not closed); an implicit shape by classifying
/// the cells of a grid over its bounds with its distance bound (sdf_eval over the Lipschitz
/// constant): a cell whose centre lies farther from the surface than the cell's half-diagonal
/// is wholly inside or outside; the others are halved config.refine_levels times, and those
/// left count half, with half their volume as the error. Deterministic.
ShapeVolume shape_volume(const Shape& shape, const VolumeConfig& config = {});

/// One instance's enclosed volume in world space: the object-space volume times |det| of the
/// instance's linear map.
struct InstanceVolume {
  uint32_t instance = 0;
  bool closed = false;
  double volume = 0;  ///< world units cubed; for meshes |signed_volume| scaled
  double error = 0;
  bool inward = false;  ///< a closed mesh whose triangles face inwards (negative signed volume)
  uint64_t open_edges = 0, bad_edges = 0;  ///< a mesh's (MeshVolume)
};

/// Every instance's volume, meshes and shapes measured once each however often placed; point
/// sets (Mesh::points) are not closed.
std::vector<InstanceVolume> instance_volumes(const Scene& scene, const VolumeConfig& config = {});

}  // namespace penumbra
