// Nodes: local and world transforms, the hierarchy's checks, the scene's roots and its
// depth-first walk, and the cameras and punctual lights the walk places.
#include "io/gltf/nodes.h"

#include <tiny_gltf.h>

#include <cmath>
#include <set>

#include "io/gltf/shapes.h"

namespace penumbra::gltf {

namespace {

// The node's TRS (or matrix), animated channels overriding the static TRS.
Transform local_transform(const GltfContext& ctx, const NodeTransforms& nodes, int node) {
  const auto& n = ctx.model.nodes[size_t(node)];
  const std::string where = idx("nodes", size_t(node));
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16) ctx.fail(where + ".matrix", "must have 16 values");
    Transform t = from_column_major(n.matrix.data());
    if (!is_finite(t)) ctx.fail(where + ".matrix", "contains NaN or infinite values");
    return t;
  }
  std::array<double, 3> tr{0, 0, 0}, sc{1, 1, 1};
  Quat q;
  if (!n.translation.empty()) {
    if (n.translation.size() != 3) ctx.fail(where + ".translation", "must have 3 values");
    std::copy(n.translation.begin(), n.translation.end(), tr.begin());
  }
  if (!n.scale.empty()) {
    if (n.scale.size() != 3) ctx.fail(where + ".scale", "must have 3 values");
    std::copy(n.scale.begin(), n.scale.end(), sc.begin());
  }
  if (!n.rotation.empty()) {
    if (n.rotation.size() != 4) ctx.fail(where + ".rotation", "must have 4 values");
    q = {n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]};
    const double len = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (!std::isfinite(len) || len < 1e-6)
      ctx.fail(where + ".rotation", "is not a unit quaternion (length " + std::to_string(len) + ")");
    if (std::fabs(len - 1) > 1e-3)
      ctx.warn(where + ".rotation",
               "quaternion not normalised (length " + std::to_string(len) + "); normalising");
  }
  if (size_t(node) < nodes.poses->size()) {
    const NodePose& pose = (*nodes.poses)[size_t(node)];
    if (pose.has_t) tr = pose.t;
    if (pose.has_r) q = pose.r;
    if (pose.has_s) sc = pose.s;
  }
  for (double v : tr)
    if (!std::isfinite(v)) ctx.fail(where + ".translation", "contains NaN or infinite values");
  for (double v : sc)
    if (!std::isfinite(v)) ctx.fail(where + ".scale", "contains NaN or infinite values");
  return compose_trs(tr, q, sc);
}

void add_camera(const GltfContext& ctx, int camera_index, int node, const Transform& world) {
  const std::string node_where = idx("nodes", size_t(node));
  if (camera_index < 0 || size_t(camera_index) >= ctx.model.cameras.size())
    ctx.fail(node_where + ".camera", "camera index " + std::to_string(camera_index) + " out of range (" +
                                         std::to_string(ctx.model.cameras.size()) + " cameras)");
  const auto& src = ctx.model.cameras[size_t(camera_index)];
  Camera cam;
  cam.name = src.name.empty() ? idx("cameras", size_t(camera_index)) : src.name;
  place_camera(ctx, node, world, cam);
  if (src.type == "perspective") {
    cam.projection = Projection::Perspective;
    cam.yfov = float(src.perspective.yfov);
    cam.aspect = float(src.perspective.aspectRatio);
    cam.znear = float(src.perspective.znear);
    cam.zfar = src.perspective.zfar > 0 ? float(src.perspective.zfar) : kInfinity;
  } else {
    cam.projection = Projection::Orthographic;
    cam.xmag = float(src.orthographic.xmag);
    cam.ymag = float(src.orthographic.ymag);
    cam.aspect = cam.xmag / cam.ymag;
    cam.znear = float(src.orthographic.znear);
    cam.zfar = float(src.orthographic.zfar);
  }
  ctx.out.scene.cameras.push_back(cam);
  const std::string& node_name = ctx.model.nodes[size_t(node)].name;
  ctx.out.info.camera_instances.push_back(cam.name + " (" + src.type + ", " + node_where +
                                          (node_name.empty() ? "" : " '" + node_name + "'") + ")");
}

void add_light(const GltfContext& ctx, int light_index, int node, const Transform& world) {
  const std::string node_where = idx("nodes", size_t(node));
  if (light_index < 0 || size_t(light_index) >= ctx.model.lights.size())
    ctx.fail(node_where + ".extensions.KHR_lights_punctual.light",
             "light index " + std::to_string(light_index) + " out of range (" +
                 std::to_string(ctx.model.lights.size()) + " lights)");
  const auto& src = ctx.model.lights[size_t(light_index)];
  Light l;
  l.name = src.name.empty() ? "lights[" + std::to_string(light_index) + "]" : src.name;
  l.type = src.type == "point" ? LightType::Point
                               : (src.type == "spot" ? LightType::Spot : LightType::Directional);
  if (src.color.size() == 3) l.color = {float(src.color[0]), float(src.color[1]), float(src.color[2])};
  l.intensity = float(src.intensity);
  l.range = src.range > 0 ? float(src.range) : kInfinity;
  l.inner_cone = float(src.spot.innerConeAngle);
  l.outer_cone = float(src.spot.outerConeAngle);
  place_light(ctx, node, world, l);
  ctx.out.scene.lights.push_back(l);
}

}  // namespace

void place_camera(const GltfContext& ctx, int node, const Transform& world, Camera& cam) {
  cam.eye = transform_point(world, {0, 0, 0});
  // Orthonormalise the node's axes (scale is not part of a camera placement).
  const Vec3f w = normalize(transform_vector(world, {0, 0, 1}));
  Vec3f u = transform_vector(world, {1, 0, 0});
  u = normalize(u - w * dot(u, w));
  if (!(dot(w, w) > 0) || !(dot(u, u) > 0) || !is_finite(cam.eye))
    ctx.fail(idx("nodes", size_t(node)), "camera transform is singular");
  cam.w = w;
  cam.u = u;
  cam.v = cross(w, u);
}

void place_light(const GltfContext& ctx, int node, const Transform& world, Light& light) {
  light.position = transform_point(world, {0, 0, 0});
  light.direction = normalize(transform_vector(world, {0, 0, -1}));
  if (light.type != LightType::Point && !(dot(light.direction, light.direction) > 0))
    ctx.fail(idx("nodes", size_t(node)), "light transform is singular");
}

void mark_moving_nodes(const GltfContext& ctx, NodeTransforms& nodes) {
  const size_t n = ctx.model.nodes.size();
  std::vector<uint8_t> target(n, 0);
  for (const auto& anim : ctx.model.animations)
    for (const auto& ch : anim.channels)
      if (ch.target_node >= 0 && size_t(ch.target_node) < n &&
          (ch.target_path == "translation" || ch.target_path == "rotation" || ch.target_path == "scale"))
        target[size_t(ch.target_node)] = 1;
  // Each node once: up the parent chain (acyclic, link_nodes) to a known node, then down.
  nodes.moving.assign(n, 0);
  std::vector<uint8_t> known(n, 0);
  std::vector<int> chain;
  for (size_t i = 0; i < n; ++i) {
    chain.clear();
    for (int cur = int(i); cur >= 0 && !known[size_t(cur)]; cur = nodes.parent[size_t(cur)])
      chain.push_back(cur);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int p = nodes.parent[size_t(*it)];
      nodes.moving[size_t(*it)] = target[size_t(*it)] || (p >= 0 && nodes.moving[size_t(p)]);
      known[size_t(*it)] = 1;
    }
  }
}

void validate_cameras(const GltfContext& ctx) {
  for (size_t i = 0; i < ctx.model.cameras.size(); ++i) {
    const auto& c = ctx.model.cameras[i];
    const std::string where = idx("cameras", i) + (c.name.empty() ? "" : " '" + c.name + "'");
    auto positive = [&](double v, const char* field) {
      if (!(std::isfinite(v) && v > 0))
        ctx.fail(where, std::string(field) + " must be a finite number > 0 (got " + std::to_string(v) + ")");
    };
    if (c.type == "perspective") {
      const auto& p = c.perspective;
      positive(p.yfov, "perspective.yfov");
      if (p.yfov >= kPi)
        ctx.fail(where, "perspective.yfov must be < pi (got " + std::to_string(p.yfov) + ")");
      positive(p.znear, "perspective.znear");
      if (p.aspectRatio != 0) positive(p.aspectRatio, "perspective.aspectRatio");
      if (p.zfar != 0) {
        positive(p.zfar, "perspective.zfar");
        if (p.zfar <= p.znear) ctx.fail(where, "perspective.zfar must be greater than znear");
      }
    } else if (c.type == "orthographic") {
      const auto& o = c.orthographic;
      positive(o.xmag, "orthographic.xmag");
      positive(o.ymag, "orthographic.ymag");
      if (!(std::isfinite(o.znear) && o.znear >= 0)) ctx.fail(where, "orthographic.znear must be >= 0");
      positive(o.zfar, "orthographic.zfar");
      if (o.zfar <= o.znear) ctx.fail(where, "orthographic.zfar must be greater than znear");
    } else {
      ctx.fail(where, "unknown camera type '" + c.type + "'");
    }
  }
}

void validate_lights(const GltfContext& ctx) {
  for (size_t i = 0; i < ctx.model.lights.size(); ++i) {
    const auto& l = ctx.model.lights[i];
    const std::string where = "extensions.KHR_lights_punctual." + idx("lights", i);
    if (l.type != "point" && l.type != "spot" && l.type != "directional")
      ctx.fail(where, "unknown light type '" + l.type + "'");
    if (!l.color.empty()) {
      if (l.color.size() != 3) ctx.fail(where + ".color", "must have 3 values");
      for (double v : l.color)
        if (!(std::isfinite(v) && v >= 0)) ctx.fail(where + ".color", "values must be finite and >= 0");
    }
    if (!(std::isfinite(l.intensity) && l.intensity >= 0))
      ctx.fail(where + ".intensity", "must be finite and >= 0");
    if (!(std::isfinite(l.range) && l.range >= 0)) ctx.fail(where + ".range", "must be finite and > 0");
    if (l.type == "spot") {
      const double in = l.spot.innerConeAngle, out = l.spot.outerConeAngle;
      if (!(std::isfinite(in) && std::isfinite(out) && in >= 0 && in < out && out <= kPi / 2 + 1e-6))
        ctx.fail(where + ".spot", "cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
    }
  }
}

std::vector<int> scene_roots(const GltfContext& ctx) {
  const tinygltf::Model& model = ctx.model;
  const int asked = ctx.options.scene;
  int scene = asked >= 0 ? asked : model.defaultScene;
  if (asked >= 0 && size_t(asked) >= model.scenes.size())
    throw InputError(ctx.file, "--scene",
                     "scene " + std::to_string(asked) + " does not exist (" +
                         std::to_string(model.scenes.size()) + " scenes)");
  if (scene >= int(model.scenes.size()) || scene < -1)
    ctx.fail("scene", "default scene " + std::to_string(scene) + " out of range (" +
                          std::to_string(model.scenes.size()) + " scenes)");
  if (scene < 0 && !model.scenes.empty()) scene = 0;
  ctx.out.info.scene_index = scene;
  if (scene >= 0) return model.scenes[size_t(scene)].nodes;
  std::vector<int> roots;
  std::vector<bool> is_child(model.nodes.size(), false);
  for (const auto& n : model.nodes)
    for (int c : n.children)
      if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = true;
  for (size_t i = 0; i < is_child.size(); ++i)
    if (!is_child[i]) roots.push_back(int(i));
  if (!model.nodes.empty()) ctx.warn("scenes", "file has no scene; rendering all root nodes");
  return roots;
}

NodeTransforms link_nodes(const GltfContext& ctx, const std::vector<NodePose>& poses) {
  const size_t n = ctx.model.nodes.size();
  std::vector<int> parent(n, -1);
  for (size_t i = 0; i < n; ++i) {
    for (int c : ctx.model.nodes[i].children) {
      if (c < 0 || size_t(c) >= n)
        ctx.fail(idx("nodes", i) + ".children",
                 "node index " + std::to_string(c) + " out of range (" + std::to_string(n) + " nodes)");
      if (size_t(c) == i) ctx.fail(idx("nodes", i) + ".children", "node is its own child");
      if (parent[size_t(c)] >= 0)
        ctx.fail(idx("nodes", size_t(c)), "has more than one parent (nodes[" +
                                              std::to_string(parent[size_t(c)]) + "] and nodes[" +
                                              std::to_string(i) + "])");
      parent[size_t(c)] = int(i);
    }
  }
  // With at most one parent each, a cycle is a loop of parent links; find one iteratively.
  std::vector<uint8_t> state(n, 0);  // 0 unvisited, 1 on the current parent chain, 2 done
  std::vector<size_t> path;
  for (size_t i = 0; i < n; ++i) {
    path.clear();
    size_t cur = i;
    bool cycle = false;
    while (state[cur] != 2) {
      if (state[cur] == 1) {
        cycle = true;
        break;
      }
      state[cur] = 1;
      path.push_back(cur);
      if (parent[cur] < 0) break;
      cur = size_t(parent[cur]);
    }
    if (cycle) ctx.fail(idx("nodes", cur), "is part of a node cycle");
    for (size_t p : path) state[p] = 2;
  }
  NodeTransforms nodes;
  nodes.parent = std::move(parent);
  nodes.world.assign(n, Transform{});
  nodes.known.assign(n, 0);
  nodes.poses = &poses;
  return nodes;
}

const Transform& world_transform(const GltfContext& ctx, NodeTransforms& nodes, int node) {
  // Walk up to the first ancestor with a known world transform (or a root), then down.
  std::vector<int> chain;
  for (int cur = node; cur >= 0 && !nodes.known[size_t(cur)]; cur = nodes.parent[size_t(cur)])
    chain.push_back(cur);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const int p = nodes.parent[size_t(*it)];
    const Transform world =
        (p >= 0 ? nodes.world[size_t(p)] : Transform{}) * local_transform(ctx, nodes, *it);
    if (!is_finite(world))
      ctx.fail(idx("nodes", size_t(*it)), "world transform overflows to non-finite values");
    nodes.world[size_t(*it)] = world;
    nodes.known[size_t(*it)] = 1;
  }
  return nodes.world[size_t(node)];
}

NodeUses place_nodes(const GltfContext& ctx, NodeTransforms& nodes, const std::vector<int>& roots) {
  const size_t n = ctx.model.nodes.size();
  std::set<int> seen_roots;
  std::vector<int> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
    const int r = *it;
    if (r < 0 || size_t(r) >= n)
      ctx.fail("scenes.nodes",
               "node index " + std::to_string(r) + " out of range (" + std::to_string(n) + " nodes)");
    if (nodes.parent[size_t(r)] >= 0)
      ctx.fail(idx("nodes", size_t(r)), "is listed as a scene root but is a child of nodes[" +
                                            std::to_string(nodes.parent[size_t(r)]) + "]");
    if (!seen_roots.insert(r).second) ctx.fail(idx("nodes", size_t(r)), "listed twice as a scene root");
    stack.push_back(r);
  }
  NodeUses uses;
  while (!stack.empty()) {
    const int index = stack.back();
    stack.pop_back();
    const auto& node = ctx.model.nodes[size_t(index)];
    const Transform world = world_transform(ctx, nodes, index);  // the parent's is known: pre-order
    if (node.mesh >= 0 || node.mesh < -1) uses.meshes.push_back({node.mesh, index});
    if (node.extensions.count(kShapesExtension)) uses.shapes.push_back(index);
    if (node.camera >= 0 || node.camera < -1) {
      add_camera(ctx, node.camera, index, world);
      uses.cameras.push_back(index);
    }
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end()) {
      const auto& li = it->second.Get("light");
      if (!li.IsNumber())
        ctx.fail(idx("nodes", size_t(index)) + ".extensions.KHR_lights_punctual.light", "must be an integer");
      add_light(ctx, int(li.GetNumberAsInt()), index, world);
      uses.lights.push_back(index);
    }
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back(*c);
  }
  return uses;
}

}  // namespace penumbra::gltf
