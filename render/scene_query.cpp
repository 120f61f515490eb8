// Spatial queries on a loaded scene; see scene_query.h.
#include "render/scene_query.h"

#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/interaction.h"

namespace penumbra {

int find_node(const GltfInfo& info, const std::string& spec, const std::string& file, std::string& error) {
  if (!spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos) {
    const long long i = spec.size() <= 9 ? std::stoll(spec) : -1;
    if (i >= 0 && i < info.node_count) return int(i);
    error = file + " has " + std::to_string(info.node_count) + " nodes (0 to " +
            std::to_string(info.node_count - 1) + ")";
    return -1;
  }
  int found = -1;
  for (size_t i = 0; i < info.node_names.size(); ++i) {
    if (info.node_names[i] != spec) continue;
    if (found >= 0) {
      error = "several nodes of " + file + " have this name (nodes " + std::to_string(found) + " and " +
              std::to_string(i) + "); give its index";
      return -1;
    }
    found = int(i);
  }
  if (found < 0) error = file + " has no node of that name";
  return found;
}

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
