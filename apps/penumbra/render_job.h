// One `penumbra render` run as it moves through its phases (check, load, set up, build,
// render, write, report): the request, the scene and its lights, the renderer's configuration,
// the accelerator, the images and the figures the summary and the statistics report.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "apps/penumbra/progress.h"
#include "apps/penumbra/render_options.h"
#include "io/farm/render_settings.h"
#include "io/gltf/loader.h"
#include "renderer/integrators/render.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"

namespace penumbra::cli {

/// The SHA-256 of each image as written, when --stats-json asks for them.
struct WrittenHashes {
  std::string exr, png, cost_png;
};

struct RenderJob {
  explicit RenderJob(const RenderArgs& a)
      : args(a),
        progress(progress_mode(a.progress, a.quiet)),
        frame(a.frame ? std::optional<int64_t>(std::stoll(*a.frame)) : std::nullopt) {}
  const RenderArgs& args;
  ProgressMode progress;         ///< how the phases report on stderr
  std::optional<int64_t> frame;  ///< --frame's number (checked before), for the JSON progress lines
  RenderRequest request;
  LoadedScene loaded;
  RenderConfig cfg;
  Camera camera;
  Environment environment;
  AreaLights area_lights;
  bool default_light = false;  ///< the scene had no light: the default key light was added
  RenderSettings settings;     ///< what decides the pixels (path renders and windows only)
  std::string scene_sha256;    ///< over every file the scene loaded (path renders and windows)
  std::unique_ptr<Accelerator> accel;
  double accel_built_sah = 0;  ///< the accelerator's SAH cost when last built (the refit policy's base)
  /// How this frame's accelerator came to be: "built", "reused" or "instances moved" (from the
  /// previous frame), "refitted" or "rebuilt" (the previous frame's, to moved vertices).
  std::string accel_update = "built";
  double load_s = 0, build_s = 0, write_s = 0;
  RenderStats stats;
  Film film;
  PathImage path_image;  ///< path tracer only; its film is moved into `film`
  int interrupted = 0;   ///< the signal that ended a path render early, or 0
  bool frame_complete = true;
  bool remove_state = false;  ///< a completed --checkpoint/--resume render: drop OUT.exr.resume once written
  double mean_spp = 0;
  WrittenHashes hashes;

  PathLights path_lights() const { return {&area_lights, &environment}; }
};

}  // namespace penumbra::cli
