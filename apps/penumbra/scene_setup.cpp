// Scene loading, camera choice and accelerator parameters for the subcommands.
#include "apps/penumbra/scene_setup.h"

#include <algorithm>
#include <cstdio>

#include "apps/penumbra/cli_support.h"
#include "io/files/error.h"
#include "render/accel_params.h"
#include "render/scene_query.h"
#include "render/session.h"
#include "renderer/accel/embree.h"
#include "renderer/accel/factory.h"

namespace penumbra::cli {

LoadedScene load_scene(const std::string& file, int scene, bool allow_external, bool flatten,
                       uint64_t max_memory, bool quiet, std::optional<double> time, bool keep_animation,
                       const std::string& variant) {
  GltfLoadOptions opt;
  opt.variant = variant;
  opt.time = time;
  opt.keep_animation = keep_animation;
  opt.flatten = flatten;
  opt.scene = scene;
  opt.allow_external_uris = allow_external;
  opt.max_memory_bytes = max_memory;
  LoadedScene loaded = load_gltf(file, opt);
  if (!quiet) {
    const size_t shown = std::min<size_t>(loaded.warnings.size(), 20);
    for (size_t i = 0; i < shown; ++i)
      std::fprintf(stderr, "penumbra: warning: %s: %s\n", file.c_str(), loaded.warnings[i].c_str());
    if (loaded.warnings.size() > shown)
      std::fprintf(stderr, "penumbra: warning: %s: ... and %zu more warnings\n", file.c_str(),
                   loaded.warnings.size() - shown);
  }
  return loaded;
}

std::string describe_scene_size(const Scene& scene) {
  const std::string triangles = human_count(count_stored_triangles(scene)) + " triangles";
  if (scene.shapes.empty()) return triangles;
  return triangles + ", " + std::to_string(scene.shapes.size()) +
         (scene.shapes.size() == 1 ? " shape" : " shapes");
}

int find_gltf_node(const GltfInfo& info, const std::string& spec, const std::string& file) {
  std::string error;
  const int node = find_node(info, spec, file, error);
  if (node < 0) {
    const bool index = !spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos;
    throw UsageError("--node " + (index ? spec : "'" + spec + "'") + ": " + error);
  }
  return node;
}

int find_camera(const Scene& scene, const std::string& spec, const std::string& file) {
  return penumbra::find_camera(scene, spec, file, "--camera");
}

AccelConfig parse_accel(const std::string& name, const std::vector<std::string>& params) {
  bool known = false;
  std::string names;
  for (const auto& n : accelerator_names()) {
    known |= n == name;
    names += (names.empty() ? "" : ", ") + n;
  }
  if (!known) throw UsageError("--accel: unknown accelerator '" + name + "' (known: " + names + ")");
  AccelConfig config;
  for (const auto& p : params) {
    apply_accel_param(config, p);
    const std::string prefix = p.substr(0, p.find('.'));
    if (prefix != name)
      throw UsageError("--accel-param " + p + ": a parameter of '" + prefix + "', but --accel is '" + name +
                       "'");
  }
  validate(config);  // every structure's parameters, as every front end checks them
  return config;
}

std::string accel_param_help() {
  std::string h = "accelerator build parameter key=value (repeatable):";
  for (const auto& k : accel_param_keys())
    h += "\n  " + k.key + " (default " + k.default_value + "): " + k.description;
  return h;
}

}  // namespace penumbra::cli
