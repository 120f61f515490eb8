// Scene to accelerator views.
#include "renderer/integrators/scene_accel.h"

namespace penumbra {

std::vector<TriangleMeshView> mesh_views(const Scene& scene) {
  std::vector<TriangleMeshView> views;
  views.reserve(scene.meshes.size());
  for (const auto& m : scene.meshes) views.push_back({m.positions, m.indices});
  return views;
}

std::vector<InstanceView> instance_views(const Scene& scene) {
  std::vector<InstanceView> views;
  views.reserve(scene.instances.size());
  for (const Instance& inst : scene.instances) views.push_back({uint32_t(inst.mesh), inst.to_world});
  return views;
}

std::unique_ptr<Accelerator> make_scene_accelerator(std::string_view name, const Scene& scene,
                                                    const AccelConfig& config) {
  return make_accelerator(name, mesh_views(scene), instance_views(scene), config);
}

}  // namespace penumbra
