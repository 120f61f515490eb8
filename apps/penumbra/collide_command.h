// `penumbra collide`: static collision detection over a glTF scene's nodes at its pose, or at
// each frame of a range: the pairs of nodes whose meshes (or fitted proxies) touch or
// interpenetrate, with a contact point and, for proxies, the penetration depth, and the work of
// the broad and narrow phases (renderer/collision/scene_collide.h); with --continuous, also the
// first contacts between consecutive frames of moving rigid nodes, by conservative advancement
// on their proxies (renderer/collision/continuous.h).
#pragma once

#include <optional>
#include <string>

namespace penumbra::cli {

struct CollideArgs {
  std::string scene_file;
  std::string proxy = "mesh";         ///< "mesh" or a proxy_kind_name
  int kdop = 26;                      ///< k of --proxy kdop
  std::optional<std::string> frames;  ///< "A-B[:STEP]" or "N": each at time N / fps
  double fps = 24;
  bool include_children = false;
  bool volumes = false;     ///< each contact's interpenetration volume
  bool continuous = false;  ///< also the first contacts between consecutive frames (proxies)
  bool json = false;
  int scene = -1;
  std::string max_memory;
  bool allow_external = false;
  bool quiet = false;
};

/// Checks the arguments, loads, tests each frame and prints the report (text or --json) on
/// stdout. Returns the exit code; throws UsageError or InputError for bad input.
int run_collide(const CollideArgs& args);

}  // namespace penumbra::cli
