// Traversal-cost images: for every pixel, the work an acceleration structure does to answer the
// camera rays of that pixel (nodes or grid cells visited, triangles tested), from the same
// stratified samples as the beauty. The data behind `penumbra render --aov cost` and the
// benchmark's heat maps.
#pragma once

#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/render.h"

namespace penumbra {

/// Per-pixel means over the pixel's camera samples, row-major, top row first.
struct CostImage {
  int width = 0, height = 0;
  std::vector<float> nodes;      ///< nodes (BVH, kD-tree) or cells (grid) visited per camera ray
  std::vector<float> triangles;  ///< ray-triangle tests per camera ray
};

/// Traces the camera rays of `config` (width, height, spp, seed, threads) through
/// accel.intersect_counted(). Requires accel.counts_traversal(); the result is the same for
/// any thread count.
CostImage render_cost(const Accelerator& accel, const Camera& camera, const RenderConfig& config);

/// nodes + triangles per pixel: the quantity the heat maps show.
std::vector<float> total_cost(const CostImage& cost);

}  // namespace penumbra
