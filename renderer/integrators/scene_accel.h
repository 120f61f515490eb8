// The accelerator the integrators query: the scene's meshes, shapes and instances handed to the
// accelerator factory as plain geometry views (geom_id in hits == instance index), and beside it,
// when the scene has Gaussian splats, a structure of the same back end over their proxies (one
// view of Splat shapes per cloud, placed by the splat instances). The scene itself stays plain
// data; this is where it meets accel/.
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

/// The splats of a scene as geometry: per cloud its Splat shapes (splat_shape, prim_id = splat
/// index) in a CurveKind::Shapes view, and per splat instance its placement (geom_id = index
/// into Scene::splat_instances). The views point into `shapes`.
struct SplatGeometry {
  std::vector<std::vector<Shape>> shapes;
  std::vector<GeometryView> views;
  std::vector<InstanceView> instances;
};
SplatGeometry splat_geometry(const Scene& scene);

/// make_accelerator(name, mesh_views(scene), instance_views(scene), config): the structure
/// every integrator queries (geom_id = instance index). With splats in the scene it also holds
/// make_accelerator(name, splat geometry) (splat_accelerator); its own queries answer for the
/// surfaces alone. The scene must outlive it. Throws as make_accelerator does.
std::unique_ptr<Accelerator> make_scene_accelerator(std::string_view name, const Scene& scene,
                                                    const AccelConfig& config = {});

/// The splat structure of an accelerator from make_scene_accelerator, or null (no splats).
const Accelerator* splat_accelerator(const Accelerator& accel);

/// refit_or_rebuild(accel, built_sah, name, mesh_views(scene), instance_views(scene), config):
/// the structure of an earlier pose of `scene` refitted to this one, or built anew; the splats'
/// structure is built anew over the scene's splats as they are.
RefitReport refit_or_rebuild_scene(std::unique_ptr<Accelerator>& accel, double& built_sah,
                                   std::string_view name, const Scene& scene, const AccelConfig& config = {});

}  // namespace penumbra
