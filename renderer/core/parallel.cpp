// The tile scheduler on a TBB arena.
#include "renderer/core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace penumbra {

int thread_count(int requested) {
  return requested > 0 ? requested : tbb::this_task_arena::max_concurrency();
}

TileScheduler::TileScheduler(const PixelWindow& window, int tile_size, int threads)
    : m_window(window),
      m_tile_size(std::max(1, tile_size)),
      m_threads(thread_count(threads)),
      m_arena(m_threads) {
  if (!window.empty()) {
    m_tiles_x = (window.width() + m_tile_size - 1) / m_tile_size;
    m_tiles_y = (window.height() + m_tile_size - 1) / m_tile_size;
  }
}

void TileScheduler::for_each_tile(const std::function<void(const PixelWindow& tile)>& fn) {
  const int ts = m_tile_size;
  const PixelWindow& w = m_window;
  m_arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tile_count(), 1), [&](const tbb::blocked_range<int>& r) {
      for (int tile = r.begin(); tile != r.end(); ++tile) {
        const int x0 = w.x0 + (tile % m_tiles_x) * ts, y0 = w.y0 + (tile / m_tiles_x) * ts;
        fn(PixelWindow{x0, y0, std::min(x0 + ts, w.x1), std::min(y0 + ts, w.y1)});
      }
    });
  });
}

}  // namespace penumbra
