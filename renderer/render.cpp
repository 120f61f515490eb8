// Tile renderer.
#include "renderer/render.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>

#include "renderer/sampling.h"

namespace penumbra {

void render_whitted_pixel(const Scene& scene, const Accelerator& accel, const Camera& camera,
                          const RenderConfig& config, int x, int y, float rgba[4],
                          RayCounts& counts) {
  const uint32_t n = uint32_t(config.spp);
  // Differentials one sample spacing apart (pbrt-v4: scaled by max(1/8, 1/sqrt(spp))).
  const float step = std::max(0.125f, 1.0f / std::sqrt(float(n)));
  Vec3f sum{0, 0, 0};
  float alpha = 0;
  for (uint32_t s = 0; s < n; ++s) {
    Rng rng = make_pixel_rng(uint32_t(x), uint32_t(y), s, config.seed);
    const Vec2f j = stratified_sample(s, n, rng);
    const float px = float(x) + j.x, py = float(y) + j.y;
    const Ray ray = generate_camera_ray(camera, config.width, config.height, px, py);
    const Ray rx = generate_camera_ray(camera, config.width, config.height, px + step, py);
    const Ray ry = generate_camera_ray(camera, config.width, config.height, px, py + step);
    const RayDifferential rd{true, rx.org, rx.dir, ry.org, ry.dir};
    float coverage = 0;
    sum += whitted_radiance(scene, accel, config.whitted, ray, rd, coverage, counts);
    alpha += coverage;
  }
  // Box filter: the plain mean of the pixel's samples.
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
  const auto t0 = std::chrono::steady_clock::now();
  Film film = make_film(config.width, config.height);
  const int ts = config.tile_size;
  const int tiles_x = (config.width + ts - 1) / ts, tiles_y = (config.height + ts - 1) / ts;
  const int tiles = tiles_x * tiles_y;
  const int threads = config.threads > 0 ? config.threads : tbb::this_task_arena::max_concurrency();

  std::atomic<uint64_t> camera_rays{0}, shadow_rays{0}, reflection_rays{0};
  std::atomic<int> done{0};
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
      for (int tile = r.begin(); tile != r.end(); ++tile) {
        const int x0 = (tile % tiles_x) * ts, y0 = (tile / tiles_x) * ts;
        const int x1 = std::min(x0 + ts, config.width), y1 = std::min(y0 + ts, config.height);
        RayCounts counts;
        for (int y = y0; y < y1; ++y)
          for (int x = x0; x < x1; ++x)
            render_whitted_pixel(scene, accel, camera, config, x, y, film.pixel(x, y), counts);
        camera_rays += counts.camera;
        shadow_rays += counts.shadow;
        reflection_rays += counts.reflection;
        const int d = ++done;
        if (progress) progress(d, tiles);
      }
    });
  });

  if (stats) {
    stats->rays = {camera_rays.load(), shadow_rays.load(), reflection_rays.load()};
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats->threads = threads;
  }
  return film;
}

}  // namespace penumbra
