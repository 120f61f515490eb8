// The film: a scene-linear RGBA float image, colour premultiplied by alpha (coverage).
#pragma once

#include <cstddef>
#include <vector>

namespace penumbra {

struct Film {
  int width = 0, height = 0;
  std::vector<float> rgba;  ///< row-major, top row first, 4 floats per pixel

  float* pixel(int x, int y) { return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
  const float* pixel(int x, int y) const {
    return &rgba[(size_t(y) * size_t(width) + size_t(x)) * 4];
  }
};

inline Film make_film(int width, int height) {
  return Film{width, height, std::vector<float>(size_t(width) * size_t(height) * 4, 0.0f)};
}

}  // namespace penumbra
