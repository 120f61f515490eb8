// The film: a scene-linear RGBA float image, colour premultiplied by alpha (coverage).
#pragma once

#include <cstddef>
#include <vector>

namespace penumbra {

struct Film {
  int width = 0, height = 0;
  std::vector<float> rgba;  ///< row-major, top row first, 4 floats per pixel
  /// Where this film lies in the full frame (a crop or farm tile: its EXR data window inside
  /// the full_width x full_height display window). A whole frame has origin 0 and full = size.
  int origin_x = 0, origin_y = 0;
  int full_width = 0, full_height = 0;

  float* pixel(int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
  const float* pixel(int x, int y) const { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
};

inline Film make_film(int width, int height) {
  return Film{width, height, std::vector<float>(size_t(width) * size_t(height) * 4, 0.0f), 0, 0,
              width, height};
}

}  // namespace penumbra
