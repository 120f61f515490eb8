// The deep pass: every camera sample of the beauty traced again through its own integrator with
// the deep record on, and each pixel's records merged into deep samples (renderer/film/deep.h).
#pragma once

// The samples are the beauty's own (the same positions, lens points, times and sample streams),
// so the deep samples hold exactly the radiance the flat beauty averages: flattening the deep
// image gives the beauty's RGBA. The pass costs about as much as the beauty's first render.

#include <cstdint>
#include <vector>

#include "renderer/film/deep.h"
#include "renderer/integrators/render.h"

namespace penumbra {

/// Deep pass settings with their defaults.
struct DeepConfig {
  /// Records of one surface (scene instance) merge when their depths differ by at most this
  /// fraction of the nearer one's: 0.01 keeps one sample per surface and pixel at any scale.
  float merge_tolerance = 0.01f;
  /// Bytes the deep samples may take in memory, counted tile by tile as they are found (twice,
  /// for the image being assembled from the tiles): the pass stops when they would exceed it.
  uint64_t max_bytes = UINT64_MAX;
};

/// The deep image, or why there is none.
struct DeepResult {
  DeepImage image;             ///< covers render_window(config); empty when over_budget
  bool over_budget = false;    ///< the samples found would exceed DeepConfig::max_bytes
  uint64_t bytes = 0;          ///< in memory: the image's, or when over budget what was found so far
  uint64_t samples_found = 0;  ///< deep samples (when over budget: in the tiles done)
};

/// Traces the camera samples of `integrator` (Whitted or Path; `lights` non-null for Path) under
/// `config` and merges each pixel's records. `samples`, if not null, holds the camera samples each
/// pixel of the render window took (the path tracer's adaptive counts); else every pixel takes
/// config.spp. Deterministic for any thread count and tile size.
DeepResult render_deep(const Scene& scene, const Accelerator& accel, const PathLights* lights,
                       const Camera& camera, const RenderConfig& config, IntegratorType integrator,
                       const std::vector<uint32_t>* samples, const DeepConfig& deep = {});

}  // namespace penumbra
