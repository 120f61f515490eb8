// The phases of `penumbra render`.
#include "apps/penumbra/render_command.h"

#include <cstdio>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/exr_layers.h"
#include "apps/penumbra/path_render.h"
#include "apps/penumbra/progress.h"
#include "apps/penumbra/render_identity.h"
#include "apps/penumbra/render_job.h"
#include "apps/penumbra/scene_setup.h"
#include "apps/penumbra/stats_json.h"
#include "io/atomic_file.h"
#include "io/environment_io.h"
#include "io/file_checks.h"
#include "io/hash.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/scene_accel.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// Bytes an acceleration structure needs per stored triangle, for the budget before it is built
/// (Embree's and the own BVH's nodes, references and triangle copies stay below this).
constexpr uint64_t kAccelBytesPerTriangle = 96;

/// Bytes per rendered pixel of every buffer a render keeps until its outputs are written: the
/// film (RGBA float), the path tracer's accumulators and statistics, light groups (double sums
/// and float means), data AOVs (14 floats), cost AOVs (3 floats), the EXR's packed channels
/// (4 bytes each, twice with --multipart) and the display image (float RGB and its encoding).
uint64_t image_bytes_per_pixel(const RenderRequest& q, bool multipart) {
  const bool light_groups = q.aovs.count("light") > 0;
  uint64_t b = 16;
  if (q.path) b += kPathPixelBytes + 4 + 4;
  if (light_groups) b += kLightGroupChannels * (8 + 4);
  if (q.data_aovs) b += 14 * 4;
  if (q.cost_aov) b += 3 * 4 + 3;
  if (q.aovs.count("samples")) b += 4;  // the counts as floats for the EXR
  const uint64_t channels = 4 + (q.data_aovs ? 14 : 0) + (light_groups ? kLightGroupChannels : 0) +
                            (q.cost_aov ? 3 : 0) + (q.aovs.empty() ? 0 : 2);
  b += channels * 4 * (multipart ? 2 : 1);  // packed channels; --multipart also repacks them per part
  if (q.png) b += 12 + 3;
  return b;
}

/// Charges the scene, the accelerator and every image buffer to the budget; returns the bytes
/// taken. Throws UsageError (exit 2) naming the image when they do not fit.
uint64_t charge_image_budget(const RenderJob& job) {
  const RenderConfig& cfg = job.cfg;
  const uint64_t budget = job.request.budget;
  const PixelWindow w = render_window(cfg);
  const uint64_t image =
      uint64_t(w.width()) * uint64_t(w.height()) * image_bytes_per_pixel(job.request, job.args.multipart);
  const Scene& scene = job.loaded.scene;
  const uint64_t scene_bytes =
      scene_memory_bytes(scene) + count_stored_triangles(scene) * kAccelBytesPerTriangle;
  if (image > budget || scene_bytes > budget - image)
    throw UsageError("image " + std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " (" +
                     job.args.integrator + (job.request.aovs.empty() ? "" : ", with AOVs") + ") needs " +
                     format_bytes(image) + " for the film and output buffers, over the " +
                     format_bytes(budget) + " budget with the rest of the scene (" +
                     format_bytes(scene_bytes) + ") (--max-memory)");
  return image + scene_bytes;
}

void load_phase(RenderJob& job) {
  const RenderArgs& a = job.args;
  set_phase("loading the scene");
  const auto t0 = Clock::now();
  job.loaded = load_scene(a.scene_file, a.scene, a.allow_external, a.flatten, job.request.budget, a.quiet,
                          job.request.time);
  job.load_s = seconds_since(t0);
  // No output may replace a buffer or image the scene was loaded from.
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (const auto& f : job.loaded.info.source_files) inputs.push_back({"the scene's file", f});
  check_distinct_files(job.request.outputs, inputs);
}

/// Camera and resolution (the image aspect follows the camera's hint unless both are given),
/// the budget, the path tracer's lights, the default light, and the render's identity.
void setup_phase(RenderJob& job) {
  const RenderArgs& a = job.args;
  const RenderRequest& q = job.request;
  Scene& scene = job.loaded.scene;
  const int cam =
      a.camera.empty() ? (scene.cameras.empty() ? -1 : 0) : find_camera(scene, a.camera, a.scene_file);
  const float hint =
      cam >= 0 && scene.cameras[size_t(cam)].aspect > 0 ? scene.cameras[size_t(cam)].aspect : 16.0f / 9.0f;
  job.cfg = make_render_config(a, q, hint);
  RenderConfig& cfg = job.cfg;
  validate(cfg);  // the library's own range checks, after the command line's named ones
  const uint64_t committed = charge_image_budget(job);
  if (!cfg.window.empty() && q.cost_aov)
    throw UsageError("--aov cost renders the whole frame; not with --crop or --tile");
  job.camera = cam >= 0 ? scene.cameras[size_t(cam)]
                        : frame_bounds(compute_bounds(scene), float(cfg.width) / float(cfg.height));
  // The path tracer's lights: emissive triangles and the environment.
  if (q.env_colour)
    job.environment = make_constant_environment(*q.env_colour * a.env_intensity);
  else if (!a.env.empty())
    job.environment = load_environment(a.env, a.env_intensity, a.env_rotation, q.budget - committed);
  if (q.path) job.area_lights = build_area_lights(scene);
  if (scene.lights.empty() && (!q.path || (job.area_lights.pmf.empty() && is_black(job.environment)))) {
    scene.lights.push_back(default_key_light(job.camera));
    job.default_light = true;
  }
  // What this render is, for its resume state and the metadata of crops and tiles: the content
  // of every file it loaded and every setting that decides its pixels.
  if (q.path || !cfg.window.empty()) {
    // The bytes as the loader read them, not the files as they are now.
    job.scene_sha256 = sha256_of_set(job.loaded.info.source_files, job.loaded.info.source_sha256);
    job.settings = pixel_settings(a, cfg, job.camera, job.scene_sha256,
                                  !a.env.empty() && !q.env_colour ? sha256_file(a.env) : "");
  }
}

void build_phase(RenderJob& job) {
  set_phase("building the acceleration structure");
  const auto t0 = Clock::now();
  job.accel = make_scene_accelerator(job.args.accel, job.loaded.scene, job.request.accel_config);
  job.build_s = seconds_since(t0);
}

/// --debug-pixel: one pixel exactly as the full render would compute it, printed on stdout.
int render_debug_pixel(RenderJob& job) {
  const RenderRequest& q = job.request;
  const RenderConfig& cfg = job.cfg;
  if (q.debug_x < 0 || q.debug_y < 0 || q.debug_x >= cfg.width || q.debug_y >= cfg.height)
    throw UsageError("--debug-pixel " + job.args.debug_pixel + " is outside the " +
                     std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " image");
  float rgba[4];
  RayCounts counts;
  if (q.path)
    render_path_pixel(job.loaded.scene, *job.accel, job.path_lights(), job.camera, cfg, q.debug_x, q.debug_y,
                      rgba, counts);
  else
    render_whitted_pixel(job.loaded.scene, *job.accel, job.camera, cfg, q.debug_x, q.debug_y, rgba, counts);
  std::printf("pixel %d,%d: R %.6g G %.6g B %.6g A %.6g (rays: camera %llu, shadow %llu, %s %llu)\n",
              q.debug_x, q.debug_y, rgba[0], rgba[1], rgba[2], rgba[3],
              static_cast<unsigned long long>(counts.camera), static_cast<unsigned long long>(counts.shadow),
              q.path ? "bounce" : "reflection", static_cast<unsigned long long>(counts.reflection));
  return kExitOk;
}

void render_phase(RenderJob& job) {
  set_phase("rendering");
  ProgressReporter reporter(!job.args.quiet);
  if (job.request.path)
    run_path_render(job, reporter);
  else
    job.film = render_whitted(job.loaded.scene, *job.accel, job.camera, job.cfg, &job.stats,
                              [&](int d, int t) { reporter(d, t); });
  reporter.finish();
  job.mean_spp = double(job.stats.samples) / (double(job.film.width) * double(job.film.height));
}

/// The EXR with its layers, the display image, the heat map, then the statistics that record
/// their hashes.
void write_phase(RenderJob& job) {
  const RenderRequest& q = job.request;
  const auto t0 = Clock::now();
  LayerBuffers buffers;
  render_layer_buffers(job, buffers);
  const ExrOptions exr = make_exr_options(job, buffers);
  set_phase("writing the outputs");
  const bool hashes = !job.args.stats_json.empty();
  write_exr(job.film, q.out, exr, hashes ? &job.hashes.exr : nullptr);
  if (q.png) write_display_image(job.film, *q.png, q.display, hashes ? &job.hashes.png : nullptr);
  if (q.cost_png)
    write_heatmap(total_cost(buffers.cost), job.cfg.width, job.cfg.height, *q.cost_png,
                  cost_caption(buffers.cost, job.args.accel), hashes ? &job.hashes.cost_png : nullptr);
  job.write_s = seconds_since(t0);
  if (hashes) write_stats_json(job);
}

}  // namespace

int run_render(const RenderArgs& a) {
  RenderJob job(a);
  job.request = check_render_args(a);  // everything typed is checked before loading
  install_signal_handlers();
  load_phase(job);
  setup_phase(job);
  build_phase(job);
  if (!a.debug_pixel.empty()) return render_debug_pixel(job);
  render_phase(job);
  write_phase(job);
  if (job.remove_state) fs::remove(fs::path(job.request.out).concat(".resume"));
  if (!a.quiet) print_render_summary(job);
  const RenderRequest& q = job.request;
  if (q.paths_to_stdout) {
    std::printf("%s\n", q.out.string().c_str());
    if (q.png) std::printf("%s\n", q.png->string().c_str());
    if (q.cost_png) std::printf("%s\n", q.cost_png->string().c_str());
  }
  if (!job.interrupted) return kExitOk;
  if (job.frame_complete)
    std::fprintf(stderr, "penumbra: interrupted by signal %d during the last pass: the image is complete\n",
                 job.interrupted);
  else
    std::fprintf(
        stderr,
        "penumbra: interrupted by signal %d after %d passes (%.2f spp): the image holds the finished passes; "
        "continue with the same command and --resume\n",
        job.interrupted, job.stats.passes, job.mean_spp);
  return 128 + job.interrupted;
}

}  // namespace penumbra::cli
