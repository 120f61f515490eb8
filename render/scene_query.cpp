// Spatial queries on a loaded scene; see scene_query.h.
#include "render/scene_query.h"

#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/interaction.h"

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

const Accelerator& query_structure(Session& session, const RenderSpec& spec) {
  const bool world_apart = session.loaded.info.animation_count != 0 && session.loaded_at_time;
  session.structure = build_structure(session.loaded.scene, spec, world_apart, std::move(session.structure));
  return *session.structure.accel;
}

Pick pick(const Scene& scene, const Accelerator& accel, const Camera& camera, int width, int height, int x,
          int y) {
  Pick p;
  p.ray = generate_camera_ray(camera, width, height, float(x) + 0.5f, float(y) + 0.5f);
  Hit hit;
  if (!intersect_visible(scene, accel, p.ray, hit, scene_needs_hit_filter(scene))) return p;
  const SurfaceInteraction si = make_interaction(scene, p.ray, hit);
  p.hit = true;
  p.match.distance = hit.t;
  p.match.point = si.p;
  p.match.u = hit.u;
  p.match.v = hit.v;
  p.match.geom_id = hit.geom_id;
  p.match.prim_id = hit.prim_id;
  p.owner = match_owner(scene, hit.geom_id);
  p.depth = dot(si.p - camera.eye, -camera.w);
  p.normal = si.ng;
  return p;
}

}  // namespace penumbra
