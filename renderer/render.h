// The multi-threaded tile renderer: square tiles scheduled with TBB, stratified jittered
// supersampling with a box filter, one RNG per (pixel, sample) so the image is bit-identical
// for any thread count.
#pragma once

#include <cstdint>
#include <functional>

#include "renderer/camera.h"
#include "renderer/film.h"
#include "renderer/whitted.h"

namespace penumbra {

/// Render settings with their defaults (the CLI validates user values before use).
struct RenderConfig {
  int width = 960;
  int height = 540;
  int spp = 4;            ///< samples per pixel, >= 1; perfect squares stratify fully
  int threads = 0;        ///< worker threads; 0 = all hardware threads
  int tile_size = 32;     ///< square tile edge in pixels
  uint64_t seed = 0;      ///< decorrelates whole renders; same seed => same image
  WhittedConfig whitted;
};

struct RenderStats {
  RayCounts rays;
  double seconds = 0;
  int threads = 0;
};

/// Called after each finished tile with (tiles done, tiles total), from worker threads;
/// the callee must be thread-safe. May be empty.
using ProgressFn = std::function<void(int done, int total)>;

/// Renders the scene with the Whitted integrator. Requires a valid config (width, height,
/// spp, tile_size >= 1) and an accelerator built over mesh_views(scene) and instance_views(scene).
Film render_whitted(const Scene& scene, const Accelerator& accel, const Camera& camera,
                    const RenderConfig& config, RenderStats* stats = nullptr,
                    const ProgressFn& progress = {});

/// One pixel's value (RGBA, premultiplied) exactly as render_whitted computes it: the
/// replay behind `penumbra render --debug-pixel x,y`.
void render_whitted_pixel(const Scene& scene, const Accelerator& accel, const Camera& camera,
                          const RenderConfig& config, int x, int y, float rgba[4],
                          RayCounts& counts);

}  // namespace penumbra
