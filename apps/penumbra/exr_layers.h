// The EXR of a render: its metadata (render settings, OpenEXR's camera matrices, the id name
// manifest, the identity of crops and tiles) and its AOV layers, typed per layer (half colour,
// float data, uint ids), in ExrOptions for io/image_output's write_exr.
#pragma once

#include <vector>

#include "io/image_output.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/cost_map.h"

namespace penumbra::cli {

struct RenderJob;

/// The per-pixel layers an EXR points into; must outlive the ExrOptions made from it.
struct LayerBuffers {
  DataAovs data;               ///< albedo, N, P, Z, UV, ids (from the beauty's camera samples)
  std::vector<float> samples;  ///< the path tracer's sample counts as floats
  CostImage cost;              ///< traversal cost of the camera rays
};

/// Traces what the requested data and cost AOVs need (the beauty's own camera samples).
void render_layer_buffers(const RenderJob& job, LayerBuffers& buffers);

/// The beauty's EXR options: compression, part layout, every metadata attribute, and one channel
/// per requested AOV, pointing into `buffers` and job.path_image.
ExrOptions make_exr_options(const RenderJob& job, LayerBuffers& buffers);

}  // namespace penumbra::cli
