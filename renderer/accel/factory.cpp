// The accelerator factory: the one place that maps a back-end name to a builder.
#include "renderer/accel/factory.h"

#include <algorithm>
#include <stdexcept>

#include "renderer/accel/brute.h"
#include "renderer/accel/embree.h"
#include "renderer/accel/instances.h"

namespace penumbra {

std::vector<std::string> accelerator_names() {
  return {"embree", "bvh", "kdtree", "grid", "octree", "brute"};
}

namespace {

[[noreturn]] void throw_unknown(std::string_view name) {
  std::string known;
  for (const auto& n : accelerator_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown accelerator '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace

std::unique_ptr<Accelerator> make_accelerator(std::string_view name, std::span<const GeometryView> meshes,
                                              const AccelConfig& config) {
  if (name == "embree") return make_embree_accelerator(meshes, config.embree);
  if (name == "bvh") return make_bvh_accelerator(meshes, config.bvh);
  if (name == "kdtree") return make_kdtree_accelerator(meshes, config.kdtree);
  if (name == "grid") return make_grid_accelerator(meshes, config.grid);
  if (name == "octree") return make_octree_accelerator(meshes, config.octree);
  if (name == "brute") return make_brute_accelerator(meshes);
  throw_unknown(name);
}

std::unique_ptr<Accelerator> make_accelerator(std::string_view name, std::span<const GeometryView> meshes,
                                              std::span<const InstanceView> instances,
                                              const AccelConfig& config) {
  validate_instances(instances, meshes.size());
  if (name == "embree") return make_embree_accelerator(meshes, instances, config.embree);
  // A flattened scene (every placement the identity) is one level: geom_id = instance index.
  if (std::all_of(instances.begin(), instances.end(),
                  [](const InstanceView& i) { return is_identity(i.to_world); })) {
    std::vector<GeometryView> views;
    views.reserve(instances.size());
    for (const auto& i : instances) views.push_back(meshes[i.mesh]);
    return make_accelerator(name, views, config);
  }
  const auto names = accelerator_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) throw_unknown(name);
  return make_two_level_accelerator(
      [&](std::span<const GeometryView> level) { return make_accelerator(name, level, config); }, meshes,
      instances);
}

}  // namespace penumbra
