// Marching cubes over an SdfTree (Lorensen & Cline, "Marching cubes: a high resolution 3D surface
// construction algorithm", SIGGRAPH 1987) with ambiguous faces resolved by the asymptotic decider
// (Nielson & Hamann, IEEE Visualization 1991), so the triangle mesh is closed, manifold and
// consistently oriented. Pure geometry: positions, unit normals and indices; no materials.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/shapes/sdf.h"

namespace penumbra {

/// Settings of extract_isosurface(). The defaults suit any tree.
struct MarchingCubesConfig {
  int padding = 2;           ///< cells added on every side of the box, >= 0 (closed shapes inside
                             ///< the box then never touch the grid's boundary)
  int refine_steps = 3;      ///< regula falsi steps on the SDF per edge vertex, in [0, 16]
                             ///< (0 = linear interpolation of the grid values)
  float normal_step = 0.5f;  ///< central-difference step, in cells, in (0, 4], of the normals
                             ///< where the analytic gradient vanishes (and of the centre
                             ///< vertices' Newton steps)
  /// Evaluate only the centre of each block of 8^3 grid points whose distance bound |f| / L keeps
  /// the surface more than a cell away from it (L = sdf_lipschitz); the mesh is the same.
  bool skip_far_blocks = true;
  /// The mesh (positions, normals, indices) may take at most this many bytes; a larger one is
  /// refused with std::length_error after counting, before its arrays are allocated.
  uint64_t max_output_bytes = UINT64_MAX;
};

/// The sampling grid of a box at a resolution: cell size `cell` = the box's longest extent /
/// resolution; n[a] = max(1, ceil(extent[a] / cell)) + 2 padding cells along axis a, centred
/// on the box; grid point (i, j, k) lies at origin + cell (i, j, k).
struct MarchingCubesGrid {
  Vec3f origin;
  float cell = 0;
  int n[3] = {0, 0, 0};  ///< cells per axis (grid points per axis: n + 1)
};

/// The grid extract_isosurface() samples. Throws std::invalid_argument for a resolution
/// outside [1, kMaxMarchingCubesResolution], an empty, flat or non-finite box, or a config
/// outside its ranges.
inline constexpr int kMaxMarchingCubesResolution = 4096;
MarchingCubesGrid marching_cubes_grid(const Bounds3f& box, int resolution, const MarchingCubesConfig& config);

/// An indexed triangle mesh: 3 indices per triangle, counter-clockwise seen from f > 0
/// (outward for a solid), one unit normal per position: sdf_gradient_normal, central differences
/// where that vanishes.
struct IsosurfaceMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;
  std::vector<uint32_t> indices;
};

/// Bytes of a mesh's arrays.
uint64_t mesh_bytes(uint64_t vertices, uint64_t triangles);

/// The working memory of extract_isosurface() besides its mesh, exactly: the grid values (4 bytes
/// per grid point) and two offset tables (16 bytes per grid row along x). Throws as
/// marching_cubes_grid().
uint64_t marching_cubes_work_bytes(const Bounds3f& box, int resolution,
                                   const MarchingCubesConfig& config = {});

/// What extract_isosurface() allocates, for memory budgets: its working memory plus an estimate
/// of the mesh, a vertex and two triangles (48 bytes) per cell of the grid's boundary, twice over,
/// which covers convex and moderately folded surfaces (config.max_output_bytes bounds the mesh
/// exactly). Throws as marching_cubes_grid().
uint64_t marching_cubes_bytes(const Bounds3f& box, int resolution, const MarchingCubesConfig& config = {});

/// Extracts the surface f = 0 of `tree` (in the tree's frame) inside `box` at `resolution` cells
/// along the box's longest axis (see MarchingCubesGrid). Grid points with f >= 0 (or NaN) are
/// outside, f < 0 inside (sdf_eval must be L-Lipschitz with L = sdf_lipschitz(tree) when
/// config.skip_far_blocks is set). One vertex per sign-changing grid edge, shared by the cells around it,
/// placed by linear interpolation then config.refine_steps regula falsi steps on the edge; each
/// cell face joins its crossings into segments (the asymptotic decider on faces with four), the
/// segments of a cell form closed loops, and each loop becomes a fan of triangles (or, when every
/// fan would add an edge between two vertices of one face, a fan around one extra vertex at the
/// loop's centre projected towards the surface). Every edge of the result lies in exactly two
/// triangles, once in each direction, when the surface stays inside the grid (the padding sees
/// to that for shapes inside `box`); a surface cut by the grid's boundary leaves a boundary.
/// Runs on the calling TBB arena; the output is identical for any number of threads. Throws
/// as marching_cubes_grid(), and std::length_error when the mesh would exceed
/// config.max_output_bytes or 2^32 - 1 vertices.
IsosurfaceMesh extract_isosurface(const SdfTree& tree, const Bounds3f& box, int resolution,
                                  const MarchingCubesConfig& config = {});

}  // namespace penumbra
