// The path tracer's run with its interruptions: SIGINT/SIGTERM handling (the first signal ends
// the render after the current pass, a second one or a signal outside a path render ends the
// process at once with its temporaries removed), periodic checkpoints (image and resume state,
// atomically), --resume from the state beside the output, and what is left beside it after.
#pragma once

namespace penumbra::cli {

struct RenderJob;
class ProgressReporter;

/// Installs the handlers: SIGINT, SIGTERM, SIGHUP and SIGQUIT as above; SIGPIPE ignored (a
/// closed pipe becomes a write error). Call once before loading.
void install_signal_handlers();

/// Renders job.prepared with the path tracer (render_image) into job.image, resuming from
/// and checkpointing to `OUT.exr.resume` as the flags ask. Sets job.interrupted to the signal
/// that ended it (0 if none) and job.frame_complete. Throws InputError for a resume state that
/// is damaged or belongs to another render (nothing is written then).
void run_path_render(RenderJob& job, ProgressReporter& progress);

}  // namespace penumbra::cli
