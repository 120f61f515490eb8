// Denoising a render in memory.
#include "render/denoise_render.h"

#include <stdexcept>
#include <string>

namespace penumbra {

DenoiseConfig denoise_config(const RenderConfig& config) {
  DenoiseConfig c;
  c.threads = config.threads;
  return c;
}

DenoiseInput denoise_input(const RenderImage& image, const DataAovs& data) {
  const size_t n = size_t(image.film.width) * size_t(image.film.height);
  if (image.halves.size() != n * kHalfChannels)
    throw std::invalid_argument("denoise: the render has no colour halves (render with the 'halves' layer)");
  if (data.halves.size() != n * 2 * kDenoiseFeatures)
    throw std::invalid_argument("denoise: the render has no feature halves (render with the 'halves' layer)");
  DenoiseInput in;
  in.width = image.film.width;
  in.height = image.film.height;
  for (int h = 0; h < 2; ++h) {
    in.color[h].resize(n * 3);
    in.features[h].resize(n * kDenoiseFeatures);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c)
        in.color[h][i * 3 + size_t(c)] = image.halves[i * kHalfChannels + size_t(h * 3 + c)];
      for (int k = 0; k < kDenoiseFeatures; ++k)
        in.features[h][i * kDenoiseFeatures + size_t(k)] =
            data.halves[(i * 2 + size_t(h)) * kDenoiseFeatures + size_t(k)];
    }
  }
  return in;
}

Film with_colour(const Film& film, const std::vector<float>& rgb) {
  Film out = film;
  const size_t n = size_t(film.width) * size_t(film.height);
  for (size_t i = 0; i < n && i * 3 + 2 < rgb.size(); ++i)
    for (int c = 0; c < 3; ++c) out.rgba[i * 4 + size_t(c)] = rgb[i * 3 + size_t(c)];
  return out;
}

Film denoise_render(const RenderImage& image, const DataAovs& data, const RenderConfig& config,
                    const std::function<void(int, int)>& progress) {
  const DenoiseInput in = denoise_input(image, data);
  return with_colour(image.film, denoise_nfor(in, denoise_config(config), progress));
}

}  // namespace penumbra
