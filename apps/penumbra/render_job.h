// One `penumbra render` run as it moves through its phases (check, load, set up, build,
// render, write, report): the request, the scene and its lights, the renderer's configuration,
// the render session's phases' values (prepared render, structure, image) and the figures the
// summary and the statistics report.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "apps/penumbra/progress.h"
#include "apps/penumbra/render_options.h"
#include "io/farm/render_settings.h"
#include "io/gltf/loader.h"
#include "render/session.h"
#include "renderer/integrators/render.h"

namespace penumbra::cli {

/// The SHA-256 of each image as written, when --stats-json asks for them.
struct WrittenHashes {
  std::string exr, png, cost_png, deep;
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
  PreparedRender prepared;   ///< the session's prepared render: settings resolved, camera, lights, identity
  std::string scene_sha256;  ///< over every file the scene loaded
  Structure structure;       ///< the acceleration structure and how this frame's came to be
  double load_s = 0, build_s = 0, write_s = 0;
  double deep_s = 0, deep_write_s = 0;  ///< --deep: tracing the deep samples; writing the deep EXR
  uint64_t deep_samples = 0;            ///< --deep: the deep image's samples
  RenderImage image;                    ///< the beauty, the path tracer's layers and the statistics
  int interrupted = 0;                  ///< the signal that ended a path render early, or 0
  bool frame_complete = true;
  bool remove_state = false;  ///< a completed --checkpoint/--resume render: drop OUT.exr.resume once written
  double mean_spp = 0;
  uint64_t bytes_left = UINT64_MAX;  ///< of the --max-memory budget, once the image and scene are charged
  WrittenHashes hashes;
};

}  // namespace penumbra::cli
