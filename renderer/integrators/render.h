// The multi-threaded tile renderer: square tiles scheduled with TBB, one sample stream per
// (pixel, sample) so the image is bit-identical for any thread count.
//
// Whitted: stratified jittered supersampling of each pixel, box filtered (or any pixel filter,
// applied by filter importance sampling). Path: progressive passes over the image (1, 2, 4, 8,
// 16 samples, then 16 per pass), each pixel the mean of its samples, with an optional time limit
// (checked after each whole pass) and optional adaptive sampling that stops pixels whose
// estimated error falls below a threshold. Each pixel's value depends only on its own
// samples, so neither threads, tiles nor the pass schedule change it.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "renderer/scene/camera.h"
#include "renderer/film/film.h"
#include "renderer/film/filter.h"
#include "renderer/integrators/path.h"
#include "renderer/integrators/whitted.h"

namespace penumbra {

enum class IntegratorType : uint8_t { Whitted, Path };

/// A rectangle of pixels [x0, x1) x [y0, y1) of the full frame.
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

/// Render settings with their defaults (the CLI validates user values before use).
struct RenderConfig {
  int width = 960;
  int height = 540;
  int spp = 4;            ///< samples per pixel, >= 1 (path: the maximum with --adaptive)
  int threads = 0;        ///< worker threads; 0 = all hardware threads
  int tile_size = 32;     ///< square tile edge in pixels
  uint64_t seed = 0;      ///< decorrelates whole renders; same seed => same image
  PixelFilter filter;     ///< box, 1 pixel wide by default
  WhittedConfig whitted;
  // Path tracer only.
  PathConfig path;
  SamplerType sampler = SamplerType::Sobol;
  double time_limit = 0;          ///< seconds; > 0: stop after the pass that reaches it
  float adaptive_threshold = 0;   ///< > 0: stop a pixel once its error estimate is below this
  int adaptive_min_spp = 16;      ///< samples every pixel takes before it may stop
  bool light_groups = false;      ///< also accumulate the LightGroups split (PathImage::groups)
  /// Only these pixels of the width x height frame (crops, farm tiles); empty = the whole
  /// frame. Every pixel is computed exactly as in the whole frame, so parts merge bit for bit.
  PixelWindow window;
  /// Set (e.g. by a signal handler): stop after the current pass. May be null.
  const std::atomic<bool>* stop = nullptr;
};

/// config.window clamped to the frame, or the whole frame if it is empty.
PixelWindow render_window(const RenderConfig& config);

struct RenderStats {
  RayCounts rays;
  double seconds = 0;
  int threads = 0;
  int passes = 0;           ///< path: passes rendered
  uint64_t samples = 0;     ///< camera samples taken in all
  bool time_limited = false;  ///< path: the time limit ended the render early
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

/// A path-traced image with its per-pixel statistics.
struct PathImage {
  Film film;                       ///< mean of each pixel's samples (RGBA, premultiplied);
                                   ///< all per-pixel vectors cover render_window(config)
  std::vector<uint32_t> samples;   ///< samples taken per pixel
  std::vector<float> variance;     ///< variance of each pixel's mean luminance (0 if n < 2)
  /// With RenderConfig::light_groups: 15 floats per pixel, the means of LightGroups' emission,
  /// diffuse_direct, diffuse_indirect, specular_direct, specular_indirect (RGB each).
  std::vector<float> groups;
};

/// Names of the five light groups in PathImage::groups order.
inline constexpr const char* kLightGroupNames[5] = {"emission", "diffuse_direct", "diffuse_indirect",
                                                     "specular_direct", "specular_indirect"};

/// The path tracer's per-pixel running sums, accumulated in each pixel's sample order: what a
/// checkpoint saves and a resumed render continues from (plain data, written as raw bytes).
struct PathAccumulators {
  struct Pixel {
    double rgba[4] = {0, 0, 0, 0};
    double sum_y = 0, sum_y2 = 0;  ///< luminance sums for the error estimate
    uint32_t n = 0;                ///< samples taken
    uint32_t active = 1;           ///< 0 once adaptive sampling stopped the pixel
  };
  PixelWindow window;              ///< the render window the pixels cover
  std::vector<Pixel> pixels;
  std::vector<double> groups;      ///< 15 light-group sums per pixel, or empty
  uint32_t reached = 0;            ///< samples every still-active pixel has taken
  int passes = 0;                  ///< passes completed
  bool complete = false;           ///< the requested spp (or adaptive convergence) was reached
};

/// Called after every completed pass with the accumulators (for checkpoints).
using PassFn = std::function<void(const PathAccumulators& state)>;

/// Renders with the path tracer. Same requirements as render_whitted; `lights` must be built
/// from the same scene (build_area_lights) with a non-null environment.
/// `state`, if given, is continued from when it matches the config's window and light groups
/// (a resumed render: passes already done are skipped, so the result is bit-identical to an
/// uninterrupted render with the same settings), and holds the final sums afterwards.
/// Between passes the render stops early when config.stop is set or the time limit is near.
PathImage render_path(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                      const Camera& camera, const RenderConfig& config,
                      RenderStats* stats = nullptr, const ProgressFn& progress = {},
                      PathAccumulators* state = nullptr, const PassFn& after_pass = {});

/// The image (means, counts, variances, light groups) of a set of accumulators.
PathImage resolve_path_image(const PathAccumulators& state, const RenderConfig& config);

/// One pixel exactly as render_path computes it with all `config.spp` samples (no adaptive
/// stop): the replay behind --debug-pixel.
void render_path_pixel(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                       const Camera& camera, const RenderConfig& config, int x, int y,
                       float rgba[4], RayCounts& counts);

/// Raster position (pixel corner at integer coordinates) of camera sample `s` of pixel (x, y)
/// exactly as `integrator` places it: the one definition the integrators, the data AOVs and
/// the cost map share.
Vec2f camera_sample_position(const RenderConfig& config, IntegratorType integrator, int x, int y,
                             uint32_t s);

/// The pass schedule of render_path: sample index where pass k ends (1, 2, 4, 8, 16, 32, 48,
/// ... capped at spp).
std::vector<int> path_pass_ends(int spp);

/// Error estimate of a pixel for adaptive sampling (as Cycles weighs it): the standard error
/// of its mean luminance divided by sqrt(mean luminance), so that dark pixels, where the
/// display transform stretches noise, need a proportionally smaller absolute error.
float pixel_error(double sum_y, double sum_y2, uint32_t n);

}  // namespace penumbra
