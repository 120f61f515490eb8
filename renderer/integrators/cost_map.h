// Traversal-cost images: for every pixel, the work an acceleration structure does to answer the
// camera rays of that pixel (nodes or grid cells visited, triangles tested, and the wall-clock
// time, which every back end has, Embree included; shape tests and the SDF evaluations of
// sphere tracing), from the same stratified samples as the
// beauty. The data behind `penumbra render --aov cost` and the benchmark's heat maps.
#pragma once

#include <string>
#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/integrators/render.h"

namespace penumbra {

/// Per-pixel means over the pixel's camera samples, row-major, top row first.
struct CostImage {
  int width = 0, height = 0;
  std::vector<float> nodes;        ///< nodes (BVH, kD-tree) or cells (grid) visited per camera ray
  std::vector<float> triangles;    ///< ray-triangle tests per camera ray
  std::vector<float> shapes;       ///< ray-shape tests plus SDF evaluations per camera ray
  std::vector<float> nanoseconds;  ///< wall-clock time per camera ray (varies from run to run)
  bool counted = false;            ///< nodes and triangles are filled (accel.counts_traversal())
};

/// Traces the camera rays of `config` (width, height, spp, seed, threads, filter, sampler) at
/// the positions `integrator` samples (camera_sample_position) through
/// accel.intersect_counted(), timing each pixel. Counts (when the back end keeps them) are the
/// same for any thread count; times are measurements and vary.
CostImage render_cost(const Accelerator& accel, const Camera& camera, const RenderConfig& config,
                      IntegratorType integrator = IntegratorType::Whitted);

/// What the heat maps show: nodes + triangles + shapes per pixel when counted, else nanoseconds.
std::vector<float> total_cost(const CostImage& cost);

/// The heat map's caption for `accel_name`: "bvh: nodes + triangles + shape work per camera ray" or
/// "embree: nanoseconds per camera ray (wall clock)".
std::string cost_caption(const CostImage& cost, const std::string& accel_name);

}  // namespace penumbra
