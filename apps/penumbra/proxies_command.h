// `penumbra proxies`: bounding proxies (sphere, Ritter sphere, AABB, OBB, capsule, convex hull,
// k-DOP, composite of hulls) fitted to each mesh-placing node of a glTF scene or to one node's
// subtree, with their tightness reported, and optionally written as PENUMBRA_shapes to a
// .gltf/.glb that renders them alone or over the scene (renderer/collision/scene_proxies.h).
#pragma once

#include <optional>
#include <string>

namespace penumbra::cli {

struct ProxiesArgs {
  std::string scene_file;
  std::string kind;                 ///< a proxy_kind_name
  std::optional<std::string> node;  ///< a glTF node index or name: one proxy for its subtree
  std::string output;               ///< .glb or .gltf; empty: report only
  bool overlay = false;             ///< the output keeps the scene's own geometry
  int kdop = 26;                    ///< k of --kind kdop
  int samples = 20000;              ///< surface samples per proxy for the Hausdorff distance
  int threads = 0;
  bool json = false;
  int scene = -1;
  std::string max_memory;
  bool allow_external = false;
  bool quiet = false;
};

/// Checks the arguments and output before loading, fits, prints the report (text or --json) on
/// stdout and writes the output atomically. Returns the exit code; throws UsageError or
/// InputError for bad input (an unknown kind or node, a node placing no mesh, a scene placing
/// none, geometry too large for the budget).
int run_proxies(const ProxiesArgs& args);

}  // namespace penumbra::cli
