// The image renderer of both integrators: Whitted in one pass, the path tracer in progressive
// passes with checkpointable per-pixel sums, over the tiles of core/parallel.h with one sample
// stream per (pixel, sample), so the image is bit-identical for any thread count.
#pragma once

// Whitted: stratified jittered supersampling of each pixel, box filtered (or any pixel filter,
// applied by filter importance sampling). Path: progressive passes over the image (1, 2, 4, 8,
// 16 samples, then 16 per pass), each pixel the mean of its samples, with an optional time limit
// (checked after each whole pass) and optional adaptive sampling that stops pixels whose
// estimated error falls below a threshold. Each pixel's value depends only on its own
// samples, so neither threads, tiles nor the pass schedule change it.

#include <cstdint>
#include <functional>
#include <vector>

#include "renderer/film/film.h"
#include "renderer/integrators/path.h"
#include "renderer/integrators/ray_counts.h"
#include "renderer/integrators/render_config.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/whitted.h"
#include "renderer/scene/camera.h"

namespace penumbra {

struct RenderStats {
  RayCounts rays;
  double seconds = 0;
  int threads = 0;
  int passes = 0;             ///< path: passes rendered by this call
  int image_passes = 0;       ///< path: passes the image holds, a resumed render's earlier ones included
  uint64_t samples = 0;       ///< camera samples taken in all
  bool time_limited = false;  ///< path: the time limit ended the render early
};

/// Called after each finished tile with (tiles done, tiles total), from worker threads;
/// the callee must be thread-safe. May be empty.
using ProgressFn = std::function<void(int done, int total)>;

/// Renders the scene with the Whitted integrator. Requires a config that passes validate()
/// and an accelerator from make_scene_accelerator(name, scene).
Film render_whitted(const Scene& scene, const Accelerator& accel, const Camera& camera,
                    const RenderConfig& config, RenderStats* stats = nullptr,
                    const ProgressFn& progress = {});

/// One pixel's value (RGBA, premultiplied) exactly as render_whitted computes it: the
/// replay behind `penumbra render --debug-pixel x,y`.
void render_whitted_pixel(const Scene& scene, const Accelerator& accel, const Camera& camera,
                          const RenderConfig& config, int x, int y, float rgba[4], RayCounts& counts);

/// Camera sample `s` of pixel (x, y) exactly as render_whitted takes it (its position, lens
/// point and time, its differentials): the radiance, its coverage, and with `deep` the layers it
/// composited. `config` as render_whitted uses it (hit_filter only where the scene needs it).
Vec3f whitted_sample(const Scene& scene, const Accelerator& accel, const Camera& camera,
                     const RenderConfig& config, int x, int y, uint32_t s, float& coverage, RayCounts& counts,
                     DeepTrace* deep = nullptr);

/// Camera sample `s` of pixel (x, y) exactly as render_path takes it (its own sample stream),
/// with path tracer settings `pc` (hit_filter only where the scene needs it): the radiance, its
/// coverage, the light groups and the deep record when asked for.
Vec3f path_sample(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                  const Camera& camera, const RenderConfig& config, const PathConfig& pc, int x, int y,
                  uint32_t s, float& coverage, RayCounts& counts, LightGroups* groups = nullptr,
                  DeepTrace* deep = nullptr);

/// A path-traced image with its per-pixel statistics.
struct PathImage {
  Film film;                      ///< mean of each pixel's samples (RGBA, premultiplied);
                                  ///< all per-pixel vectors cover render_window(config)
  std::vector<uint32_t> samples;  ///< samples taken per pixel
  std::vector<float> variance;    ///< variance of each pixel's mean luminance (0 if n < 2)
  /// With RenderConfig::light_groups: kLightGroupChannels floats per pixel, the means of the
  /// light groups in kLightGroupNames order (RGB each).
  std::vector<float> groups;
  /// With RenderConfig::halves: kHalfChannels floats per pixel, the mean RGB (premultiplied) of
  /// the pixel's even-numbered samples, then of its odd-numbered ones (the even mean again for a
  /// pixel of one sample).
  std::vector<float> halves;
};

/// Floats per pixel of PathImage::halves.
inline constexpr int kHalfChannels = 6;

/// The path tracer's per-pixel running sums, accumulated in each pixel's sample order: what a
/// checkpoint saves and a resumed render continues from (plain data, written as raw bytes).
struct PathAccumulators {
  struct Pixel {
    double rgba[4] = {0, 0, 0, 0};
    double sum_y = 0, sum_y2 = 0;  ///< luminance sums for the error estimate
    uint32_t n = 0;                ///< samples taken
    uint32_t active = 1;           ///< 0 once adaptive sampling stopped the pixel
  };
  PixelWindow window;  ///< the render window the pixels cover
  std::vector<Pixel> pixels;
  std::vector<double> groups;  ///< kLightGroupChannels light-group sums per pixel, or empty
  /// With RenderConfig::halves: 4 sums per pixel (RGBA) of its odd-numbered samples, or empty.
  std::vector<double> odd;
  uint32_t reached = 0;   ///< samples every still-active pixel has taken
  int passes = 0;         ///< passes completed
  bool complete = false;  ///< the requested spp (or adaptive convergence) was reached
};

/// Bytes of one pixel's accumulators as a checkpoint stores them (raw, native byte order).
inline constexpr size_t kPathPixelBytes = sizeof(PathAccumulators::Pixel);
static_assert(kPathPixelBytes == 56, "checkpoints store PathAccumulators::Pixel as 56 raw bytes");

/// Called after every completed pass with the accumulators (for checkpoints).
using PassFn = std::function<void(const PathAccumulators& state)>;

/// Renders with the path tracer. Same requirements as render_whitted; `lights` must be built
/// from the same scene (build_area_lights) with a non-null environment.
/// `state`, if given, is continued from when it matches the config's window and light groups
/// (a resumed render: passes already done are skipped, so the result is bit-identical to an
/// uninterrupted render with the same settings), and holds the final sums afterwards.
/// Between passes the render stops early when config.stop is set or the time limit is near.
PathImage render_path(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                      const Camera& camera, const RenderConfig& config, RenderStats* stats = nullptr,
                      const ProgressFn& progress = {}, PathAccumulators* state = nullptr,
                      const PassFn& after_pass = {});

/// The image (means, counts, variances, light groups) of a set of accumulators.
PathImage resolve_path_image(const PathAccumulators& state, const RenderConfig& config);

/// One pixel exactly as render_path computes it with all `config.spp` samples (no adaptive
/// stop): the replay behind --debug-pixel.
void render_path_pixel(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                       const Camera& camera, const RenderConfig& config, int x, int y, float rgba[4],
                       RayCounts& counts);

/// Raster position (pixel corner at integer coordinates) of camera sample `s` of pixel (x, y)
/// exactly as `integrator` places it (Raster: as Whitted): the one definition the integrators,
/// the rasteriser, the data AOVs and the cost map share.
Vec2f camera_sample_position(const RenderConfig& config, IntegratorType integrator, int x, int y, uint32_t s);

/// A camera sample: where it lies on the film (raster position) and on the aperture (a
/// sample_aperture point; {0, 0} for a pinhole).
struct CameraSample {
  Vec2f film;
  Vec2f aperture{0, 0};
  float time = 0.5f;  ///< in the shutter (Ray::time); the middle without motion blur
};

/// Camera sample `s` of pixel (x, y) exactly as `integrator` takes it: the position of
/// camera_sample_position and, through a thin lens with a radius, the aperture point (the path
/// stream's second request; Whitted's own Sobol stream), and with config.motion_blur the time
/// (the path stream's next request; the next of Whitted's own stream). The raster integrator
/// renders through a pinhole at the middle of the shutter.
CameraSample camera_sample(const Camera& camera, const RenderConfig& config, IntegratorType integrator, int x,
                           int y, uint32_t s);

/// The camera ray of camera_sample(...): what the integrators trace first, and what the data
/// AOVs, Cryptomatte and the cost map trace to see the same surfaces.
Ray camera_sample_ray(const Camera& camera, const RenderConfig& config, IntegratorType integrator, int x,
                      int y, uint32_t s);

/// The spacing in pixels of the differentials of a render with `spp` samples per pixel, the
/// footprint textures are filtered over (pbrt-v4: max(1/8, 1/sqrt(spp))).
float differential_step(int spp);

/// The pass schedule of render_path: sample index where pass k ends (1, 2, 4, 8, 16, 32, 48,
/// ... capped at spp).
std::vector<int> path_pass_ends(int spp);

/// Error estimate of a pixel for adaptive sampling (as Cycles weighs it): the standard error
/// of its mean luminance divided by sqrt(mean luminance), so that dark pixels, where the
/// display transform stretches noise, need a proportionally smaller absolute error.
float pixel_error(double sum_y, double sum_y2, uint32_t n);

}  // namespace penumbra
