// The accelerator the integrators query: the scene's meshes, shapes and instances handed to the
// accelerator factory as plain geometry views (geom_id in hits == instance index). The scene
// itself stays plain data; this is where it meets accel/.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "renderer/accel/factory.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// Views of every mesh, then every shape (view index = meshes.size() + shape index), and of every
/// instance for make_accelerator(name, views, instances); they point into the scene, which must
/// outlive them.
std::vector<GeometryView> mesh_views(const Scene& scene);
std::vector<InstanceView> instance_views(const Scene& scene);

/// make_accelerator(name, mesh_views(scene), instance_views(scene), config): the structure
/// every integrator queries (geom_id = instance index). The scene must outlive it. Throws as
/// make_accelerator does.
std::unique_ptr<Accelerator> make_scene_accelerator(std::string_view name, const Scene& scene,
                                                    const AccelConfig& config = {});

/// refit_or_rebuild(accel, built_sah, name, mesh_views(scene), instance_views(scene), config):
/// the structure of an earlier pose of `scene` refitted to this one, or built anew.
RefitReport refit_or_rebuild_scene(std::unique_ptr<Accelerator>& accel, double& built_sah,
                                   std::string_view name, const Scene& scene, const AccelConfig& config = {});

}  // namespace penumbra
