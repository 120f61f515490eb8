// `penumbra render`: checks the flags, loads the scene, sets up the camera, configuration,
// lights and memory budget, builds the accelerator, renders (or replays --debug-pixel), writes
// the EXR, display image, heat map and statistics, and reports.
#pragma once

#include "apps/penumbra/render_options.h"

namespace penumbra::cli {

/// Runs one render. Returns the exit code (0, or 128 + signal after an interrupt); throws
/// UsageError / InputError for bad input and std::runtime_error for failed writes.
int run_render(const RenderArgs& args);

}  // namespace penumbra::cli
