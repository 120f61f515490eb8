// Signals, checkpoints and resume around render_path.
#include "apps/penumbra/path_render.h"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include "apps/penumbra/progress.h"
#include "apps/penumbra/render_job.h"
#include "io/farm/checkpoint.h"
#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/image/image_output.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

// While a path render runs, the first SIGINT/SIGTERM asks it to stop after the current pass
// (the finished passes are then written); otherwise, or on a second signal, temporaries are
// removed and the process dies of the signal.
std::atomic<bool> g_graceful{false}, g_stop{false};
std::atomic<int> g_signal{0};

extern "C" void on_signal(int sig) {
  if (g_graceful.load() && !g_stop.load()) {
    g_signal = sig;
    g_stop = true;
    return;
  }
  remove_pending_temporaries();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

/// The resume state's settings: the render's own, plus the window its pixels cover.
RenderSettings state_settings(const RenderJob& job) {
  RenderSettings s = job.prepared.identity;
  const PixelWindow win = render_window(job.prepared.config);
  s.entries["window"] = std::to_string(win.x0) + "," + std::to_string(win.y0) + "-" + std::to_string(win.x1) +
                        "," + std::to_string(win.y1);
  return s;
}

}  // namespace

void install_signal_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::signal(SIGHUP, on_signal);
  std::signal(SIGQUIT, on_signal);
  // A reader that goes away (a closed pipe) is a checked write error (EPIPE), not a death that
  // would leave temporaries behind.
  std::signal(SIGPIPE, SIG_IGN);
}

void run_path_render(RenderJob& job, ProgressReporter& progress) {
  const RenderArgs& a = job.args;
  const fs::path& out = job.request.out;
  const fs::path state_file = fs::path(out).concat(".resume");
  const RenderSettings fingerprint = state_settings(job);
  PathAccumulators state;
  if (a.resume) {
    if (fs::exists(state_file)) {
      state = read_checkpoint(state_file, fingerprint);
      const PixelWindow win = render_window(job.prepared.config);
      if (state.window.x0 != win.x0 || state.window.y0 != win.y0 || state.window.x1 != win.x1 ||
          state.window.y1 != win.y1)
        throw InputError(state_file.string(), "", "its pixels cover another window than this render's");
      if (prints_text(job.progress, a.quiet))
        std::fprintf(stderr, "penumbra: resuming %s: %d passes done, %u spp reached\n",
                     state_file.string().c_str(), state.passes, state.reached);
    } else if (prints_text(job.progress, a.quiet)) {
      std::fprintf(stderr, "penumbra: no checkpoint at %s: starting from the beginning\n",
                   state_file.string().c_str());
    }
  }
  auto last_checkpoint = Clock::now();
  const PassFn after_pass = [&](const PathAccumulators& st) {
    if (!(a.checkpoint > 0) || st.complete || seconds_since(last_checkpoint) < a.checkpoint) return;
    ExrOptions cp;
    cp.half = !a.use_float;
    cp.compression = a.compression;
    cp.metadata = {{"penumbra:scene", a.scene_file},
                   {"penumbra:checkpoint", "passes " + std::to_string(st.passes)}};
    write_exr(resolve_path_image(st, job.prepared.config).film, out, cp);
    write_checkpoint(state_file, st, fingerprint);
    last_checkpoint = Clock::now();
  };
  RenderHooks hooks;
  hooks.progress = [&](int d, int t) { progress(d, t); };
  hooks.resume = &state;
  hooks.after_pass = after_pass;
  hooks.stop = &g_stop;
  g_graceful = true;
  job.image = render_image(job.loaded.scene, job.structure.accel.get(), job.prepared, hooks);
  g_graceful = false;
  // A signal during the last pass still ends the run with 128 + signal, the image complete.
  if (g_stop.load()) job.interrupted = g_signal.load();
  job.frame_complete = state.complete;
  if (!job.request.state_beside_output) return;  // no resume state beside a stream or device
  // Interrupted with --deep, even in the last pass: the deep image is traced once --resume (or a
  // job's unit) continues from the state.
  if (job.interrupted && (!state.complete || job.request.deep)) {
    write_checkpoint(state_file, state, fingerprint);
  } else if (state.complete) {
    // Removed only after the outputs are written, so that a failed write can still resume.
    job.remove_state = (a.checkpoint > 0 || a.resume) && fs::exists(state_file);
  } else if (a.checkpoint > 0 || a.resume) {
    write_checkpoint(state_file, state, fingerprint);  // stopped by --time-limit: resumable too
  }
}

}  // namespace penumbra::cli
