// What `penumbra render` tells a person on stderr: a progress line while rendering (updated in
// place on a terminal, one line per 10% in logs) and the summary of a finished run.
#pragma once

#include <mutex>

#include "apps/penumbra/cli_support.h"

namespace penumbra::cli {

struct RenderJob;

/// Progress on stderr: a self-overwriting line on a terminal, or a line per 10% in logs.
class ProgressReporter {
 public:
  explicit ProgressReporter(bool enabled);
  void operator()(int done, int total);
  /// Ends a terminal progress line left open by a render that stopped early (--time-limit,
  /// --adaptive), so the summary starts on its own line.
  void finish();

 private:
  bool m_enabled, m_tty, m_open = false;
  std::mutex m_mutex;
  Clock::time_point m_start = Clock::now();
  double m_last = -1;
  int m_last_decile = 0;
};

/// The run's summary: scene, camera, image settings, times per phase, rays and peak memory.
void print_render_summary(const RenderJob& job);

}  // namespace penumbra::cli
