// `penumbra merge`: the EXRs of one render's --crop/--tile parts assembled into the full frame,
// byte for byte, after checking that they belong together (see io/exr_merge.h); and
// `penumbra denoise`: an EXR with the halves layers denoised (io/image/exr_denoise.h).
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

struct DenoiseArgs {
  std::string input, output;
  std::string denoise_main = "denoised";  ///< the main layer: denoised or noisy
  int threads = 0;                        ///< 0: every hardware thread (does not change pixels)
  std::string max_memory;                 ///< budget; empty = half the RAM
  std::string progress = "auto";          ///< progress_modes()
  bool quiet = false;
};

/// `penumbra denoise IN -o OUT`: checks the paths (an .exr output, not the input), denoises
/// (io/image/exr_denoise.h) with progress, and prints the output path.
int run_denoise(const DenoiseArgs& args);

}  // namespace penumbra::cli
