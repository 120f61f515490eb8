// Parsing "key=value" accelerator parameters into AccelConfig.
#include "render/accel_params.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace penumbra {
namespace {

template <typename T>
T parse_value(std::string_view key, std::string_view text) {
  T v{};
  const char* end = text.data() + text.size();
  std::from_chars_result r;
  if constexpr (std::is_floating_point_v<T>) {
    r = std::from_chars(text.data(), end, v);
    if (r.ec == std::errc() && r.ptr == end && !std::isfinite(v)) r.ec = std::errc::invalid_argument;
  } else {
    r = std::from_chars(text.data(), end, v);
  }
  if (text.empty() || r.ec != std::errc() || r.ptr != end)
    throw std::invalid_argument("--accel-param " + std::string(key) + ": '" + std::string(text) +
                                "' is not a valid " +
                                (std::is_floating_point_v<T> ? "number" : "non-negative integer"));
  return v;
}

}  // namespace

std::vector<AccelParamInfo> accel_param_keys() {
  const AccelConfig d;
  auto num = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  return {
      {"embree.robust", d.embree.robust ? "1" : "0", "RTC_SCENE_FLAG_ROBUST, 0 or 1"},
      {"embree.quality", std::to_string(d.embree.quality), "build quality: 0 low, 1 medium, 2 high"},
      {"bvh.width", std::to_string(d.bvh.width),
       "node width: 0 (the CPU's widest), 8 (AVX2), 4 (SSE) or 2 (binary)"},
      {"bvh.max_leaf_size", std::to_string(d.bvh.max_leaf_size), "largest leaf, [1, 255]"},
      {"bvh.bin_count", std::to_string(d.bvh.bin_count), "SAH bins per axis, [2, 256]"},
      {"bvh.traversal_cost", num(d.bvh.traversal_cost), "SAH cost of a node visit, > 0"},
      {"bvh.intersection_cost", num(d.bvh.intersection_cost), "SAH cost of a triangle test, > 0"},
      {"bvh.spatial_alpha", num(d.bvh.spatial_alpha),
       "spatial splits where object-split children overlap by more than this fraction of the root's area, "
       "[0, 1] (0: off)"},
      {"bvh.spatial_budget", num(d.bvh.spatial_budget),
       "references spatial splits may add, per triangle, [0, 4]"},
      {"bvh.refit_max_growth", num(d.bvh.refit_max_growth),
       "--frames: refit while the SAH cost is within this factor of the last build's, 0 or [1, 1000]; 0 = "
       "always rebuild"},
      {"kdtree.traversal_cost", num(d.kdtree.traversal_cost), "K_T, > 0"},
      {"kdtree.intersection_cost", num(d.kdtree.intersection_cost), "K_I, > 0"},
      {"kdtree.empty_bonus", num(d.kdtree.empty_bonus), "cost reduction for an empty side, [0, 1)"},
      {"kdtree.max_depth", std::to_string(d.kdtree.max_depth), "[0, 64]; 0 = 8 + 1.3 log2 N"},
      {"octree.max_leaf_prims", std::to_string(d.octree.max_leaf_prims),
       "a node with more primitives is subdivided, [1, 1024]"},
      {"octree.max_depth", std::to_string(d.octree.max_depth), "depth limit (root = 0), [1, 20]"},
      {"octree.reference_budget", num(d.octree.reference_budget),
       "extra references splits may add, x the primitive count, [0, 64]"},
      {"bsp.traversal_cost", num(d.bsp.traversal_cost), "K_T, > 0"},
      {"bsp.intersection_cost", num(d.bsp.intersection_cost), "K_I, > 0"},
      {"bsp.empty_bonus", num(d.bsp.empty_bonus), "cost reduction for an empty side, [0, 1)"},
      {"bsp.max_depth", std::to_string(d.bsp.max_depth), "[0, 64]; 0 = 8 + 1.3 log2 N"},
      {"bsp.bins", std::to_string(d.bsp.bins), "positions per direction, [2, 64]"},
      {"bsp.triangle_planes", std::to_string(d.bsp.triangle_planes),
       "directions from the node's largest triangles, [0, 16]"},
      {"bsp.fixed_directions", d.bsp.fixed_directions ? "1" : "0",
       "1: the 10 diagonal directions are candidates; 0: axes and triangle planes only"},
      {"grid.lambda", num(d.grid.lambda), "cells per triangle of the finest grids, (0, 64]"},
      {"grid.coarse_lambda", num(d.grid.coarse_lambda),
       "cells per triangle of grids with sub-grids, (0, 64]"},
      {"grid.max_resolution", std::to_string(d.grid.max_resolution), "cells along one axis, [1, 4096]"},
      {"grid.max_cells", std::to_string(d.grid.max_cells), "cells of one grid or sub-grid, [1, 2^30]"},
      {"grid.max_depth", std::to_string(d.grid.max_depth), "grid levels, [1, 4]; 1 = flat uniform grid"},
      {"grid.split_threshold", std::to_string(d.grid.split_threshold),
       "a cell with more triangles gets a sub-grid, [1, 2^20]"},
  };
}

void apply_accel_param(AccelConfig& c, std::string_view kv) {
  const size_t eq = kv.find('=');
  if (eq == std::string_view::npos)
    throw std::invalid_argument("--accel-param: expected key=value, got '" + std::string(kv) + "'");
  const std::string_view key = kv.substr(0, eq), value = kv.substr(eq + 1);
  if (key == "embree.robust") {
    const int v = parse_value<int>(key, value);
    if (v != 0 && v != 1)
      throw std::invalid_argument("--accel-param embree.robust: must be 0 or 1, got '" + std::string(value) +
                                  "'");
    c.embree.robust = v == 1;
  } else if (key == "embree.quality")
    c.embree.quality = parse_value<int>(key, value);
  else if (key == "bvh.width")
    c.bvh.width = parse_value<int>(key, value);
  else if (key == "bvh.max_leaf_size")
    c.bvh.max_leaf_size = parse_value<int>(key, value);
  else if (key == "bvh.bin_count")
    c.bvh.bin_count = parse_value<int>(key, value);
  else if (key == "bvh.traversal_cost")
    c.bvh.traversal_cost = parse_value<float>(key, value);
  else if (key == "bvh.intersection_cost")
    c.bvh.intersection_cost = parse_value<float>(key, value);
  else if (key == "bvh.spatial_alpha")
    c.bvh.spatial_alpha = parse_value<float>(key, value);
  else if (key == "bvh.spatial_budget")
    c.bvh.spatial_budget = parse_value<float>(key, value);
  else if (key == "bvh.refit_max_growth")
    c.bvh.refit_max_growth = parse_value<float>(key, value);
  else if (key == "kdtree.traversal_cost")
    c.kdtree.traversal_cost = parse_value<float>(key, value);
  else if (key == "kdtree.intersection_cost")
    c.kdtree.intersection_cost = parse_value<float>(key, value);
  else if (key == "kdtree.empty_bonus")
    c.kdtree.empty_bonus = parse_value<float>(key, value);
  else if (key == "kdtree.max_depth")
    c.kdtree.max_depth = parse_value<int>(key, value);
  else if (key == "octree.max_leaf_prims")
    c.octree.max_leaf_prims = parse_value<int>(key, value);
  else if (key == "octree.max_depth")
    c.octree.max_depth = parse_value<int>(key, value);
  else if (key == "octree.reference_budget")
    c.octree.reference_budget = parse_value<float>(key, value);
  else if (key == "bsp.traversal_cost")
    c.bsp.traversal_cost = parse_value<float>(key, value);
  else if (key == "bsp.intersection_cost")
    c.bsp.intersection_cost = parse_value<float>(key, value);
  else if (key == "bsp.empty_bonus")
    c.bsp.empty_bonus = parse_value<float>(key, value);
  else if (key == "bsp.max_depth")
    c.bsp.max_depth = parse_value<int>(key, value);
  else if (key == "bsp.bins")
    c.bsp.bins = parse_value<int>(key, value);
  else if (key == "bsp.triangle_planes")
    c.bsp.triangle_planes = parse_value<int>(key, value);
  else if (key == "bsp.fixed_directions") {
    const int v = parse_value<int>(key, value);
    if (v != 0 && v != 1)
      throw std::invalid_argument("--accel-param bsp.fixed_directions: must be 0 or 1, got '" +
                                  std::string(value) + "'");
    c.bsp.fixed_directions = v == 1;
  } else if (key == "grid.lambda")
    c.grid.lambda = parse_value<float>(key, value);
  else if (key == "grid.coarse_lambda")
    c.grid.coarse_lambda = parse_value<float>(key, value);
  else if (key == "grid.max_resolution")
    c.grid.max_resolution = parse_value<uint32_t>(key, value);
  else if (key == "grid.max_cells")
    c.grid.max_cells = parse_value<uint64_t>(key, value);
  else if (key == "grid.max_depth")
    c.grid.max_depth = parse_value<uint32_t>(key, value);
  else if (key == "grid.split_threshold")
    c.grid.split_threshold = parse_value<uint32_t>(key, value);
  else {
    std::string known;
    for (const auto& k : accel_param_keys()) known += (known.empty() ? "" : ", ") + k.key;
    throw std::invalid_argument("--accel-param: unknown key '" + std::string(key) + "' (known: " + known +
                                ")");
  }
}

}  // namespace penumbra

namespace penumbra {

void validate(const AccelConfig& config) {
  validate(config.embree);
  validate(config.bvh);
  validate(config.kdtree);
  validate(config.grid);
  validate(config.octree);
  validate(config.bsp);
}

AccelConfig accel_config(const std::string& name, const std::vector<std::string>& params) {
  const std::vector<std::string> names = accelerator_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("accel: unknown value '" + name + "' (known: " + known + ")");
  }
  AccelConfig config;
  for (const auto& p : params) {
    apply_accel_param(config, p);
    const std::string prefix = p.substr(0, p.find('.'));
    if (prefix != name)
      throw std::invalid_argument("accel_params " + p + ": a parameter of '" + prefix + "', but accel is '" +
                                  name + "'");
  }
  validate(config);
  return config;
}

std::string accelerator_list() {
  const std::vector<std::string> names = accelerator_names();
  std::string list;
  for (size_t i = 0; i < names.size(); ++i)
    list += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return list;
}

}  // namespace penumbra
