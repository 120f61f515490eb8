// Node geometry, proxy tightness and proxies as shapes.
#include "renderer/collision/scene_proxies.h"

#include <algorithm>
#include <stdexcept>

#include "renderer/accel/factory.h"
#include "renderer/accel/query.h"
#include "renderer/scene/volume.h"

namespace penumbra {

namespace {

DVec3 place(const Affine3f& a, Vec3f p) {
  DVec3 out;
  double* o[3] = {&out.x, &out.y, &out.z};
  for (int r = 0; r < 3; ++r)
    *o[r] = double(a.m[r][0]) * p.x + double(a.m[r][1]) * p.y + double(a.m[r][2]) * p.z + double(a.m[r][3]);
  return out;
}

// The Frobenius norm of the placement's linear part: at least the largest factor by which it
// stretches a length.
double linear_norm(const Affine3f& a) {
  double sum = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) sum += double(a.m[r][c]) * a.m[r][c];
  return std::sqrt(sum);
}

double abs_det(const Affine3f& a) {
  const auto& m = a.m;
  const double d = double(m[0][0]) * (double(m[1][1]) * m[2][2] - double(m[1][2]) * m[2][1]) -
                   double(m[0][1]) * (double(m[1][0]) * m[2][2] - double(m[1][2]) * m[2][0]) +
                   double(m[0][2]) * (double(m[1][0]) * m[2][1] - double(m[1][1]) * m[2][0]);
  return std::abs(d);
}

Affine3f frame_to_world(DVec3 x, DVec3 y, DVec3 z, DVec3 origin) {
  Affine3f a;
  const DVec3 cols[4] = {x, y, z, origin};
  for (int c = 0; c < 4; ++c) {
    a.m[0][c] = float(cols[c].x);
    a.m[1][c] = float(cols[c].y);
    a.m[2][c] = float(cols[c].z);
  }
  return a;
}

void add_shape(Scene& scene, Shape shape, const Affine3f& to_world, int material, const std::string& name,
               int node) {
  SceneShape s;
  s.name = name;
  s.shape = std::move(shape);
  s.material = material;
  s.node = node;
  scene.shapes.push_back(std::move(s));
  scene.instances.push_back(make_shape_instance(int(scene.shapes.size()) - 1, to_world, node));
}

void append_polyhedron(Scene& scene, const ConvexPolyhedron& part, int material, const std::string& name,
                       int node) {
  if (part.planes.size() <= kMaxProxyPlanes && part.planes.size() >= 4) {
    SdfTree tree;
    SdfNode n;
    n.kind = SdfKind::ConvexPolyhedron;
    n.first_plane = 0;
    n.plane_count = int(part.planes.size());
    for (const DPlane& p : part.planes)
      tree.planes.push_back({float(p.n.x), float(p.n.y), float(p.n.z), float(p.d)});
    tree.nodes.push_back(n);
    tree.root = 0;
    Shape shape = make_implicit_shape(std::move(tree));
    if (shape.sdf_bounds.empty())
      throw std::invalid_argument(name + ": the convex polyhedron encloses nothing");
    add_shape(scene, std::move(shape), Affine3f{}, material, name, node);
    return;
  }
  Mesh mesh;  // flat-shaded triangles: one vertex per corner
  mesh.name = name;
  mesh.material = material;
  mesh.node = node;
  for (size_t t = 0; t + 2 < part.triangles.size(); t += 3) {
    const DVec3 a = part.vertices[part.triangles[t]], b = part.vertices[part.triangles[t + 1]],
                c = part.vertices[part.triangles[t + 2]];
    DVec3 n = cross(b - a, c - a);
    const double len = length(n);
    n = len > 0 ? n * (1 / len) : DVec3{0, 1, 0};
    for (const DVec3& p : {a, b, c}) {
      mesh.indices.push_back(uint32_t(mesh.positions.size()));
      mesh.positions.push_back({float(p.x), float(p.y), float(p.z)});
      mesh.normals.push_back({float(n.x), float(n.y), float(n.z)});
    }
  }
  scene.meshes.push_back(std::move(mesh));
  scene.instances.push_back(make_instance(int(scene.meshes.size()) - 1, Affine3f{}, node));
}

}  // namespace

bool node_in_subtree(int node, int ancestor, std::span<const int> parents) {
  for (size_t steps = 0; node >= 0 && steps <= parents.size(); ++steps) {
    if (node == ancestor) return true;
    node = size_t(node) < parents.size() ? parents[size_t(node)] : -1;
  }
  return false;
}

bool nodes_joined(int a, int b, const NodeLinks& links) {
  if (node_in_subtree(a, b, links.parents) || node_in_subtree(b, a, links.parents)) return true;
  auto joints_of = [&](int n) {
    return n >= 0 && size_t(n) < links.skin_joints.size() ? std::span<const int>(links.skin_joints[size_t(n)])
                                                          : std::span<const int>();
  };
  const std::span<const int> ja = joints_of(a), jb = joints_of(b);
  for (int j : ja)
    if (node_in_subtree(b, j, links.parents) || std::find(jb.begin(), jb.end(), j) != jb.end()) return true;
  for (int j : jb)
    if (node_in_subtree(a, j, links.parents)) return true;
  return false;
}

std::vector<NodeGeometry> node_geometry(const Scene& scene, std::span<const int> node_parents, int root,
                                        const ShapeTrianglesConfig& shapes) {
  std::vector<NodeGeometry> out;
  std::vector<int> entry_of_node;  // root < 0: glTF node -> index into out, -1 none yet
  std::vector<double> mesh_volume_cache(scene.meshes.size(), -2);  // -2: not measured, -1: open
  std::vector<ShapeTriangles> shape_cache(scene.shapes.size());
  std::vector<double> shape_volume(scene.shapes.size(), -2);
  for (const Instance& inst : scene.instances) {
    const bool is_shape = inst.shape >= 0 && size_t(inst.shape) < scene.shapes.size();
    if (!is_shape && (inst.mesh < 0 || size_t(inst.mesh) >= scene.meshes.size())) continue;
    const int own_node =
        is_shape ? scene.shapes[size_t(inst.shape)].node : scene.meshes[size_t(inst.mesh)].node;
    const int node = inst.node >= 0 ? inst.node : own_node;
    if (node < 0) continue;
    if (root >= 0 && !node_in_subtree(node, root, node_parents)) continue;
    // The triangles placed: a mesh's, or a shape's tessellation (made once per shape).
    std::span<const Vec3f> positions;
    std::span<const uint32_t> indices;
    bool points = false;  // a point or line set: measured, but no triangles to collide
    double volume = -1;   // object space, -1 when open
    double error = 0;
    if (is_shape) {
      const SceneShape& ss = scene.shapes[size_t(inst.shape)];
      ShapeTriangles& t = shape_cache[size_t(inst.shape)];
      double& v = shape_volume[size_t(inst.shape)];
      if (v == -2) {
        try {
          t = shape_triangles(ss.shape, shapes);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument("node " + std::to_string(node) + ": shape '" + ss.name +
                                      "': " + e.what());
        }
        const MeshVolume mv = mesh_volume(t.positions, t.indices);
        v = t.closed && mv.closed ? std::abs(mv.signed_volume) : -1;
      }
      positions = t.positions, indices = t.indices, volume = v;
      error = t.error * linear_norm(inst.to_world);
    } else {
      const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
      double& v = mesh_volume_cache[size_t(inst.mesh)];
      if (v == -2) {
        const MeshVolume mv = mesh_volume(mesh.positions, mesh.indices);
        v = mv.closed && !mesh.points ? std::abs(mv.signed_volume) : -1;
      }
      positions = mesh.positions, indices = mesh.indices, points = mesh.points || mesh.lines, volume = v;
    }
    NodeGeometry* g = nullptr;
    if (root >= 0) {
      if (out.empty()) {
        out.emplace_back();
        out.back().node = root;
        out.back().enclosed_volume = 0;
      }
      g = &out[0];
    } else {
      if (size_t(node) >= entry_of_node.size()) entry_of_node.resize(size_t(node) + 1, -1);
      if (entry_of_node[size_t(node)] < 0) {
        entry_of_node[size_t(node)] = int(out.size());
        out.emplace_back();
        out.back().node = node;
        out.back().enclosed_volume = 0;
      }
      g = &out[size_t(entry_of_node[size_t(node)])];
    }
    const uint32_t base = uint32_t(g->points.size());
    for (const Vec3f& p : positions) {
      g->points.push_back(place(inst.to_world, p));
      const DVec3& w = g->points.back();
      g->positions.push_back({float(w.x), float(w.y), float(w.z)});
    }
    for (size_t t = 0; t + 2 < indices.size(); t += 3) {
      const uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
      g->measured.insert(g->measured.end(), {base + a, base + b, base + c});
      if (!points) g->triangles.insert(g->triangles.end(), {base + a, base + b, base + c});
    }
    g->enclosed_volume = volume < 0 ? NAN : g->enclosed_volume + volume * abs_det(inst.to_world);
    ++g->instances;
    g->shapes += is_shape;
    g->shape_error = std::max(g->shape_error, error);
    g->instance_triangles.push_back(g->triangles.size());
    g->instance_to_world.push_back(inst.to_world);
  }
  std::sort(out.begin(), out.end(),
            [](const NodeGeometry& a, const NodeGeometry& b) { return a.node < b.node; });
  return out;
}

ShapeTrianglesCount placed_geometry_count(const Scene& scene, const ShapeTrianglesConfig& shapes) {
  ShapeTrianglesCount n;
  for (const Instance& inst : scene.instances) {
    ShapeTrianglesCount one;
    if (inst.shape >= 0 && size_t(inst.shape) < scene.shapes.size())
      one = shape_triangles_count(scene.shapes[size_t(inst.shape)].shape, shapes);
    else if (inst.mesh >= 0 && size_t(inst.mesh) < scene.meshes.size())
      one = {scene.meshes[size_t(inst.mesh)].positions.size(),
             scene.meshes[size_t(inst.mesh)].indices.size() / 3};
    n.vertices += one.vertices, n.triangles += one.triangles;
  }
  return n;
}

ProxyTightness proxy_tightness(const Proxy& proxy, const NodeGeometry& geometry, size_t samples, int threads,
                               double hull_volume) {
  ProxyTightness t;
  t.proxy_volume = proxy_volume(proxy);
  t.mesh_volume = geometry.enclosed_volume;
  if (std::isfinite(t.mesh_volume) && t.mesh_volume > 0) t.volume_ratio = t.proxy_volume / t.mesh_volume;
  if (std::isfinite(hull_volume) && hull_volume > 0) t.hull_ratio = t.proxy_volume / hull_volume;
  if (geometry.measured.empty() || samples == 0) return t;
  std::vector<DVec3> surface;
  sample_proxy_surface(proxy, samples, 0x5eed5eedull, surface);
  std::vector<Vec3f> queries;
  queries.reserve(surface.size());
  for (const DVec3& p : surface) queries.push_back({float(p.x), float(p.y), float(p.z)});
  GeometryView view;
  view.positions = geometry.positions;
  view.indices = geometry.measured;
  const std::unique_ptr<Accelerator> accel = make_accelerator("bvh", std::span<const GeometryView>(&view, 1));
  QueryScene qs;
  qs.meshes = std::span<const GeometryView>(&view, 1);
  std::vector<PrimitiveMatch> matches;
  std::vector<uint32_t> counts;
  nearest_batch(*accel, qs, queries, 1, kInfinity, threads, matches, counts);
  for (size_t i = 0; i < queries.size(); ++i)
    if (counts[i] > 0) t.hausdorff = std::max(t.hausdorff, double(matches[i].distance));
  t.samples = queries.size();
  return t;
}

std::vector<NodeProxy> fit_scene_proxies(const Scene& scene, std::span<const int> node_parents,
                                         const SceneProxyConfig& config) {
  std::vector<NodeProxy> out;
  for (const NodeGeometry& g : node_geometry(scene, node_parents, config.root)) {
    if (g.points.empty()) continue;
    NodeProxy np;
    np.node = g.node;
    np.vertices = g.points.size();
    np.triangles = g.triangles.size() / 3;
    try {
      np.proxy = fit_proxy(config.kind, g.points, g.triangles, config.fit);
      const double hull = config.kind == ProxyKind::Hull ? np.proxy.parts[0].volume
                                                         : convex_hull(g.points, config.fit.hull).volume;
      np.tightness = proxy_tightness(np.proxy, g, config.samples, config.threads, hull);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("node " + std::to_string(g.node) + ": " + e.what());
    }
    out.push_back(std::move(np));
  }
  return out;
}

void append_proxy_shapes(Scene& scene, const Proxy& proxy, int material, const std::string& name, int node) {
  switch (proxy.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter: {
      Shape s;
      s.kind = ShapeKind::Sphere;
      const DVec3 c = proxy.sphere.center;
      s.radius = float(
          std::max(proxy.sphere.radius, 1e-6 * std::max({1.0, std::abs(c.x), std::abs(c.y), std::abs(c.z)})));
      add_shape(scene, s, frame_to_world({1, 0, 0}, {0, 1, 0}, {0, 0, 1}, c), material, name, node);
      return;
    }
    case ProxyKind::Aabb:
    case ProxyKind::Obb: {
      const OrientedBox& b = proxy.box;
      const double floor = 1e-6 * std::max({1e-30, b.half.x, b.half.y, b.half.z});
      Shape s;
      s.kind = ShapeKind::Box;
      s.half_size = {float(std::max(b.half.x, floor)), float(std::max(b.half.y, floor)),
                     float(std::max(b.half.z, floor))};
      add_shape(scene, s, frame_to_world(b.axis[0], b.axis[1], b.axis[2], b.center), material, name, node);
      return;
    }
    case ProxyKind::Capsule: {
      const CapsuleProxy& c = proxy.capsule;
      const double len = length(c.b - c.a);
      const DVec3 y = len > 0 ? (c.b - c.a) * (1 / len) : DVec3{0, 1, 0};
      const DVec3 t = std::abs(y.x) < 0.9 ? DVec3{1, 0, 0} : DVec3{0, 1, 0};
      DVec3 x = cross(y, t);
      x = x * (1 / length(x));
      const DVec3 z = cross(x, y);
      Shape s;
      s.kind = ShapeKind::Capsule;
      s.radius = float(std::max(c.radius, 1e-6 * std::max(1.0, len)));
      s.half_height = float(0.5 * len);
      add_shape(scene, s, frame_to_world(x, y, z, (c.a + c.b) * 0.5), material, name, node);
      return;
    }
    default:
      for (size_t i = 0; i < proxy.parts.size(); ++i)
        append_polyhedron(scene, proxy.parts[i], material,
                          proxy.parts.size() > 1 ? name + "[" + std::to_string(i) + "]" : name, node);
      return;
  }
}

}  // namespace penumbra
