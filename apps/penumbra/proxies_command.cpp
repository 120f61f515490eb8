// `penumbra proxies`.
#include "apps/penumbra/proxies_command.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/path_render.h"
#include "apps/penumbra/scene_setup.h"
#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/gltf/gltf_writer.h"
#include "renderer/collision/scene_proxies.h"

namespace penumbra::cli {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

/// Bytes held per placed vertex while fitting: double and float copies, indices, the hull's
/// input and the query structure.
constexpr uint64_t kBytesPerVertex = 256;

/// Bytes held per surface sample of the Hausdorff distance: the point twice and its match.
constexpr uint64_t kBytesPerSample = 96;

Json dvec(DVec3 v) {
  return Json::array({v.x, v.y, v.z});
}
Json number_or_null(double v) {
  return std::isfinite(v) ? Json(v) : Json();
}

Json proxy_json(const NodeProxy& np, const std::string& name) {
  const Proxy& p = np.proxy;
  Json j;
  j["node"] = np.node;
  j["name"] = name;
  j["vertices"] = np.vertices;
  j["triangles"] = np.triangles;
  switch (p.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      j["sphere"] = {{"center", dvec(p.sphere.center)}, {"radius", p.sphere.radius}};
      break;
    case ProxyKind::Aabb:
    case ProxyKind::Obb:
      j["box"] = {{"center", dvec(p.box.center)},
                  {"axes", Json::array({dvec(p.box.axis[0]), dvec(p.box.axis[1]), dvec(p.box.axis[2])})},
                  {"half_extents", dvec(p.box.half)}};
      break;
    case ProxyKind::Capsule:
      j["capsule"] = {{"a", dvec(p.capsule.a)}, {"b", dvec(p.capsule.b)}, {"radius", p.capsule.radius}};
      break;
    default: {
      Json parts = Json::array();
      for (const ConvexPolyhedron& c : p.parts) {
        Json planes = Json::array();
        for (const DPlane& pl : c.planes) planes.push_back({pl.n.x, pl.n.y, pl.n.z, pl.d});
        parts.push_back({{"vertices", c.vertices.size()},
                         {"faces", c.planes.size()},
                         {"volume", c.volume},
                         {"qhull_volume", c.qhull_volume >= 0 ? Json(c.qhull_volume) : Json()},
                         {"thickened", c.thickened},
                         {"planes", planes}});
      }
      j["parts"] = parts;
    }
  }
  const ProxyTightness& t = np.tightness;
  j["volume"] = t.proxy_volume;
  j["mesh_volume"] = number_or_null(t.mesh_volume);
  j["volume_ratio"] = number_or_null(t.volume_ratio);
  j["hull_ratio"] = number_or_null(t.hull_ratio);
  j["hausdorff"] = t.hausdorff;
  j["samples"] = t.samples;
  return j;
}

std::string proxy_text(const NodeProxy& np) {
  const Proxy& p = np.proxy;
  switch (p.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      return format("centre (%.6g, %.6g, %.6g), radius %.6g", p.sphere.center.x, p.sphere.center.y,
                    p.sphere.center.z, p.sphere.radius);
    case ProxyKind::Aabb:
    case ProxyKind::Obb:
      return format("centre (%.6g, %.6g, %.6g), half extents (%.6g, %.6g, %.6g)", p.box.center.x,
                    p.box.center.y, p.box.center.z, p.box.half.x, p.box.half.y, p.box.half.z);
    case ProxyKind::Capsule:
      return format("segment (%.6g, %.6g, %.6g)-(%.6g, %.6g, %.6g), radius %.6g", p.capsule.a.x,
                    p.capsule.a.y, p.capsule.a.z, p.capsule.b.x, p.capsule.b.y, p.capsule.b.z,
                    p.capsule.radius);
    default: {
      size_t faces = 0, vertices = 0;
      for (const ConvexPolyhedron& c : p.parts) faces += c.planes.size(), vertices += c.vertices.size();
      return format("%zu part%s, %zu faces, %zu vertices", p.parts.size(), p.parts.size() == 1 ? "" : "s",
                    faces, vertices);
    }
  }
}

std::string ratio_text(double r, const char* what) {
  return std::isfinite(r) ? format(", %.4gx the %s", r, what) : std::string();
}

}  // namespace

int run_proxies(const ProxiesArgs& a) {
  ProxyKind kind;
  if (!parse_proxy_kind(a.kind, kind)) {
    std::string names;
    for (int i = 0; i < kProxyKindCount; ++i)
      names += std::string(i ? ", " : "") + proxy_kind_name(ProxyKind(i));
    throw UsageError("--kind " + a.kind + ": not a proxy kind (" + names + ")");
  }
  if (a.kdop != 6 && a.kdop != 14 && a.kdop != 18 && a.kdop != 26)
    throw UsageError("--kdop " + std::to_string(a.kdop) + ": k must be 6, 14, 18 or 26");
  if (a.node && a.node->empty())
    throw UsageError(
        "--node: the value is empty (give a node index or name, or leave --node out for every node)");
  std::vector<std::pair<std::string, fs::path>> outputs;
  const fs::path out(a.output);
  std::string ext = out.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (!a.output.empty()) {
    if (ext != ".glb" && ext != ".gltf")
      throw UsageError("-o " + a.output + ": the output must be a .glb or .gltf file");
    outputs.push_back({"-o", out});
    if (ext == ".gltf")
      outputs.push_back({"the buffer beside -o", out.parent_path() / (out.stem().string() + ".bin")});
    for (const auto& [name, path] : outputs) resolve_output(path, name);
    check_distinct_files(outputs, {{"the scene", a.scene_file}});
  } else if (a.overlay) {
    throw UsageError("--overlay: it shapes the output; give -o OUT.gltf");
  }
  const uint64_t budget = memory_budget(a.max_memory);
  install_signal_handlers();

  set_phase("loading the scene");
  const LoadedScene loaded = load_scene(a.scene_file, a.scene, a.allow_external, false, budget, a.quiet);
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (const auto& f : loaded.info.source_files) inputs.push_back({"the scene's file", f});
  if (!outputs.empty()) check_distinct_files(outputs, inputs);
  SceneProxyConfig config;
  config.kind = kind;
  config.fit.kdop = a.kdop;
  config.samples = size_t(a.samples);
  config.threads = a.threads;
  if (a.node) config.root = find_gltf_node(loaded.info, *a.node, a.scene_file);
  const uint64_t placed = placed_geometry_count(loaded.scene).vertices;
  const uint64_t scene_bytes = scene_memory_bytes(loaded.scene);
  const uint64_t needed = placed * kBytesPerVertex + uint64_t(a.samples) * kBytesPerSample;
  if (needed > budget - std::min(budget, scene_bytes))
    throw UsageError(a.scene_file + ": fitting proxies to " + human_count(placed) + " placed vertices with " +
                     human_count(uint64_t(a.samples)) + " samples needs " + human_count(needed) +
                     "B beside the scene, over the budget (--max-memory)");

  set_phase("fitting proxies");
  std::vector<NodeProxy> proxies;
  try {
    proxies = fit_scene_proxies(loaded.scene, loaded.info.node_parents, config);
  } catch (const std::invalid_argument& e) {
    throw InputError(a.scene_file, "", e.what());
  }
  if (proxies.empty())
    throw UsageError(a.scene_file + ": " +
                     (config.root < 0 ? std::string("no node places a mesh")
                                      : "node '" + loaded.info.node_names[size_t(config.root)] +
                                            "' and the nodes below it place no mesh"));
  auto node_name = [&](int node) {
    return size_t(node) < loaded.info.node_names.size() ? loaded.info.node_names[size_t(node)]
                                                        : std::string();
  };

  if (!a.output.empty()) {
    set_phase("writing the proxies");
    Scene scene = loaded.scene;
    if (!a.overlay) {
      scene.meshes.clear();
      scene.shapes.clear();
      scene.instances.clear();
      scene.instance_motion.clear();
    }
    Material m;
    m.name = std::string("proxy ") + proxy_kind_name(kind);
    m.base_color = {0.95f, 0.45f, 0.12f};
    m.metallic = 0;
    m.roughness = 0.6f;
    if (a.overlay) {
      m.alpha = 0.35f;
      m.alpha_mode = AlphaMode::Blend;
    }
    scene.materials.push_back(m);
    const int material = int(scene.materials.size()) - 1;
    for (const NodeProxy& np : proxies)
      append_proxy_shapes(scene, np.proxy, material, node_name(np.node) + " " + proxy_kind_name(kind), -1);
    if (!scene.instance_motion.empty()) scene.instance_motion.resize(scene.instances.size());
    if (ext == ".glb")
      write_glb(scene, out);
    else
      write_gltf(scene, out);
  }

  if (a.json) {
    Json doc;
    doc["scene"] = a.scene_file;
    doc["kind"] = proxy_kind_name(kind);
    if (kind == ProxyKind::Kdop) doc["k"] = a.kdop;
    Json list = Json::array();
    for (const NodeProxy& np : proxies) list.push_back(proxy_json(np, node_name(np.node)));
    doc["proxies"] = list;
    if (!a.output.empty()) doc["output"] = a.output;
    std::printf("%s\n", doc.dump(2).c_str());
  } else {
    for (const NodeProxy& np : proxies) {
      const ProxyTightness& t = np.tightness;
      std::printf("node %d '%s' (%s vertices): %s %s\n  volume %.6g%s%s, Hausdorff %.4g (%llu samples)\n",
                  np.node, node_name(np.node).c_str(), human_count(np.vertices).c_str(),
                  proxy_kind_name(kind), proxy_text(np).c_str(), t.proxy_volume,
                  ratio_text(t.volume_ratio, "mesh").c_str(), ratio_text(t.hull_ratio, "hull").c_str(),
                  t.hausdorff, (unsigned long long)t.samples);
    }
    if (!a.output.empty()) std::printf("%s\n", a.output.c_str());
  }
  return kExitOk;
}

}  // namespace penumbra::cli
