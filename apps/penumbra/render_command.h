// `penumbra render`: checks the flags, loads the scene, sets up the camera, configuration,
// lights and memory budget, builds the accelerator, renders (or replays --debug-pixel), writes
// the EXR, display image, heat map and statistics, and reports.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "apps/penumbra/render_options.h"

namespace penumbra::cli {

/// Runs one render. Returns the exit code (0, or 128 + signal after an interrupt); throws
/// UsageError / InputError for bad input and std::runtime_error for failed writes.
int run_render(const RenderArgs& args);

/// The checks run_render makes before it loads anything (every frame's flags and outputs, no
/// file written by two frames); returns every file the run would write, named by its option.
/// Throws UsageError / InputError as run_render does.
std::vector<std::pair<std::string, std::filesystem::path>> check_render(const RenderArgs& args);

/// The frame patterns of `args` without planning its frames: a --frames range (or a
/// turntable's) needs a run of '#' in every output path; a '#' without a range needs --frame.
/// Throws UsageError. Returns 0.
int check_frame_patterns(const RenderArgs& args);

}  // namespace penumbra::cli
