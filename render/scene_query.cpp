// Spatial queries on a loaded scene; see scene_query.h.
#include "render/scene_query.h"

#include "renderer/integrators/scene_accel.h"

namespace penumbra {

SceneGeometry scene_geometry(const Scene& scene) {
  return {mesh_views(scene), instance_views(scene)};
}

MatchOwner match_owner(const Scene& scene, uint32_t geom_id) {
  MatchOwner o;
  if (geom_id >= scene.instances.size()) return o;
  const Instance& inst = scene.instances[geom_id];
  o.instance = int(geom_id);
  o.node = inst.node;
  if (inst.shape >= 0) {
    o.shape = inst.shape;
    o.material = scene.shapes[size_t(inst.shape)].material;
  } else {
    o.mesh = inst.mesh;
    o.material = scene.meshes[size_t(inst.mesh)].material;
  }
  return o;
}

}  // namespace penumbra
