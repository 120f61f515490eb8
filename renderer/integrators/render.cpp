// Image renderer: Whitted (one pass) and path tracer (progressive passes).
#include "renderer/integrators/render.h"

#include <atomic>
#include <chrono>

#include "renderer/core/rng.h"
#include "renderer/integrators/visibility.h"

namespace penumbra {

namespace {

using Clock = std::chrono::steady_clock;

bool is_plain_box(const PixelFilter& f) {
  return f.type == FilterType::Box && f.width == 1;
}

// Raster position of a camera sample from u in [0,1)^2 by filter importance sampling.
Vec2f filtered_position(const RenderConfig& config, int x, int y, Vec2f u) {
  const Vec2f o = sample_filter(config.filter, u);
  return {float(x) + 0.5f + o.x, float(y) + 0.5f + o.y};
}

// Whitted's sample s of pixel (x, y): stratified jitter, through the filter unless it is the
// plain 1-pixel box (then the jittered position itself).
Vec2f whitted_position(const RenderConfig& config, int x, int y, uint32_t s) {
  Rng rng = make_pixel_rng(uint32_t(x), uint32_t(y), s, config.seed);
  const Vec2f j = stratified_sample(s, uint32_t(config.spp), rng);
  if (is_plain_box(config.filter)) return {float(x) + j.x, float(y) + j.y};
  return filtered_position(config, x, y, j);
}

// Whitted's sample s of pixel (x, y): the stratified position, then the aperture point and the
// time from a Sobol stream of their own.
CameraSample whitted_camera_sample(const Camera& camera, const RenderConfig& config, int x, int y,
                                   uint32_t s) {
  CameraSample cs{whitted_position(config, x, y, s)};
  if (!(camera.lens.radius > 0) && !config.motion_blur) return cs;
  constexpr uint64_t kLensTimeSeed = 0xa9e7'0e5a'11e5'0f0cull;
  SampleStream st =
      make_sample_stream(SamplerType::Sobol, uint32_t(x), uint32_t(y), s, config.seed ^ kLensTimeSeed);
  if (camera.lens.radius > 0) cs.aperture = sample_aperture(camera.lens, st.get2d());
  if (config.motion_blur) cs.time = st.get1d();
  return cs;
}

// The camera sample a path stream begins with: its first request places it on the film, its
// second (with a lens only) on the aperture, the next (with motion blur only) in the shutter.
CameraSample take_path_camera_sample(const Camera& camera, const RenderConfig& config, int x, int y,
                                     SampleStream& st) {
  CameraSample cs;
  cs.film = filtered_position(config, x, y, st.get2d());
  if (camera.lens.radius > 0) cs.aperture = sample_aperture(camera.lens, st.get2d());
  if (config.motion_blur) cs.time = st.get1d();
  return cs;
}

// The ray of camera sample `cs` through film position `film` (the sample's own, or a
// differential's): through its aperture point, at its time, from where the camera is then.
Ray sample_ray(const Camera& camera, const CameraRaster& raster, const CameraSample& cs, Vec2f film) {
  Ray r = move_camera_ray(
      camera, thin_lens_ray(camera, raster_ray(camera, raster, film.x, film.y), cs.aperture), cs.time);
  r.time = cs.time;
  return r;
}

// A camera ray of sample `cs` with differentials `step` pixels apart.
Ray camera_ray(const Camera& camera, const RenderConfig& config, const CameraSample& cs, float step,
               RayDifferential& rd) {
  const CameraRaster raster = camera_raster(camera, config.width, config.height);
  const Ray rx = sample_ray(camera, raster, cs, {cs.film.x + step, cs.film.y});
  const Ray ry = sample_ray(camera, raster, cs, {cs.film.x, cs.film.y + step});
  rd = RayDifferential{true, rx.org, rx.dir, ry.org, ry.dir};
  return sample_ray(camera, raster, cs, cs.film);
}

struct RayCounters {
  std::atomic<uint64_t> camera{0}, shadow{0}, reflection{0};
  void add(const RayCounts& c) {
    camera += c.camera;
    shadow += c.shadow;
    reflection += c.reflection;
  }
  RayCounts load() const { return {camera.load(), shadow.load(), reflection.load()}; }
};

// A film covering the render window.
Film window_film(const RenderConfig& config) {
  const PixelWindow w = render_window(config);
  Film f = make_film(w.width(), w.height());
  f.origin_x = w.x0;
  f.origin_y = w.y0;
  f.full_width = config.width;
  f.full_height = config.height;
  return f;
}

TileScheduler make_scheduler(const RenderConfig& config) {
  return TileScheduler(render_window(config), config.tile_size, config.threads);
}

}  // namespace

float differential_step(int spp) {
  return std::max(0.125f, 1.0f / std::sqrt(float(spp)));
}

Vec2f camera_sample_position(const RenderConfig& config, IntegratorType integrator, int x, int y,
                             uint32_t s) {
  if (integrator != IntegratorType::Path) return whitted_position(config, x, y, s);
  SampleStream st = make_sample_stream(config.sampler, uint32_t(x), uint32_t(y), s, config.seed);
  return filtered_position(config, x, y, st.get2d());  // the stream's first request (path_samples)
}

CameraSample camera_sample(const Camera& camera, const RenderConfig& config, IntegratorType integrator, int x,
                           int y, uint32_t s) {
  if (integrator == IntegratorType::Raster) return {whitted_position(config, x, y, s)};
  if (integrator == IntegratorType::Whitted) return whitted_camera_sample(camera, config, x, y, s);
  SampleStream st = make_sample_stream(config.sampler, uint32_t(x), uint32_t(y), s, config.seed);
  return take_path_camera_sample(camera, config, x, y, st);
}

Ray camera_sample_ray(const Camera& camera, const RenderConfig& config, IntegratorType integrator, int x,
                      int y, uint32_t s) {
  const CameraSample cs = camera_sample(camera, config, integrator, x, y, s);
  return sample_ray(camera, camera_raster(camera, config.width, config.height), cs, cs.film);
}

Vec3f whitted_sample(const Scene& scene, const Accelerator& accel, const Camera& camera,
                     const RenderConfig& config, int x, int y, uint32_t s, float& coverage, RayCounts& counts,
                     DeepTrace* deep) {
  const CameraSample cs = whitted_camera_sample(camera, config, x, y, s);
  RayDifferential rd;
  const Ray ray = camera_ray(camera, config, cs, differential_step(config.spp), rd);
  return whitted_radiance(scene, accel, config.whitted, ray, rd, coverage, counts, deep);
}

void render_whitted_pixel(const Scene& scene, const Accelerator& accel, const Camera& camera,
                          const RenderConfig& config, int x, int y, float rgba[4], RayCounts& counts) {
  const uint32_t n = uint32_t(config.spp);
  Vec3f sum{0, 0, 0};
  float alpha = 0;
  for (uint32_t s = 0; s < n; ++s) {
    float coverage = 0;
    sum += whitted_sample(scene, accel, camera, config, x, y, s, coverage, counts);
    alpha += coverage;
  }
  // The plain mean of the pixel's samples.
  const float inv = 1.0f / float(n);
  rgba[0] = sum.x * inv;
  rgba[1] = sum.y * inv;
  rgba[2] = sum.z * inv;
  rgba[3] = alpha * inv;
}

Film render_whitted(const Scene& scene, const Accelerator& accel, const Camera& camera,
                    const RenderConfig& user_config, RenderStats* stats, const ProgressFn& progress) {
  RenderConfig config = user_config;
  config.whitted.hit_filter = config.whitted.hit_filter && scene_needs_hit_filter(scene);
  const auto t0 = Clock::now();
  Film film = window_film(config);
  TileScheduler scheduler = make_scheduler(config);
  const int tiles = scheduler.tile_count();
  RayCounters rays;
  std::atomic<int> done{0};
  scheduler.for_each_tile([&](const PixelWindow& tile) {
    RayCounts counts;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        render_whitted_pixel(scene, accel, camera, config, x, y,
                             film.pixel(x - film.origin_x, y - film.origin_y), counts);
    rays.add(counts);
    const int d = ++done;
    if (progress) progress(d, tiles);
  });
  if (stats) {
    stats->rays = rays.load();
    stats->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    stats->threads = scheduler.threads();
    stats->passes = 1;
    stats->samples = uint64_t(film.width) * uint64_t(film.height) * uint64_t(config.spp);
  }
  return film;
}

std::vector<int> path_pass_ends(int spp) {
  std::vector<int> ends;
  int n = 0;
  while (n < spp) {
    n = std::min(spp, n + std::max(1, std::min(n, 16)));
    ends.push_back(n);
  }
  return ends;
}

float pixel_error(double sum_y, double sum_y2, uint32_t n) {
  if (n < 2) return kInfinity;
  const double mean = sum_y / n;
  const double var = std::max(0.0, (sum_y2 - sum_y * mean) / double(n - 1));
  const double standard_error = std::sqrt(var / n);
  return float(standard_error / std::sqrt(std::max(mean, 1e-4)));
}

namespace {

// Per-pixel accumulators of the path tracer.
using PixelAccum = PathAccumulators::Pixel;

}  // namespace

Vec3f path_sample(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                  const Camera& camera, const RenderConfig& config, const PathConfig& pc, int x, int y,
                  uint32_t s, float& coverage, RayCounts& counts, LightGroups* groups, DeepTrace* deep) {
  // The differential rays of camera ray p, made only for a first hit that needs them.
  struct Footprint {
    const Camera& camera;
    CameraRaster raster;
    CameraSample cs;
    float step;
  };
  const auto make_rd = [](const void* ctx) {
    const Footprint& f = *static_cast<const Footprint*>(ctx);
    const Vec2f p = f.cs.film;
    const Ray rx = sample_ray(f.camera, f.raster, f.cs, {p.x + f.step, p.y});
    const Ray ry = sample_ray(f.camera, f.raster, f.cs, {p.x, p.y + f.step});
    return RayDifferential{true, rx.org, rx.dir, ry.org, ry.dir};
  };
  SampleStream samples = make_sample_stream(config.sampler, uint32_t(x), uint32_t(y), s, config.seed);
  const CameraRaster raster = camera_raster(camera, config.width, config.height);
  const Footprint fp{camera, raster, take_path_camera_sample(camera, config, x, y, samples),
                     differential_step(config.spp)};
  const Ray ray = sample_ray(camera, raster, fp.cs, fp.cs.film);
  return path_radiance(scene, accel, lights, pc, ray, LazyDifferential{make_rd, &fp}, samples, coverage,
                       counts, groups, deep);
}

namespace {

// Adds samples [s0, s1) of pixel (x, y) to `acc` (and their light groups to `groups`,
// kLightGroupChannels sums, and the odd-numbered samples' RGBA to `odd`, if not null).
void path_samples(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                  const Camera& camera, const RenderConfig& config, const PathConfig& pc, int x, int y,
                  uint32_t s0, uint32_t s1, PixelAccum& acc, RayCounts& counts, double* groups = nullptr,
                  double* odd = nullptr) {
  for (uint32_t s = s0; s < s1; ++s) {
    float coverage = 0;
    LightGroups lg;
    const Vec3f l = path_sample(scene, accel, lights, camera, config, pc, x, y, s, coverage, counts,
                                groups ? &lg : nullptr);
    if (groups) add_light_groups(lg, groups);
    acc.rgba[0] += l.x;
    acc.rgba[1] += l.y;
    acc.rgba[2] += l.z;
    acc.rgba[3] += coverage;
    if (odd && (s & 1u)) {
      odd[0] += l.x;
      odd[1] += l.y;
      odd[2] += l.z;
      odd[3] += coverage;
    }
    const double y_lum = luminance(l);
    acc.sum_y += y_lum;
    acc.sum_y2 += y_lum * y_lum;
    ++acc.n;
  }
}

void resolve(const PixelAccum& acc, float rgba[4]) {
  const double inv = acc.n ? 1.0 / acc.n : 0.0;
  for (int c = 0; c < 4; ++c) rgba[c] = float(acc.rgba[c] * inv);
}

}  // namespace

void render_path_pixel(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                       const Camera& camera, const RenderConfig& config, int x, int y, float rgba[4],
                       RayCounts& counts) {
  PathConfig pc = config.path;
  pc.hit_filter = pc.hit_filter && scene_needs_hit_filter(scene);
  PixelAccum acc;
  path_samples(scene, accel, lights, camera, config, pc, x, y, 0, uint32_t(config.spp), acc, counts);
  resolve(acc, rgba);
}

PathImage resolve_path_image(const PathAccumulators& state, const RenderConfig& config) {
  const size_t npix = state.pixels.size();
  PathImage image;
  image.film = window_film(config);
  image.samples.resize(npix);
  image.variance.resize(npix);
  for (size_t i = 0; i < npix && i * 4 < image.film.rgba.size(); ++i) {
    const PixelAccum& acc = state.pixels[i];
    resolve(acc, &image.film.rgba[i * 4]);
    image.samples[i] = acc.n;
    if (!state.groups.empty()) {
      constexpr size_t kG = kLightGroupChannels;
      if (image.groups.empty()) image.groups.assign(npix * kG, 0.0f);
      for (size_t k = 0; k < kG; ++k)
        image.groups[i * kG + k] = acc.n ? float(state.groups[i * kG + k] / acc.n) : 0.0f;
    }
    if (!state.odd.empty()) {
      if (image.halves.empty()) image.halves.assign(npix * kHalfChannels, 0.0f);
      // Samples 0, 2, 4, ... are the even half, 1, 3, ... the odd one.
      const uint32_t n_odd = acc.n / 2, n_even = acc.n - n_odd;
      float* h = &image.halves[i * kHalfChannels];
      for (int c = 0; c < 3; ++c) {
        const double odd_sum = state.odd[i * 4 + size_t(c)];
        const double even = n_even ? (acc.rgba[c] - odd_sum) / n_even : 0.0;
        h[c] = float(even);
        h[3 + c] = n_odd ? float(odd_sum / n_odd) : float(even);
      }
    }
    if (acc.n >= 2) {
      const double mean = acc.sum_y / acc.n;
      image.variance[i] = float(std::max(0.0, (acc.sum_y2 - acc.sum_y * mean) / double(acc.n - 1)) / acc.n);
    }
  }
  return image;
}

bool matches(const PathAccumulators& state, const RenderConfig& config) {
  const PixelWindow w = render_window(config);
  return state.window.x0 == w.x0 && state.window.y0 == w.y0 && state.window.x1 == w.x1 &&
         state.window.y1 == w.y1 && state.pixels.size() == size_t(w.width()) * size_t(w.height()) &&
         state.groups.size() == (config.light_groups ? state.pixels.size() * kLightGroupChannels : 0) &&
         state.odd.size() == (config.halves ? state.pixels.size() * 4 : 0);
}

PathImage render_path(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                      const Camera& camera, const RenderConfig& config, RenderStats* stats,
                      const ProgressFn& progress, PathAccumulators* resume, const PassFn& after_pass) {
  PathConfig pc = config.path;
  pc.hit_filter = pc.hit_filter && scene_needs_hit_filter(scene);
  const auto t0 = Clock::now();
  const PixelWindow win = render_window(config);
  const size_t npix = size_t(win.width()) * size_t(win.height());
  PathAccumulators local;
  PathAccumulators& state = resume ? *resume : local;
  if (state.pixels.empty() || !matches(state, config)) {  // a fresh start
    state = PathAccumulators{};
    state.window = win;
    state.pixels.assign(npix, PixelAccum{});
    state.groups.assign(config.light_groups ? npix * kLightGroupChannels : 0, 0.0);
    state.odd.assign(config.halves ? npix * 4 : 0, 0.0);
  }
  std::vector<PixelAccum>& accum = state.pixels;
  std::vector<double>& group_sums = state.groups;
  const std::vector<int> ends = path_pass_ends(config.spp);
  TileScheduler scheduler = make_scheduler(config);
  const int total_units = scheduler.tile_count() * int(ends.size());
  const bool adaptive = config.adaptive_threshold > 0;
  const uint32_t min_spp = uint32_t(std::max(2, std::min(config.adaptive_min_spp, config.spp)));
  RayCounters rays;
  std::atomic<int> done{0};
  std::atomic<uint64_t> active_pixels{0};
  int passes = 0;
  bool time_limited = false;
  uint32_t begin = state.reached;  // every pixel still sampling has taken exactly this many
  size_t first = 0;
  while (first < ends.size() && uint32_t(ends[first]) <= begin) ++first;
  done = int(first) * scheduler.tile_count();
  for (size_t pass = first; pass < ends.size(); ++pass) {
    const auto pass_start = Clock::now();
    const uint32_t pass_begin = begin;
    const uint32_t end = uint32_t(ends[pass]);
    active_pixels = 0;
    scheduler.for_each_tile([&](const PixelWindow& tile) {
      RayCounts counts;
      uint64_t active = 0;
      for (int y = tile.y0; y < tile.y1; ++y)
        for (int x = tile.x0; x < tile.x1; ++x) {
          const size_t pi = size_t(y - win.y0) * size_t(win.width()) + size_t(x - win.x0);
          PixelAccum& acc = accum[pi];
          if (!acc.active) continue;
          path_samples(scene, accel, lights, camera, config, pc, x, y, begin, end, acc, counts,
                       group_sums.empty() ? nullptr : &group_sums[pi * kLightGroupChannels],
                       state.odd.empty() ? nullptr : &state.odd[pi * 4]);
          if (adaptive && acc.n >= min_spp &&
              pixel_error(acc.sum_y, acc.sum_y2, acc.n) < config.adaptive_threshold)
            acc.active = false;
          active += acc.active;
        }
      rays.add(counts);
      active_pixels += active;
      const int d = ++done;
      if (progress) progress(d, total_units);
    });
    ++passes;
    ++state.passes;
    begin = end;
    state.reached = end;
    if (after_pass) after_pass(state);
    if (end >= uint32_t(config.spp) || (adaptive && active_pixels.load() == 0)) {
      state.complete = true;
      break;
    }
    if (config.stop && config.stop->load()) break;
    if (config.time_limit > 0) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - t0).count();
      const double last = std::chrono::duration<double>(Clock::now() - pass_start).count();
      // Stop unless the next pass (at most as long as this one, scaled by its sample count)
      // still fits in the limit.
      const double next =
          last * double(uint32_t(ends[pass + 1]) - end) / double(std::max(1u, end - pass_begin));
      if (elapsed + next > config.time_limit) {
        time_limited = true;
        break;
      }
    }
  }
  if (first >= ends.size()) state.complete = true;  // resumed at or beyond the requested spp

  PathImage image = resolve_path_image(state, config);
  if (stats) {
    uint64_t total_samples = 0;
    for (uint32_t n : image.samples) total_samples += n;
    stats->rays = rays.load();
    stats->seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    stats->threads = scheduler.threads();
    stats->passes = passes;
    stats->image_passes = state.passes;
    stats->samples = total_samples;
    stats->time_limited = time_limited;
  }
  return image;
}

}  // namespace penumbra
