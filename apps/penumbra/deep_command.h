// `penumbra deep`: the compositing operations on deep EXRs (renderer/film/deep.h), for renders
// made with `render --deep`: `flatten` (the flat image the samples composite to), `merge`
// (elements rendered apart, as one deep image) and `holdout` (an element's part of the merge,
// flat, as Nuke's DeepHoldout gives it).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace penumbra::cli {

struct DeepArgs {
  std::vector<std::string> inputs;  ///< flatten and holdout: one; merge: two or more
  std::string by;                   ///< holdout: the deep EXR held out
  std::string output;
  std::string max_memory;  ///< budget for the inputs' samples and the result; empty = half the RAM
};

/// The three operations as subcommands of `deep`, bound to `args`.
struct DeepCommands {
  CLI::App* deep = nullptr;
  CLI::App* flatten = nullptr;
  CLI::App* merge = nullptr;
  CLI::App* holdout = nullptr;
};
DeepCommands add_deep_command(CLI::App& app, DeepArgs& args);

/// Runs the chosen operation: reads the inputs (read_deep_exr: every channel Penumbra writes, samples
/// sorted front to back; merge and holdout also same windows and hard surfaces), writes the
/// output atomically and prints its path. Throws UsageError or InputError (exit 2) naming the
/// file for bad input.
int run_deep(const DeepCommands& commands, const DeepArgs& args);

}  // namespace penumbra::cli
