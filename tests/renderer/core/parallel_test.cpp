// Tests for renderer/core/parallel: the tile scheduler visits every pixel of any window exactly
// once for odd sizes, any tile size and any thread count, and the thread-count rule.
#include "renderer/core/parallel.h"

#include <atomic>
#include <catch2/catch.hpp>
#include <vector>

using namespace penumbra;

TEST_CASE("tile scheduler: each pixel of the window exactly once, any tiles and threads",
          "[parallel][quick]") {
  for (const PixelWindow w : {PixelWindow{0, 0, 1, 1}, PixelWindow{0, 0, 37, 23}, PixelWindow{5, 3, 70, 40},
                              PixelWindow{10, 7, 11, 64}})
    for (int tile_size : {1, 3, 8, 32, 100})
      for (int threads : {0, 1, 2, 7}) {
        const int width = w.x1 + 3, height = w.y1 + 2;  // a frame larger than the window
        std::vector<std::atomic<int>> visits(size_t(width) * size_t(height));
        TileScheduler scheduler(w, tile_size, threads);
        CHECK(scheduler.threads() == thread_count(threads));
        std::atomic<int> tiles{0};
        scheduler.for_each_tile([&](const PixelWindow& t) {
          ++tiles;
          CHECK(!t.empty());
          CHECK(t.width() <= tile_size);
          CHECK(t.height() <= tile_size);
          for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x) ++visits[size_t(y) * size_t(width) + size_t(x)];
        });
        CHECK(tiles.load() == scheduler.tile_count());
        int wrong = 0;
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < width; ++x) {
            const bool inside = x >= w.x0 && x < w.x1 && y >= w.y0 && y < w.y1;
            wrong += visits[size_t(y) * size_t(width) + size_t(x)].load() != (inside ? 1 : 0);
          }
        INFO("window " << w.x0 << "," << w.y0 << " - " << w.x1 << "," << w.y1 << " tile " << tile_size
                       << " threads " << threads);
        CHECK(wrong == 0);
      }
}

TEST_CASE("tile scheduler: an empty window runs nothing", "[parallel][quick]") {
  TileScheduler scheduler(PixelWindow{}, 16, 2);
  CHECK(scheduler.tile_count() == 0);
  int calls = 0;
  scheduler.for_each_tile([&](const PixelWindow&) { ++calls; });
  CHECK(calls == 0);
}

TEST_CASE("thread_count: a positive request as given, 0 = every hardware thread", "[parallel][quick]") {
  CHECK(thread_count(3) == 3);
  CHECK(thread_count(0) >= 1);
  CHECK(thread_count(-1) == thread_count(0));
}
