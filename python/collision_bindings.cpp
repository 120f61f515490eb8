// Scene.proxies and Scene.collide: bounding proxies fitted to the scene's nodes with their
// tightness, the nodes that touch, and the first contacts of moving nodes up to a later time
// (renderer/collision/scene_proxies.h, scene_collide.h, continuous.h: what `penumbra proxies`
// and `penumbra collide` call), as dicts of NumPy arrays.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <variant>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "python/bindings.h"
#include "render/scene_query.h"
#include "renderer/collision/continuous.h"
#include "renderer/collision/scene_collide.h"
#include "renderer/collision/scene_proxies.h"

namespace penumbra::python {

namespace {

py::array_t<double> vec(DVec3 v) {
  py::array_t<double> a(3);
  double* d = a.mutable_data();
  d[0] = v.x, d[1] = v.y, d[2] = v.z;
  return a;
}

py::dict part_dict(const ConvexPolyhedron& c) {
  py::array_t<double> vertices({py::ssize_t(c.vertices.size()), py::ssize_t(3)});
  py::array_t<int64_t> triangles({py::ssize_t(c.triangles.size() / 3), py::ssize_t(3)});
  py::array_t<double> planes({py::ssize_t(c.planes.size()), py::ssize_t(4)});
  double* v = vertices.mutable_data();
  for (const DVec3& p : c.vertices) *v++ = p.x, *v++ = p.y, *v++ = p.z;
  int64_t* t = triangles.mutable_data();
  for (uint32_t i : c.triangles) *t++ = i;
  double* p = planes.mutable_data();
  for (const DPlane& pl : c.planes) *p++ = pl.n.x, *p++ = pl.n.y, *p++ = pl.n.z, *p++ = pl.d;
  py::dict d;
  d["vertices"] = vertices;
  d["triangles"] = triangles;
  d["planes"] = planes;
  d["volume"] = c.volume;
  d["qhull_volume"] = c.qhull_volume >= 0 ? py::object(py::float_(c.qhull_volume)) : py::object(py::none());
  d["thickened"] = c.thickened;
  return d;
}

py::object finite_or_none(double v) {
  return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none());
}

py::dict proxy_dict(const NodeProxy& np, const GltfInfo& info) {
  py::dict d;
  const Proxy& p = np.proxy;
  d["node"] = np.node;
  d["name"] = size_t(np.node) < info.node_names.size() ? info.node_names[size_t(np.node)] : std::string();
  d["kind"] = proxy_kind_name(p.kind);
  d["vertices"] = np.vertices;
  d["triangles"] = np.triangles;
  switch (p.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      d["center"] = vec(p.sphere.center);
      d["radius"] = p.sphere.radius;
      break;
    case ProxyKind::Aabb:
    case ProxyKind::Obb: {
      d["center"] = vec(p.box.center);
      py::array_t<double> axes({py::ssize_t(3), py::ssize_t(3)});
      double* a = axes.mutable_data();
      for (const DVec3& ax : p.box.axis) *a++ = ax.x, *a++ = ax.y, *a++ = ax.z;
      d["axes"] = axes;
      d["half_extents"] = vec(p.box.half);
      break;
    }
    case ProxyKind::Capsule:
      d["a"] = vec(p.capsule.a);
      d["b"] = vec(p.capsule.b);
      d["radius"] = p.capsule.radius;
      break;
    default: {
      py::list parts;
      for (const ConvexPolyhedron& c : p.parts) parts.append(part_dict(c));
      d["parts"] = parts;
    }
  }
  const ProxyTightness& t = np.tightness;
  d["volume"] = t.proxy_volume;
  d["mesh_volume"] = finite_or_none(t.mesh_volume);
  d["volume_ratio"] = finite_or_none(t.volume_ratio);
  d["hull_ratio"] = finite_or_none(t.hull_ratio);
  d["hausdorff"] = t.hausdorff;
  d["samples"] = t.samples;
  return d;
}

py::list proxies(SceneSession& s, const std::string& kind,
                 const std::optional<std::variant<int, std::string>>& node, int kdop, int64_t samples,
                 int threads) {
  SceneProxyConfig config;
  if (!parse_proxy_kind(kind, config.kind)) {
    std::string names;
    for (int i = 0; i < kProxyKindCount; ++i)
      names += std::string(i ? ", " : "") + proxy_kind_name(ProxyKind(i));
    throw py::value_error("kind '" + kind + "': not a proxy kind (" + names + ")");
  }
  if (kdop != 6 && kdop != 14 && kdop != 18 && kdop != 26)
    throw py::value_error("kdop " + std::to_string(kdop) + ": k must be 6, 14, 18 or 26");
  if (samples < 0 || samples > 10000000) throw py::value_error("samples must be in [0, 10^7]");
  if (threads < 0 || threads > 1024) throw py::value_error("threads must be in [0, 1024]");
  config.fit.kdop = kdop;
  config.samples = size_t(samples);
  config.threads = threads;
  SessionLock lock(s);
  if (node) {
    const std::string spec = std::holds_alternative<int>(*node) ? std::to_string(std::get<int>(*node))
                                                                : std::get<std::string>(*node);
    if (std::holds_alternative<int>(*node) && std::get<int>(*node) < 0)
      throw py::value_error("node " + spec + ": not a node index");
    std::string error;
    config.root = find_node(s.loaded.info, spec, s.file, error);
    if (config.root < 0) throw py::value_error("node " + spec + ": " + error);
  }
  std::vector<NodeProxy> fitted;
  {
    py::gil_scoped_release release;
    try {
      fitted = fit_scene_proxies(s.loaded.scene, s.loaded.info.node_parents, config);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file, "", e.what());
    }
  }
  py::list out;
  for (const NodeProxy& np : fitted) out.append(proxy_dict(np, s.loaded.info));
  return out;
}

std::string node_name(const SceneSession& s, int node) {
  return size_t(node) < s.loaded.info.node_names.size() ? s.loaded.info.node_names[size_t(node)] : "";
}

py::dict swept_dict(const ContinuousReport& r, const SceneSession& s, double t0, double t1, bool mesh) {
  auto contacts = [&](const std::vector<SweptContact>& from, bool touching) {
    py::list list;
    for (const SweptContact& c : from) {
      py::dict d;
      d["a"] = c.a;
      d["b"] = c.b;
      d["a_name"] = node_name(s, c.a);
      d["b_name"] = node_name(s, c.b);
      d["time"] = t0 + c.u * (t1 - t0);
      d["fraction"] = c.u;
      if (touching) {
        d["point"] = vec(c.point);
        d["normal"] = vec(c.normal);
      }
      list.append(d);
    }
    return list;
  };
  py::list nonrigid;
  for (int n : r.nonrigid_nodes) {
    py::dict d;
    d["node"] = n;
    d["name"] = node_name(s, n);
    nonrigid.append(d);
  }
  py::dict out;
  out["contacts"] = contacts(r.contacts, true);
  out["undecided"] = contacts(r.undecided, false);
  out["to_time"] = t1;
  out["nodes"] = r.nodes;
  out["moving_nodes"] = r.moving_nodes;
  out["nonrigid_nodes"] = nonrigid;
  out["broad_pairs"] = r.broad_pairs;
  out["family_pairs"] = r.family_pairs;
  out["narrow_tests"] = r.narrow_tests;
  out[mesh ? "triangle_pairs" : "advancement_steps"] = r.steps;
  return out;
}

// The first contacts between the session's pose and its animation posed at `until`.
py::dict continuous(SceneSession& s, const CollideConfig& config, double until) {
  if (!std::isfinite(until)) throw py::value_error("until must be a finite number of seconds");
  if (!s.loaded.animation)
    throw py::value_error(
        "until: the scene must be loaded with time= and keep_animation=True, and its animation must move "
        "only "
        "placements (no skins or morph targets)");
  ContinuousReport r;
  {
    py::gil_scoped_release release;
    Scene end = s.loaded.scene;
    if (!pose_gltf_scene(*s.loaded.animation, until, end))
      throw py::value_error("until: the animation changes more than placements at that time");
    try {
      r = collide_continuous(s.loaded.scene, end,
                             {s.loaded.info.node_parents, s.loaded.info.node_skin_joints}, config);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file, "", e.what());
    }
  }
  return swept_dict(r, s, s.time, until, config.mesh);
}

py::dict collide(SceneSession& s, const std::string& proxy, bool include_children, int kdop,
                 std::optional<double> until, bool volumes) {
  CollideConfig config;
  config.include_children = include_children;
  config.volumes = volumes;
  if (proxy != "mesh") {
    config.mesh = false;
    if (!parse_proxy_kind(proxy, config.kind))
      throw py::value_error("proxy '" + proxy + "': not mesh or a proxy kind");
  }
  if (kdop != 6 && kdop != 14 && kdop != 18 && kdop != 26)
    throw py::value_error("kdop " + std::to_string(kdop) + ": k must be 6, 14, 18 or 26");
  config.fit.kdop = kdop;
  SessionLock lock(s);
  std::optional<py::dict> swept;
  if (until) swept = continuous(s, config, *until);
  CollideReport r;
  {
    py::gil_scoped_release release;
    try {
      r = collide_scene(s.loaded.scene, {s.loaded.info.node_parents, s.loaded.info.node_skin_joints}, config);
    } catch (const std::invalid_argument& e) {
      throw InputError(s.file, "", e.what());
    }
  }
  py::list contacts;
  for (const NodeContact& c : r.contacts) {
    py::dict d;
    d["a"] = c.a;
    d["b"] = c.b;
    d["a_name"] = node_name(s, c.a);
    d["b_name"] = node_name(s, c.b);
    d["point"] = vec(c.point);
    d["depth"] = finite_or_none(c.depth);
    d["depth_error"] =
        std::isfinite(c.depth) ? py::object(py::float_(c.depth_error)) : py::object(py::none());
    d["shape_error"] = c.shape_error;
    d["direction"] = std::isfinite(c.depth) ? py::object(vec(c.direction)) : py::object(py::none());
    d["triangle_pairs"] = c.triangle_pairs;
    d["volume"] = volumes ? py::object(py::float_(c.volume.volume)) : py::object(py::none());
    d["volume_error"] = volumes ? py::object(py::float_(c.volume.error)) : py::object(py::none());
    d["volume_exact"] = volumes ? py::object(py::bool_(c.volume.exact)) : py::object(py::none());
    contacts.append(d);
  }
  py::dict out;
  out["contacts"] = contacts;
  out["nodes"] = r.nodes;
  out["broad_pairs"] = r.broad_pairs;
  out["family_pairs"] = r.family_pairs;
  out["narrow_tests"] = r.narrow_tests;
  out["triangle_tests"] = r.triangle_tests;
  out["continuous"] = swept ? py::object(*swept) : py::object(py::none());
  return out;
}

}  // namespace

void bind_collision(SceneClass& scene) {
  scene.def(
      "collide", &collide, py::kw_only(), py::arg("proxy") = "mesh", py::arg("include_children") = false,
      py::arg("kdop") = 26, py::arg("until") = py::none(), py::arg("volumes") = false,
      "The nodes that touch or interpenetrate at the scene's pose, as `penumbra collide` finds them: a "
      "sweep and prune over the nodes' boxes, pairs the hierarchy or a skin joins left out unless "
      "include_children, "
      "and an exact test on the triangles (proxy='mesh') or on fitted proxies (a proxy kind, which also "
      "gives depth and direction). Returns a dict: contacts (a list of dicts: a, b, a_name, b_name, point, "
      "depth, depth_error, shape_error, direction, triangle_pairs, and with volumes=True volume, "
      "volume_error, "
      "volume_exact: the "
      "volume the pair shares as `collide --volumes` measures it), nodes, broad_pairs, family_pairs, "
      "narrow_tests, triangle_tests, and continuous. With until (seconds; the scene loaded "
      "with time= and "
      "keep_animation=True: animations that move placements), continuous holds the first contacts of moving "
      "nodes (meshes: exact; proxies: nodes that move rigidly) from the "
      "scene's pose to its animation at until, as `penumbra collide --continuous` finds them between two "
      "frames (the scene itself is not moved): a dict of contacts (a, b, a_name, b_name, time, fraction, "
      "point, normal), undecided (a, b, a_name, b_name, time, fraction: pairs whose advancement ran out of "
      "budget, with no contact before time), "
      "to_time, nodes, moving_nodes, nonrigid_nodes (dicts of node, name), broad_pairs, family_pairs, "
      "narrow_tests, and advancement_steps (proxies) or triangle_pairs (meshes: swept triangle pairs "
      "tested); else None.");
  scene.def(
      "proxies", &proxies, py::arg("kind"), py::arg("node") = py::none(), py::kw_only(), py::arg("kdop") = 26,
      py::arg("samples") = 20000, py::arg("threads") = 0,
      "Bounding proxies fitted to each node that places a mesh, or with node (index or name) one for "
      "that node's subtree, as `penumbra proxies` fits them: kind is sphere (minimal), ritter, aabb, obb, "
      "capsule, hull (Qhull), kdop (kdop = 6, 14, 18 or 26) or composite (a hull per connected "
      "component). Returns a list of dicts, one per node: node, name, kind, vertices, triangles; the "
      "proxy (center and radius; center, axes (3, 3) rows and half_extents; a, b and radius; or parts: "
      "dicts of vertices (V, 3), triangles (T, 3), planes (F, 4: n, d with n.p <= d inside), volume, "
      "qhull_volume, thickened); and its tightness: volume, mesh_volume, volume_ratio and hull_ratio "
      "(None where the meshes are open), hausdorff (from the proxy's surface to the geometry, over "
      "samples surface points) and samples. ValueError for an unknown kind or node.");
}

}  // namespace penumbra::python
