// Tests for renderer/integrators/render_config: validate() accepts the defaults and every
// documented bound, refuses each setting just outside its range with a message naming it, and
// render_window() clamps.
#include "renderer/integrators/render_config.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

using namespace penumbra;

namespace {
// The message of validate(c), or "" if it passes.
std::string failure(const RenderConfig& c) {
  try {
    validate(c);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}
RenderConfig with(const std::function<void(RenderConfig&)>& f) {
  RenderConfig c;
  f(c);
  return c;
}
}  // namespace

TEST_CASE("validate: defaults and the documented bounds pass", "[render][quick]") {
  CHECK(failure(RenderConfig{}).empty());
  CHECK(failure(with([](RenderConfig& c) {
          c.width = c.height = kMaxImageSize;
          c.spp = kMaxSpp;
          c.threads = kMaxThreads;
          c.tile_size = 1;
          c.filter.width = kMaxFilterWidth;
          c.whitted.max_depth = 0;
          c.path.max_depth = kMaxDepth;
          c.path.rr_depth = 1;
          c.adaptive_min_spp = 2;
          c.window = {0, 0, kMaxImageSize, 1};
        })).empty());
  CHECK(failure(with([](RenderConfig& c) {
          c.width = c.height = 1;
          c.window = {0, 0, 1, 1};
        })).empty());
}

TEST_CASE("validate: each setting outside its range is refused by name", "[render][quick]") {
  const float nan = std::nanf("");
  const std::pair<const char*, std::function<void(RenderConfig&)>> cases[] = {
      {"width", [](RenderConfig& c) { c.width = 0; }},
      {"width", [](RenderConfig& c) { c.width = kMaxImageSize + 1; }},
      {"height", [](RenderConfig& c) { c.height = -3; }},
      {"spp", [](RenderConfig& c) { c.spp = 0; }},
      {"spp", [](RenderConfig& c) { c.spp = kMaxSpp + 1; }},
      {"threads", [](RenderConfig& c) { c.threads = -1; }},
      {"tile_size", [](RenderConfig& c) { c.tile_size = 0; }},
      {"filter width", [](RenderConfig& c) { c.filter.width = 0; }},
      {"filter width", [nan](RenderConfig& c) { c.filter.width = nan; }},
      {"filter width", [](RenderConfig& c) { c.filter.width = kMaxFilterWidth * 2; }},
      {"whitted.max_depth", [](RenderConfig& c) { c.whitted.max_depth = kMaxDepth + 1; }},
      {"whitted.min_reflectance", [](RenderConfig& c) { c.whitted.min_reflectance = -1; }},
      {"whitted.ambient", [nan](RenderConfig& c) { c.whitted.ambient.y = nan; }},
      {"whitted.background", [](RenderConfig& c) { c.whitted.background.z = kInfinity; }},
      {"whitted.max_blend_layers", [](RenderConfig& c) { c.whitted.max_blend_layers = -1; }},
      {"path.max_depth", [](RenderConfig& c) { c.path.max_depth = -1; }},
      {"path.rr_depth", [](RenderConfig& c) { c.path.rr_depth = 0; }},
      {"path.max_blend_layers", [](RenderConfig& c) { c.path.max_blend_layers = -2; }},
      {"path.clamp_indirect", [nan](RenderConfig& c) { c.path.clamp_indirect = nan; }},
      {"time_limit", [](RenderConfig& c) { c.time_limit = -0.5; }},
      {"adaptive_threshold", [](RenderConfig& c) { c.adaptive_threshold = -1e-3f; }},
      {"adaptive_min_spp", [](RenderConfig& c) { c.adaptive_min_spp = 1; }},
      {"window",
       [](RenderConfig& c) {
         c.window = {10, 10, 5, 20};
       }},
      {"window",
       [](RenderConfig& c) {
         c.window = {-1, 0, 10, 10};
       }},
      {"window",
       [](RenderConfig& c) {
         c.window = {0, 0, c.width + 1, 10};
       }},
      {"window",
       [](RenderConfig& c) {
         c.window = {0, 500, 10, c.height + 1};
       }},
  };
  for (const auto& [name, breaks] : cases) {
    const std::string message = failure(with(breaks));
    INFO(name << ": " << message);
    CHECK(message.find(name) != std::string::npos);
  }
}

TEST_CASE("render_window: an empty window is the frame, others are clamped to it", "[render][quick]") {
  RenderConfig c;
  c.width = 40;
  c.height = 30;
  const PixelWindow whole = render_window(c);
  CHECK((whole.x0 == 0 && whole.y0 == 0 && whole.x1 == 40 && whole.y1 == 30));
  c.window = {30, 20, 50, 60};
  const PixelWindow clamped = render_window(c);
  CHECK((clamped.x0 == 30 && clamped.y0 == 20 && clamped.x1 == 40 && clamped.y1 == 30));
}
