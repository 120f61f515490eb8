// Penumbra's hierarchical grid: a top grid at the resolution of the primitive density whose
// crowded cells hold sub-grids of their own (max_depth 1 is the flat uniform grid); triangles
// listed in every cell they overlap (exact triangle-box test), 3D-DDA traversal (Amanatides &
// Woo 1987) at every level with early exit and hashed mailboxing. Leaves call the shared
// watertight triangle test.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// Grid build parameters.
struct GridConfig {
  float lambda = 4.0f;              ///< (0, 64]: cells per triangle of the grids without sub-grids
                                    ///< below them (the flat grid's): cells ~ lambda N
  float coarse_lambda = 0.25f;      ///< (0, 64]: cells per triangle of the grids with levels below
  uint32_t max_resolution = 1024;   ///< [1, 4096]: cap on the cells along any one axis
  uint64_t max_cells = 1ull << 24;  ///< [1, 2^30]: cap on the cells of any one grid or sub-grid
  uint32_t max_depth = 3;           ///< [1, 4]: grid levels; 1 is the flat uniform grid
  uint32_t split_threshold = 8;     ///< [1, 2^20]: a cell holding more triangles gets a sub-grid
};

/// Throws std::invalid_argument naming the field if a value is out of range.
void validate(const GridConfig& config);

/// Builds a (hierarchical) grid over copies of the triangles (`meshes` need not outlive it).
std::unique_ptr<Accelerator> make_grid_accelerator(std::span<const GeometryView> meshes,
                                                   const GridConfig& config = {});

/// Akenine-Moeller's separating-axis test ("Fast 3D Triangle-Box Overlap Testing", JGT 2001):
/// true iff triangle (a, b, c) and the box [lo, hi] share a point. Computed in double.
/// Exposed for tests.
bool triangle_box_overlap(const double lo[3], const double hi[3], Vec3f a, Vec3f b, Vec3f c);

}  // namespace penumbra
