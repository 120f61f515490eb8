// Render settings: image size, samples, threads, tiles, seed, pixel filter, both integrators'
// settings and the pixel window, with their defaults and the one validation every caller
// (CLI, benchmarks, tests) runs before rendering.
#pragma once

#include <atomic>
#include <cstdint>

#include "renderer/core/parallel.h"
#include "renderer/core/sampler.h"
#include "renderer/film/filter.h"
#include "renderer/integrators/path.h"
#include "renderer/integrators/whitted.h"

namespace penumbra {

/// Whitted: ray traced; Path: path traced; Raster: rasterised primary visibility shaded with the
/// Whitted integrator's local terms (its camera samples are Whitted's).
enum class IntegratorType : uint8_t { Whitted, Path, Raster };

/// How the rasteriser finds whether a light reaches a surface point.
enum class RasterShadows : uint8_t {
  Ray,   ///< a shadow ray through the accelerator (as the Whitted integrator)
  Map,   ///< a shadow map per light (depth maps rendered by the rasteriser)
  None,  ///< every light reaches every point facing it
};

/// Settings of the raster integrator.
struct RasterConfig {
  RasterShadows shadows = RasterShadows::Ray;
  int shadow_map_size = 1024;  ///< [16, 8192] texels on a side (point lights: per cube face)
};

/// Render settings with their defaults; validate() before use.
struct RenderConfig {
  int width = 960;        ///< [1, kMaxImageSize]
  int height = 540;       ///< [1, kMaxImageSize]
  int spp = 4;            ///< samples per pixel, [1, kMaxSpp] (path: the maximum with --adaptive)
  int threads = 0;        ///< worker threads, [0, kMaxThreads]; 0 = all hardware threads
  int tile_size = 32;     ///< square tile edge in pixels, [1, kMaxImageSize]
  uint64_t seed = 0;      ///< decorrelates whole renders; same seed => same image
  PixelFilter filter;     ///< box, 1 pixel wide by default; width in (0, kMaxFilterWidth]
  WhittedConfig whitted;  ///< max_depth [0, kMaxDepth]; also the raster integrator's shading
  RasterConfig raster;    ///< raster integrator only
  // Path tracer only.
  PathConfig path;  ///< max_depth [0, kMaxDepth], rr_depth [1, kMaxDepth]
  SamplerType sampler = SamplerType::Sobol;
  double time_limit = 0;         ///< seconds, finite >= 0; > 0: stop after the pass that reaches it
  float adaptive_threshold = 0;  ///< finite >= 0; > 0: stop a pixel once its error estimate is below this
  int adaptive_min_spp = 16;     ///< [2, kMaxSpp]: samples every pixel takes before it may stop
  bool light_groups = false;     ///< also accumulate the LightGroups split (PathImage::groups)
  /// Also keep the means of each pixel's even- and odd-numbered samples apart (PathImage::halves,
  /// DataAovs::halves): two independent estimates of every pixel, what the denoiser reads.
  bool halves = false;
  bool motion_blur = false;  ///< give each camera sample a time in the shutter (Ray::time), for
                             ///< scenes with motion (Scene::instance_motion)
  /// Only these pixels of the width x height frame (crops, farm tiles); all zero = the whole
  /// frame, else non-empty and inside the frame. Every pixel is computed exactly as in the
  /// whole frame, so parts merge bit for bit.
  PixelWindow window;
  /// Set (e.g. by a signal handler): stop after the current pass. May be null.
  const std::atomic<bool>* stop = nullptr;
};

inline constexpr int kMaxImageSize = 16384;
inline constexpr int kMaxSpp = 65536;
inline constexpr int kMaxThreads = 1024;
inline constexpr int kMaxDepth = 64;
inline constexpr float kMaxFilterWidth = 16;

/// Throws std::invalid_argument naming the first setting outside its documented range (the
/// ranges above, plus finite non-negative Whitted ambient, background and min_reflectance,
/// non-negative blend-layer limits). The render kernels never check: call this first.
void validate(const RenderConfig& config);

/// config.window clamped to the frame, or the whole frame if it is empty.
PixelWindow render_window(const RenderConfig& config);

}  // namespace penumbra
