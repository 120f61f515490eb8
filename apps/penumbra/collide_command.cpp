// `penumbra collide`.
#include "apps/penumbra/collide_command.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/scene_setup.h"
#include "io/farm/frame_outputs.h"
#include "io/files/error.h"
#include "renderer/collision/continuous.h"
#include "renderer/collision/scene_collide.h"

namespace penumbra::cli {

namespace {

using Json = nlohmann::ordered_json;

/// Bytes held per placed vertex while testing: double copies, trees or proxies.
constexpr uint64_t kBytesPerVertex = 256;
/// --volumes on meshes: bytes per placed triangle of the solids (BSP nodes and fragments, BVH).
constexpr uint64_t kSolidBytesPerTriangle = 512;
/// --volumes: bytes per cell of the quadrature (two levels held at a time).
constexpr uint64_t kBytesPerCell = 50;
/// --continuous on meshes: bytes per placed triangle of the swept trees and the start's
/// contact trees (boxes, corners, order).
constexpr uint64_t kSweptBytesPerTriangle = 192;

Json dvec(DVec3 v) {
  return Json::array({v.x, v.y, v.z});
}

std::string node_name(const GltfInfo& info, int node) {
  return size_t(node) < info.node_names.size() ? info.node_names[size_t(node)] : std::string();
}

Json frame_json(const CollideReport& r, const GltfInfo& info, std::optional<int64_t> frame, double time,
                bool volumes) {
  Json j;
  j["frame"] = frame ? Json(*frame) : Json();
  j["time"] = frame ? Json(time) : Json();  // null: the file's static pose
  j["nodes"] = r.nodes;
  j["broad_pairs"] = r.broad_pairs;
  j["family_pairs"] = r.family_pairs;
  j["narrow_tests"] = r.narrow_tests;
  j["triangle_tests"] = r.triangle_tests;
  Json list = Json::array();
  for (const NodeContact& c : r.contacts) {
    Json e;
    e["a"] = c.a;
    e["a_name"] = node_name(info, c.a);
    e["b"] = c.b;
    e["b_name"] = node_name(info, c.b);
    e["point"] = dvec(c.point);
    e["depth"] = std::isfinite(c.depth) ? Json(c.depth) : Json();
    e["depth_error"] = std::isfinite(c.depth) ? Json(c.depth_error) : Json();
    e["shape_error"] = c.shape_error;
    e["direction"] = std::isfinite(c.depth) ? dvec(c.direction) : Json();
    e["triangle_pairs"] = c.triangle_pairs;
    if (volumes) {
      e["volume"] = c.volume.volume;
      e["volume_error"] = c.volume.error;
      e["volume_exact"] = c.volume.exact;
    }
    list.push_back(e);
  }
  j["contacts"] = list;
  return j;
}

void print_frame(const CollideReport& r, const GltfInfo& info, std::optional<int64_t> frame, double time,
                 bool volumes) {
  if (frame) std::printf("frame %lld (time %.6g s): ", (long long)*frame, time);
  std::printf(
      "%llu nodes, broad phase %llu pairs (%llu joined by the hierarchy or a skin, left out), narrow phase "
      "%llu "
      "tests, %zu contact%s\n",
      (unsigned long long)r.nodes, (unsigned long long)r.broad_pairs, (unsigned long long)r.family_pairs,
      (unsigned long long)r.narrow_tests, r.contacts.size(), r.contacts.size() == 1 ? "" : "s");
  for (const NodeContact& c : r.contacts) {
    std::printf("  '%s' (%d) and '%s' (%d) at (%.6g, %.6g, %.6g)", node_name(info, c.a).c_str(), c.a,
                node_name(info, c.b).c_str(), c.b, c.point.x, c.point.y, c.point.z);
    if (std::isfinite(c.depth)) std::printf(", depth %.6g", c.depth);
    if (std::isfinite(c.depth) && c.depth_error > 0) std::printf(" (+ at most %.2g)", c.depth_error);
    // Meshes: an open mesh's depth is NaN, a closed one's has its sample spacing.
    if (!std::isfinite(c.depth) || c.depth_error > 0)
      std::printf(", %llu triangle pairs", (unsigned long long)c.triangle_pairs);
    if (volumes && c.volume.exact)
      std::printf(", volume %.6g (exact)", c.volume.volume);
    else if (volumes)
      std::printf(", volume %.6g +- %.2g", c.volume.volume, c.volume.error);
    std::printf("\n");
  }
}

Json node_list(const std::vector<int>& nodes, const GltfInfo& info) {
  Json list = Json::array();
  for (int n : nodes) list.push_back(Json{{"node", n}, {"name", node_name(info, n)}});
  return list;
}

// The first contacts between frame `from` (time t0) and the next sampled frame `to` (time t1).
Json swept_json(const ContinuousReport& r, const GltfInfo& info, int64_t to, double t0, double t1,
                bool mesh) {
  Json j;
  j["to_frame"] = to;
  j["to_time"] = t1;
  j["nodes"] = r.nodes;
  j["moving_nodes"] = r.moving_nodes;
  j["nonrigid_nodes"] = node_list(r.nonrigid_nodes, info);
  j["broad_pairs"] = r.broad_pairs;
  j["family_pairs"] = r.family_pairs;
  j["narrow_tests"] = r.narrow_tests;
  j[mesh ? "triangle_pairs" : "advancement_steps"] = r.steps;
  auto contacts = [&](const std::vector<SweptContact>& from, bool touching) {
    Json list = Json::array();
    for (const SweptContact& c : from) {
      Json e;
      e["a"] = c.a;
      e["a_name"] = node_name(info, c.a);
      e["b"] = c.b;
      e["b_name"] = node_name(info, c.b);
      e["time"] = t0 + c.u * (t1 - t0);  // undecided: no contact before it
      e["fraction"] = c.u;
      if (touching) {
        e["point"] = dvec(c.point);
        e["normal"] = dvec(c.normal);
      }
      list.push_back(e);
    }
    return list;
  };
  j["contacts"] = contacts(r.contacts, true);
  j["undecided"] = contacts(r.undecided, false);
  return j;
}

void print_swept(const ContinuousReport& r, const GltfInfo& info, int64_t to, double t0, double t1,
                 bool mesh) {
  std::printf(
      "  swept to frame %lld: %llu nodes (%llu moving, %zu %s, left out), broad phase %llu pairs (%llu "
      "joined "
      "by the hierarchy or a skin, left out), %llu %s %llu %s, %zu first contact%s\n",
      (long long)to, (unsigned long long)r.nodes, (unsigned long long)r.moving_nodes, r.nonrigid_nodes.size(),
      mesh ? "changing their triangles" : "not rigid", (unsigned long long)r.broad_pairs,
      (unsigned long long)r.family_pairs, (unsigned long long)r.narrow_tests,
      mesh ? "swept over" : "advanced in", (unsigned long long)r.steps, mesh ? "triangle pairs" : "steps",
      r.contacts.size(), r.contacts.size() == 1 ? "" : "s");
  for (int n : r.nonrigid_nodes)
    std::printf("    '%s' (%d) %s\n", node_name(info, n).c_str(), n,
                mesh ? "changes its triangles between the frames" : "does not move rigidly");
  for (const SweptContact& c : r.contacts)
    std::printf(
        "    '%s' (%d) and '%s' (%d) first touch at time %.9g s (%.6g of the way) at (%.6g, %.6g, %.6g)\n",
        node_name(info, c.a).c_str(), c.a, node_name(info, c.b).c_str(), c.b, t0 + c.u * (t1 - t0), c.u,
        c.point.x, c.point.y, c.point.z);
  for (const SweptContact& c : r.undecided)
    std::printf(
        "    '%s' (%d) and '%s' (%d) undecided: no contact before time %.9g s, the %s budget ran out\n",
        node_name(info, c.a).c_str(), c.a, node_name(info, c.b).c_str(), c.b, t0 + c.u * (t1 - t0),
        mesh ? "triangle-pair" : "step");
}

}  // namespace

int run_collide(const CollideArgs& a) {
  CollideConfig config;
  config.include_children = a.include_children;
  if (a.proxy != "mesh") {
    config.mesh = false;
    if (!parse_proxy_kind(a.proxy, config.kind)) {
      std::string names = "mesh";
      for (int i = 0; i < kProxyKindCount; ++i) names += std::string(", ") + proxy_kind_name(ProxyKind(i));
      throw UsageError("--proxy " + a.proxy + ": not mesh or a proxy kind (" + names + ")");
    }
  }
  if (a.kdop != 6 && a.kdop != 14 && a.kdop != 18 && a.kdop != 26)
    throw UsageError("--kdop " + std::to_string(a.kdop) + ": k must be 6, 14, 18 or 26");
  config.fit.kdop = a.kdop;
  config.volumes = a.volumes;
  if (!(std::isfinite(a.fps) && a.fps > 0)) throw UsageError("--fps must be a finite number > 0");
  std::optional<FrameRange> range;
  if (a.frames) {
    try {
      range = parse_frame_range(*a.frames);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  if (a.continuous) {
    if (!range || range->last - range->first < range->step)
      throw UsageError("--continuous needs --frames with two frames or more (A-B or A-B:STEP)");
  }
  const uint64_t budget = memory_budget(a.max_memory);
  std::optional<double> first_time;
  if (range) first_time = double(range->first) / a.fps;
  set_phase("loading the scene");
  LoadedScene loaded = load_scene(a.scene_file, a.scene, a.allow_external, false, budget, a.quiet, first_time,
                                  range.has_value());
  const ShapeTrianglesCount count = placed_geometry_count(loaded.scene);
  const uint64_t placed = count.vertices, triangles = count.triangles;
  // --continuous holds the previous frame's pose as well.
  const uint64_t scene_bytes = scene_memory_bytes(loaded.scene) * (a.continuous ? 2 : 1);
  uint64_t testing = placed * kBytesPerVertex;
  if (a.volumes)
    testing +=
        config.volume.max_cells * kBytesPerCell + (config.mesh ? triangles * kSolidBytesPerTriangle : 0);
  if (a.continuous && config.mesh) testing += triangles * kSweptBytesPerTriangle;
  if (testing > budget - std::min(budget, scene_bytes))
    throw UsageError(a.scene_file + ": testing " + human_count(placed) + " placed vertices needs " +
                     human_count(testing) + "B beside the scene, over the budget (--max-memory)");

  Json frames = Json::array();
  auto run_frame = [&](std::optional<int64_t> frame, double time) {
    set_phase("testing for collisions");
    CollideReport report;
    try {
      report = collide_scene(loaded.scene, {loaded.info.node_parents, loaded.info.node_skin_joints}, config);
    } catch (const std::invalid_argument& e) {
      throw InputError(a.scene_file, "", e.what());
    }
    if (a.json)
      frames.push_back(frame_json(report, loaded.info, frame, time, a.volumes));
    else
      print_frame(report, loaded.info, frame, time, a.volumes);
  };
  if (!range) {
    run_frame(std::nullopt, 0);
  } else {
    std::optional<Scene> previous;  // --continuous: the last frame's pose
    for (int64_t f = range->first; f <= range->last; f += range->step) {
      const double t = double(f) / a.fps;
      if (a.continuous && f != range->first) previous = loaded.scene;
      if (f != range->first && loaded.info.animation_count != 0) {
        set_phase("posing the scene");
        if (!loaded.animation || !pose_gltf_scene(*loaded.animation, t, loaded.scene))
          loaded = load_scene(a.scene_file, a.scene, a.allow_external, false, budget, true, t, true);
      }
      if (previous) {
        set_phase("advancing moving nodes");
        const double t0 = double(f - range->step) / a.fps;
        ContinuousReport swept;
        try {
          swept = collide_continuous(*previous, loaded.scene,
                                     {loaded.info.node_parents, loaded.info.node_skin_joints}, config);
        } catch (const std::invalid_argument& e) {
          throw InputError(a.scene_file, "", e.what());
        }
        if (a.json)
          frames.back()["continuous"] = swept_json(swept, loaded.info, f, t0, t, config.mesh);
        else
          print_swept(swept, loaded.info, f, t0, t, config.mesh);
      }
      run_frame(f, t);
    }
    if (a.continuous && a.json) frames.back()["continuous"] = nullptr;  // no next frame
  }
  if (a.json) {
    Json doc;
    doc["scene"] = a.scene_file;
    doc["proxy"] = a.proxy;
    if (config.kind == ProxyKind::Kdop && !config.mesh) doc["k"] = a.kdop;
    doc["include_children"] = a.include_children;
    doc["volumes"] = a.volumes;
    doc["continuous"] = a.continuous;
    doc["frames"] = frames;
    std::printf("%s\n", doc.dump(2).c_str());
  }
  return kExitOk;
}

}  // namespace penumbra::cli
