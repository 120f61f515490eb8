// Render settings validation and the render window.
#include "renderer/integrators/render_config.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace penumbra {

namespace {

void check_range(const char* name, long long value, long long lo, long long hi) {
  if (value < lo || value > hi)
    throw std::invalid_argument(std::string(name) + " = " + std::to_string(value) + " is outside [" +
                                std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

void check_non_negative(const char* name, double value) {
  if (!std::isfinite(value) || value < 0)
    throw std::invalid_argument(std::string(name) + " must be finite and >= 0 (got " + std::to_string(value) +
                                ")");
}

void check_non_negative(const char* name, Vec3f v) {
  for (int c = 0; c < 3; ++c) check_non_negative(name, double(v[c]));
}

}  // namespace

void validate(const RenderConfig& c) {
  check_range("width", c.width, 1, kMaxImageSize);
  check_range("height", c.height, 1, kMaxImageSize);
  check_range("spp", c.spp, 1, kMaxSpp);
  check_range("threads", c.threads, 0, kMaxThreads);
  check_range("tile_size", c.tile_size, 1, kMaxImageSize);
  if (!std::isfinite(c.filter.width) || !(c.filter.width > 0) || c.filter.width > kMaxFilterWidth)
    throw std::invalid_argument("filter width = " + std::to_string(c.filter.width) + " is outside (0, " +
                                std::to_string(int(kMaxFilterWidth)) + "] pixels");
  check_range("whitted.max_depth", c.whitted.max_depth, 0, kMaxDepth);
  check_range("whitted.max_blend_layers", c.whitted.max_blend_layers, 0, kMaxSpp);
  check_non_negative("whitted.min_reflectance", double(c.whitted.min_reflectance));
  check_non_negative("whitted.ambient", c.whitted.ambient);
  check_non_negative("whitted.background", c.whitted.background);
  check_range("raster.shadow_map_size", c.raster.shadow_map_size, 16, 8192);
  check_range("path.max_depth", c.path.max_depth, 0, kMaxDepth);
  check_range("path.rr_depth", c.path.rr_depth, 1, kMaxDepth);
  check_range("path.light_samples", c.path.light_samples, 1, 64);
  check_range("path.max_blend_layers", c.path.max_blend_layers, 0, kMaxSpp);
  check_non_negative("path.clamp_indirect", double(c.path.clamp_indirect));
  check_non_negative("time_limit", c.time_limit);
  check_non_negative("adaptive_threshold", double(c.adaptive_threshold));
  check_range("adaptive_min_spp", c.adaptive_min_spp, 2, kMaxSpp);
  const PixelWindow& w = c.window;
  const bool whole_frame = w.x0 == 0 && w.y0 == 0 && w.x1 == 0 && w.y1 == 0;
  if (!whole_frame && (w.empty() || w.x0 < 0 || w.y0 < 0 || w.x1 > c.width || w.y1 > c.height))
    throw std::invalid_argument("window [" + std::to_string(w.x0) + ", " + std::to_string(w.x1) + ") x [" +
                                std::to_string(w.y0) + ", " + std::to_string(w.y1) +
                                ") is empty or outside the " + std::to_string(c.width) + " x " +
                                std::to_string(c.height) + " frame");
}

PixelWindow render_window(const RenderConfig& config) {
  PixelWindow w = config.window;
  if (w.empty()) return {0, 0, config.width, config.height};
  w.x0 = std::clamp(w.x0, 0, config.width);
  w.x1 = std::clamp(w.x1, 0, config.width);
  w.y0 = std::clamp(w.y0, 0, config.height);
  w.y1 = std::clamp(w.y1, 0, config.height);
  return w.empty() ? PixelWindow{0, 0, 0, 0} : w;
}

}  // namespace penumbra
