// Traversal-cost images: see cost_map.h.
#include "renderer/integrators/cost_map.h"

#include <chrono>

#include "renderer/core/parallel.h"

namespace penumbra {

CostImage render_cost(const Accelerator& accel, const Camera& camera, const RenderConfig& config,
                      IntegratorType integrator) {
  CostImage img{config.width, config.height, {}, {}, {}};
  const size_t n = size_t(config.width) * size_t(config.height);
  img.nodes.assign(n, 0.0f);
  img.triangles.assign(n, 0.0f);
  img.shapes.assign(n, 0.0f);
  img.nanoseconds.assign(n, 0.0f);
  img.counted = accel.counts_traversal();
  const uint32_t spp = uint32_t(config.spp);
  TileScheduler scheduler(PixelWindow{0, 0, config.width, config.height}, config.tile_size, config.threads);
  scheduler.for_each_tile([&](const PixelWindow& tile) {
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        TraversalCost cost;
        double seconds = 0;
        for (uint32_t s = 0; s < spp; ++s) {  // the beauty's samples (render.cpp)
          const Ray ray = camera_sample_ray(camera, config, integrator, x, y, s);
          Hit hit;
          const auto t0 = std::chrono::steady_clock::now();
          accel.intersect_counted(ray, hit, cost);
          seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        }
        const size_t i = size_t(y) * size_t(config.width) + size_t(x);
        img.nanoseconds[i] = float(seconds * 1e9 / spp);
        img.nodes[i] = float(double(cost.nodes) / spp);
        img.triangles[i] = float(double(cost.triangles) / spp);
        img.shapes[i] = float(double(cost.shapes + cost.evaluations) / spp);
      }
  });
  return img;
}

std::vector<float> total_cost(const CostImage& cost) {
  if (!cost.counted) return cost.nanoseconds;
  std::vector<float> total(cost.nodes.size());
  for (size_t i = 0; i < total.size(); ++i) total[i] = cost.nodes[i] + cost.triangles[i] + cost.shapes[i];
  return total;
}

std::string cost_caption(const CostImage& cost, const std::string& accel_name) {
  return accel_name + (cost.counted ? ": nodes + triangles + shape work per camera ray"
                                    : ": nanoseconds per camera ray (wall clock)");
}

}  // namespace penumbra
