// Traversal-cost images: see cost_map.h.
#include "renderer/cost_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "renderer/sampling.h"

namespace penumbra {

CostImage render_cost(const Accelerator& accel, const Camera& camera, const RenderConfig& config) {
  CostImage img{config.width, config.height, {}, {}};
  const size_t n = size_t(config.width) * size_t(config.height);
  img.nodes.assign(n, 0.0f);
  img.triangles.assign(n, 0.0f);
  const uint32_t spp = uint32_t(config.spp);
  const int threads = config.threads > 0 ? config.threads : tbb::this_task_arena::max_concurrency();
  tbb::task_arena arena(threads);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, config.height), [&](const tbb::blocked_range<int>& rows) {
      for (int y = rows.begin(); y != rows.end(); ++y)
        for (int x = 0; x < config.width; ++x) {
          TraversalCost cost;
          for (uint32_t s = 0; s < spp; ++s) {  // the beauty's samples (render.cpp)
            Rng rng = make_pixel_rng(uint32_t(x), uint32_t(y), s, config.seed);
            const Vec2f j = stratified_sample(s, spp, rng);
            const Ray ray = generate_camera_ray(camera, config.width, config.height, float(x) + j.x, float(y) + j.y);
            Hit hit;
            accel.intersect_counted(ray, hit, cost);
          }
          const size_t i = size_t(y) * size_t(config.width) + size_t(x);
          img.nodes[i] = float(double(cost.nodes) / spp);
          img.triangles[i] = float(double(cost.triangles) / spp);
        }
    });
  });
  return img;
}

std::vector<float> total_cost(const CostImage& cost) {
  std::vector<float> total(cost.nodes.size());
  for (size_t i = 0; i < total.size(); ++i) total[i] = cost.nodes[i] + cost.triangles[i];
  return total;
}

}  // namespace penumbra
