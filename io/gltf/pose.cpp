// Posing a loaded scene at another time: every channel sampled again, the moving nodes' world
// transforms and instancing placements recomputed and checked as the loader checks them, then
// the instances, cameras and lights updated together.
#include "io/gltf/pose.h"

#include <map>
#include <stdexcept>
#include <utility>

#include "io/gltf/animation.h"
#include "io/gltf/meshes.h"

namespace penumbra {

namespace gltf {

std::shared_ptr<GltfAnimation> describe_animation(const GltfContext& ctx, const NodeTransforms& nodes,
                                                  const NodeUses& uses) {
  auto out = std::make_shared<GltfAnimation>();
  out->file = ctx.file;
  out->options = ctx.options;
  out->parent = nodes.parent;
  out->moving = nodes.moving;
  out->cameras = uses.cameras;
  out->lights = uses.lights;
  bool rigid = nodes.moving_skipped == 0;
  for (const auto& anim : ctx.model.animations)
    for (const auto& ch : anim.channels)
      rigid = rigid && !(ch.target_node >= 0 && ch.target_path == "weights") && ch.target_path != "pointer";
  for (const MeshUse& use : uses.meshes) {
    const auto& node = ctx.model.nodes[size_t(use.node)];
    rigid = rigid && node.skin < 0 && !(ctx.options.flatten && is_moving(nodes, use.node));
  }
  out->rigid = rigid;
  return out;
}

namespace {

// The bounds of mesh `mesh`'s positions, computed once per pose.
Bounds3f mesh_bounds(const Scene& scene, int mesh, std::map<int, Bounds3f>& cache) {
  auto [it, fresh] = cache.try_emplace(mesh);
  if (fresh)
    for (Vec3f p : scene.meshes[size_t(mesh)].positions) it->second = merge(it->second, p);
  return it->second;
}

// The instance `old` placed by `to_world` (its kind, node and copy kept, never the identity);
// false where the loader would leave the placement out: singular, non-finite or huge.
bool moved_instance(const Scene& scene, const Instance& old, const Transform& to_world,
                    std::map<int, Bounds3f>& bounds, Instance& out) {
  const Affine3f map = to_affine(to_world);
  try {
    out = old.shape >= 0 ? make_shape_instance(old.shape, map, old.node)
                         : make_instance(old.mesh, map, old.node);
  } catch (const std::invalid_argument&) {
    return false;
  }
  out.copy = old.copy;
  out.identity = false;
  const Bounds3f object = old.shape >= 0 ? shape_bounds(scene.shapes[size_t(old.shape)].shape)
                                         : mesh_bounds(scene, old.mesh, bounds);
  if (object.empty()) return true;
  const Bounds3f w = transform_bounds(out.to_world, object);
  return is_finite(w.lo) && is_finite(w.hi) &&
         std::max(max_component(abs(w.lo)), max_component(abs(w.hi))) <= 1e18f;
}

}  // namespace

}  // namespace gltf

bool pose_gltf_scene(const GltfAnimation& animation, double time, Scene& scene, uint64_t* moved_instances) {
  using namespace gltf;
  if (!animation.rigid || scene.cameras.size() != animation.cameras.size() ||
      scene.lights.size() != animation.lights.size())
    return false;
  // A context over the kept model; the warnings it gives were given at the load.
  MemoryBudget budget(animation.file, animation.options.max_memory_bytes);
  LoadedScene scratch;
  const GltfContext ctx{animation.model, animation.file, animation.options, budget, scratch};
  const std::vector<NodePose> poses = evaluate_animations(ctx, time);
  NodeTransforms nodes;
  nodes.parent = animation.parent;
  nodes.world.assign(animation.parent.size(), Transform{});
  nodes.known.assign(animation.parent.size(), 0);
  nodes.poses = &poses;
  nodes.moving = animation.moving;

  // Splat clouds placed by a moving node: loaded anew (their structure is built with the scene).
  for (const SplatInstance& si : scene.splat_instances)
    if (is_moving(nodes, si.node)) return false;
  // The moving nodes' instances at `time`, checked before anything changes.
  std::map<int, std::vector<Transform>> placements;  // moving node -> its placements at `time`
  std::map<int, Bounds3f> bounds;
  std::vector<std::pair<size_t, Instance>> moved;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& old = scene.instances[i];
    if (!is_moving(nodes, old.node)) continue;
    auto [it, fresh] = placements.try_emplace(old.node);
    if (fresh) it->second = placements_of(ctx, old.node, world_transform(ctx, nodes, old.node));
    const size_t k = old.copy >= 0 ? size_t(old.copy) : 0;
    if (k >= it->second.size()) return false;
    Instance inst;
    if (!moved_instance(scene, old, it->second[k], bounds, inst)) return false;
    moved.emplace_back(i, inst);
  }
  std::vector<Camera> cameras = scene.cameras;
  for (size_t k = 0; k < cameras.size(); ++k)
    place_camera(ctx, animation.cameras[k], world_transform(ctx, nodes, animation.cameras[k]), cameras[k]);
  std::vector<Light> lights = scene.lights;
  for (size_t k = 0; k < lights.size(); ++k)
    place_light(ctx, animation.lights[k], world_transform(ctx, nodes, animation.lights[k]), lights[k]);

  for (auto& [i, inst] : moved) scene.instances[i] = inst;
  scene.cameras = std::move(cameras);
  scene.lights = std::move(lights);
  if (moved_instances) *moved_instances = moved.size();
  return true;
}

}  // namespace penumbra
