// What `penumbra render` tells a person or a farm's tooling on stderr: the line announcing the
// load and the build, a progress line while rendering (updated in place on a terminal, one line
// per 10% in logs) or, with --progress json, one JSON object per line for every phase, and the
// summary of a finished run.
#pragma once

#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "apps/penumbra/cli_support.h"
#include "render/session.h"

namespace penumbra::cli {

/// What the summary and the statistics file report of one finished render: the session's
/// values and the command's timings, by reference (they outlive the report).
struct RenderReport {
  const std::string& scene_file;
  const Scene& scene;                   ///< as rendered (with the default key light, if one was added)
  const PreparedRender& prepared;       ///< resolved settings, config, camera
  const RenderImage& image;             ///< film and statistics
  const std::string& structure_update;  ///< Structure::update
  bool traced = true;                   ///< an acceleration structure was built or kept
  double load_s = 0, build_s = 0, write_s = 0;
  bool deep = false;                    ///< a deep image was written
  double deep_s = 0, deep_write_s = 0;  ///< tracing its samples; writing it (part of write_s)
  uint64_t deep_samples = 0;
  double mean_spp = 0;
  bool interrupted = false;
};

/// How progress is reported on stderr (--progress).
enum class ProgressMode {
  Auto,  ///< a self-overwriting line on a terminal, one line per 10% otherwise
  Text,  ///< one line per 10%, on a terminal too
  Json,  ///< one JSON object per line (ProgressReporter); no summary, warnings as JSON objects
  None,  ///< no progress lines
};

/// The names --progress accepts, in order: auto, text, json, none.
const std::vector<std::string>& progress_modes();

/// The help text of --progress.
std::string progress_option_help();

/// The mode `name` (one of progress_modes()) gives: "auto" is None under -q (`quiet`), an
/// explicit mode is kept under -q.
ProgressMode progress_mode(const std::string& name, bool quiet);

/// True when human-readable lines (announcements, summaries, skip notes) go to stderr: not
/// under -q, and not with JSON progress.
inline bool prints_text(ProgressMode mode, bool quiet) {
  return !quiet && mode != ProgressMode::Json;
}

/// "penumbra: " + `what` + "…" on its own line, in the Auto and Text modes: the step that
/// follows may take seconds ("loading scene.glb", "building bvh (1.20M triangles)").
void announce(ProgressMode mode, const std::string& what);

/// Each warning as {"warning": "FILE: WARNING"} on its own stderr line (up to 20, then a count).
void print_json_warnings(const std::string& file, const std::vector<std::string>& warnings);

/// Progress of one phase on stderr. Json: one object per line,
///   {"phase": "load"|"build"|"render"|"write", "fraction": 0..1, "elapsed": seconds,
///    "eta": seconds or null, "frame": N or null}
/// with a line at fraction 0 when constructed, at most one per 0.25 s while it runs, and one at
/// fraction 1 when it ends (fractions never decrease). Auto and Text: the render line
/// "render  42.0%  elapsed    1.2s  eta    1.7s" (self-overwriting on a terminal in Auto, else
/// one line per 10%); the other phases print nothing here. None: nothing. Safe to call from the
/// renderer's worker threads.
class ProgressReporter {
 public:
  /// `phase` must outlive the reporter (a string literal); `frame`: --frame's number, if any.
  ProgressReporter(ProgressMode mode, const char* phase, std::optional<int64_t> frame = {});
  /// `done` of `total` units (tiles, passes x tiles) finished.
  void operator()(int done, int total);
  /// Ends the phase: the fraction-1 line (Json) if not yet printed, or a terminal progress line
  /// left open by a render that stopped early (--time-limit, --adaptive), so the summary starts
  /// on its own line.
  void finish();

 private:
  void print_json(double fraction, double elapsed);  // with the mutex held

  ProgressMode m_mode;
  const char* m_phase;
  std::optional<int64_t> m_frame;
  bool m_tty, m_open = false, m_done = false;
  std::mutex m_mutex;
  Clock::time_point m_start = Clock::now();
  double m_last = -1;          ///< elapsed seconds at the last line printed
  double m_last_fraction = 0;  ///< the largest fraction printed (Json)
  int m_last_decile = 0;
};

/// The run's summary: scene, camera, image settings, times per phase, rays and peak memory.
void print_render_summary(const RenderReport& report);

}  // namespace penumbra::cli
