// `penumbra merge`: the EXRs of one render's --crop/--tile parts assembled into the full frame,
// byte for byte, after checking that they belong together (see io/exr_merge.h).
#pragma once

#include <string>
#include <vector>

namespace penumbra::cli {

struct MergeArgs {
  std::vector<std::string> parts;
  std::string output;
  bool force = false;      ///< accept parts without (or with differing) Penumbra metadata
  std::string max_memory;  ///< budget for the decoded frame; empty = half the RAM
};

/// Checks the output path (an .exr in an existing folder, not one of the parts), merges, and
/// prints the output path. Returns the exit code; throws for bad input.
int run_merge(const MergeArgs& args);

}  // namespace penumbra::cli
