// Scene to accelerator views.
#include "renderer/integrators/scene_accel.h"

namespace penumbra {

std::vector<GeometryView> mesh_views(const Scene& scene) {
  std::vector<GeometryView> views;
  views.reserve(scene.meshes.size() + scene.shapes.size());
  for (const auto& m : scene.meshes) {
    views.push_back({m.positions, m.indices});
    if (renders_as_curves(m)) {
      views.back().curves = m.points ? CurveKind::Points : CurveKind::Segments;
      views.back().radii = m.radii;
    }
    if (m.motion_steps >= 2) {
      views.back().motion_positions = m.motion_positions;
      views.back().motion_steps = m.motion_steps;
    }
  }
  for (const auto& s : scene.shapes) views.push_back({{}, {}, &s.shape});
  return views;
}

std::vector<InstanceView> instance_views(const Scene& scene) {
  std::vector<InstanceView> views;
  views.reserve(scene.instances.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const size_t geometry = inst.shape >= 0 ? scene.meshes.size() + size_t(inst.shape) : size_t(inst.mesh);
    views.push_back({uint32_t(geometry), inst.to_world});
    if (i < scene.instance_motion.size()) views.back().motion = scene.instance_motion[i];
  }
  return views;
}

std::unique_ptr<Accelerator> make_scene_accelerator(std::string_view name, const Scene& scene,
                                                    const AccelConfig& config) {
  return make_accelerator(name, mesh_views(scene), instance_views(scene), config);
}

RefitReport refit_or_rebuild_scene(std::unique_ptr<Accelerator>& accel, double& built_sah,
                                   std::string_view name, const Scene& scene, const AccelConfig& config) {
  return refit_or_rebuild(accel, built_sah, name, mesh_views(scene), instance_views(scene), config);
}

}  // namespace penumbra
