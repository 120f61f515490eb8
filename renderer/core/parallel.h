// The one pixel scheduler: every image loop (beauty passes, data AOVs, cost maps) walks its
// window in square tiles on a TBB arena of a chosen size, and the one thread-count rule.
// Tiles carry no state between pixels, so a pixel's value depends only on (pixel, sample) and
// images are bit-identical for any thread count or tile size.
#pragma once

#include <tbb/task_arena.h>

#include <functional>

namespace penumbra {

/// A rectangle of pixels [x0, x1) x [y0, y1) of the full frame.
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

/// Worker threads for a request: `requested` if > 0, else every hardware thread TBB reports.
int thread_count(int requested);

/// Runs a function over the tiles of a window, in parallel on its own arena. Tiles are
/// tile_size x tile_size pixels (smaller at the right and bottom edges), row-major from the
/// window's top-left corner; each pixel of the window lies in exactly one tile.
class TileScheduler {
 public:
  /// Requires tile_size >= 1; threads as thread_count().
  TileScheduler(const PixelWindow& window, int tile_size, int threads);

  int threads() const { return m_threads; }
  int tile_count() const { return m_tiles_x * m_tiles_y; }
  /// Calls fn(tile) once per tile (frame coordinates), concurrently from worker threads; fn
  /// must be thread-safe. Returns when every tile is done.
  void for_each_tile(const std::function<void(const PixelWindow& tile)>& fn);

 private:
  PixelWindow m_window;
  int m_tile_size = 1;
  int m_tiles_x = 0, m_tiles_y = 0;
  int m_threads = 1;
  tbb::task_arena m_arena;
};

}  // namespace penumbra
