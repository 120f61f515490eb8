// The accelerator factory: the one place that maps a back-end name to a builder.
#include "renderer/accel/factory.h"

#include <algorithm>
#include <stdexcept>

#include "renderer/accel/brute.h"
#include "renderer/accel/embree.h"
#include "renderer/accel/instances.h"
#include "renderer/accel/stats.h"

namespace penumbra {

std::vector<std::string> accelerator_names() {
  return {"embree", "bvh", "kdtree", "grid", "octree", "bsp", "brute"};
}

namespace {

[[noreturn]] void throw_unknown(std::string_view name) {
  std::string known;
  for (const auto& n : accelerator_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown accelerator '" + std::string(name) + "' (known: " + known + ")");
}

}  // namespace

namespace {

bool any_deforms(std::span<const GeometryView> meshes) {
  return std::any_of(meshes.begin(), meshes.end(), [](const GeometryView& m) { return m.deforms(); });
}

/// One identity placement per view, in order (a single-level build's views as instances).
std::vector<InstanceView> identity_instances(size_t count) {
  std::vector<InstanceView> instances(count);
  for (size_t i = 0; i < count; ++i) instances[i].mesh = uint32_t(i);
  return instances;
}

}  // namespace

std::unique_ptr<Accelerator> make_accelerator(std::string_view name, std::span<const GeometryView> meshes,
                                              const AccelConfig& config) {
  // The own back ends place deforming meshes in their time-aware structures under a top level.
  if (name != "embree" && any_deforms(meshes))
    return make_accelerator(name, meshes, identity_instances(meshes.size()), config);
  if (name == "embree") return make_embree_accelerator(meshes, config.embree);
  if (name == "bvh") return make_bvh_accelerator(meshes, config.bvh);
  if (name == "kdtree") return make_kdtree_accelerator(meshes, config.kdtree);
  if (name == "grid") return make_grid_accelerator(meshes, config.grid);
  if (name == "octree") return make_octree_accelerator(meshes, config.octree);
  if (name == "bsp") return make_bsp_accelerator(meshes, config.bsp);
  if (name == "brute") return make_brute_accelerator(meshes);
  throw_unknown(name);
}

namespace {

/// Whether the build is one level: every placement the identity and no mesh deforming.
bool all_identity(std::span<const GeometryView> meshes, std::span<const InstanceView> instances) {
  return std::all_of(instances.begin(), instances.end(), [&](const InstanceView& i) {
    return i.motion.empty() && is_identity(i.to_world) && !meshes[i.mesh].deforms();
  });
}

/// The views of a flattened scene: each instance's mesh, in instance order.
std::vector<GeometryView> flattened_views(std::span<const GeometryView> meshes,
                                          std::span<const InstanceView> instances) {
  std::vector<GeometryView> views;
  views.reserve(instances.size());
  for (const auto& i : instances) views.push_back(meshes[i.mesh]);
  return views;
}

}  // namespace

std::unique_ptr<Accelerator> make_accelerator(std::string_view name, std::span<const GeometryView> meshes,
                                              std::span<const InstanceView> instances,
                                              const AccelConfig& config) {
  validate_instances(instances, meshes.size());
  if (name == "embree") return make_embree_accelerator(meshes, instances, config.embree);
  // A flattened scene (every placement the identity) is one level: geom_id = instance index.
  if (all_identity(meshes, instances))
    return make_accelerator(name, flattened_views(meshes, instances), config);
  const auto names = accelerator_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) throw_unknown(name);
  DeformingConfig deforming;
  deforming.exhaustive = name == "brute";  // brute force tests every interpolated triangle
  return make_two_level_accelerator(
      [&](std::span<const GeometryView> level) { return make_accelerator(name, level, config); }, meshes,
      instances, deforming);
}

RefitReport refit_or_rebuild(std::unique_ptr<Accelerator>& accel, double& built_sah, std::string_view name,
                             std::span<const GeometryView> meshes, std::span<const InstanceView> instances,
                             const AccelConfig& config) {
  RefitReport report;
  validate_instances(instances, meshes.size());
  if (name != "bvh")
    report.reason = "the " + std::string(name) + " back end does not refit";
  else if (config.bvh.refit_max_growth == 0)
    report.reason = "refitting is off (bvh.refit_max_growth=0)";
  else if (any_deforms(meshes))
    report.reason = "deforming meshes are rebuilt";
  else if (!accel || !(all_identity(meshes, instances) ? accel->refit(flattened_views(meshes, instances))
                                                       : accel->refit_instances(meshes, instances)))
    report.reason = "the geometry's layout changed";
  if (report.reason.empty()) {
    const double sah = accel->stats().sah_cost;
    report.growth = built_sah > 0 ? sah / built_sah : 1.0;
    if (report.growth <= config.bvh.refit_max_growth) {
      report.refitted = true;
      return report;
    }
    report.reason = "its SAH cost grew " + format_number(report.growth) + "x, past bvh.refit_max_growth " +
                    format_number(config.bvh.refit_max_growth);
  }
  accel.reset();  // the old structure's memory is freed before the new one is built
  accel = make_accelerator(name, meshes, instances, config);
  built_sah = accel->stats().sah_cost;
  return report;
}

}  // namespace penumbra
