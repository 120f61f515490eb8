// The deep pass over the tiles.
#include "renderer/integrators/deep_pass.h"

#include <atomic>

#include "renderer/integrators/visibility.h"

namespace penumbra {

DeepResult render_deep(const Scene& scene, const Accelerator& accel, const PathLights* lights,
                       const Camera& camera, const RenderConfig& user_config, IntegratorType integrator,
                       const std::vector<uint32_t>* samples, const DeepConfig& deep) {
  RenderConfig config = user_config;
  const bool filter = scene_needs_hit_filter(scene);
  config.whitted.hit_filter = config.whitted.hit_filter && filter;
  PathConfig pc = config.path;
  pc.hit_filter = pc.hit_filter && filter;
  const bool path = integrator == IntegratorType::Path;

  const PixelWindow win = render_window(config);
  DeepResult result;
  DeepImage& img = result.image;
  img.width = win.width();
  img.height = win.height();
  img.origin_x = win.x0;
  img.origin_y = win.y0;
  img.full_width = config.width;
  img.full_height = config.height;
  const size_t npix = size_t(img.width) * size_t(img.height);
  img.counts.assign(npix, 0);

  const int ts = config.tile_size;
  const int tiles_x = (img.width + ts - 1) / ts;
  std::vector<std::vector<DeepSample>> tile_samples(size_t(tiles_x) * size_t((img.height + ts - 1) / ts));
  std::atomic<uint64_t> found{0};
  std::atomic<bool> over{false};
  TileScheduler scheduler(win, ts, config.threads);
  scheduler.for_each_tile([&](const PixelWindow& tile) {
    if (over.load()) return;
    std::vector<DeepSample> out;
    DeepPixel pixel;
    DeepTrace trace;
    trace.eye = camera.eye;
    trace.forward = -camera.w;
    RayCounts counts;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = size_t(y - win.y0) * size_t(img.width) + size_t(x - win.x0);
        const uint32_t n = samples ? (*samples)[i] : uint32_t(config.spp);
        pixel.clear();
        for (uint32_t s = 0; s < n; ++s) {
          trace.count = 0;
          float coverage = 0;
          if (path)
            (void)path_sample(scene, accel, *lights, camera, config, pc, x, y, s, coverage, counts, nullptr,
                              &trace);
          else
            (void)whitted_sample(scene, accel, camera, config, x, y, s, coverage, counts, &trace);
          pixel.add(trace);
        }
        img.counts[i] = pixel.resolve(n, deep.merge_tolerance, out);
      }
    // The tile's samples and the image they are copied into exist together for a moment.
    out.shrink_to_fit();
    const uint64_t total = found += out.size();
    if (2 * deep_image_bytes(npix, total) > deep.max_bytes) {
      over = true;
      return;
    }
    const size_t t = size_t((tile.y0 - win.y0) / ts) * size_t(tiles_x) + size_t((tile.x0 - win.x0) / ts);
    tile_samples[t] = std::move(out);
  });
  result.samples_found = found.load();
  result.bytes = deep_image_bytes(npix, result.samples_found);
  if (over.load()) {
    result.over_budget = true;
    img.counts.clear();
    return result;
  }

  // Row-major offsets, then each tile's pixels copied into place in the order they were found.
  std::vector<uint64_t> offset(npix + 1, 0);
  for (size_t i = 0; i < npix; ++i) offset[i + 1] = offset[i] + img.counts[i];
  img.samples.resize(size_t(offset[npix]));
  for (size_t t = 0; t < tile_samples.size(); ++t) {
    const int x0 = int(t % size_t(tiles_x)) * ts, y0 = int(t / size_t(tiles_x)) * ts;
    size_t k = 0;
    for (int y = y0; y < std::min(y0 + ts, img.height); ++y)
      for (int x = x0; x < std::min(x0 + ts, img.width); ++x) {
        const size_t i = size_t(y) * size_t(img.width) + size_t(x);
        std::copy_n(tile_samples[t].begin() + ptrdiff_t(k), img.counts[i],
                    img.samples.begin() + ptrdiff_t(offset[i]));
        k += img.counts[i];
      }
    std::vector<DeepSample>().swap(tile_samples[t]);
  }
  return result;
}

}  // namespace penumbra
