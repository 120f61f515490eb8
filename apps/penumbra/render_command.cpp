// The phases of `penumbra render`.
#include "apps/penumbra/render_command.h"

#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/exr_layers.h"
#include "apps/penumbra/path_render.h"
#include "apps/penumbra/progress.h"
#include "apps/penumbra/render_identity.h"
#include "apps/penumbra/render_job.h"
#include "apps/penumbra/scene_setup.h"
#include "apps/penumbra/stats_json.h"
#include "io/farm/frame_outputs.h"
#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/files/hash.h"
#include "io/image/contact_sheet.h"
#include "io/image/deep_exr.h"
#include "io/image/environment_io.h"
#include "io/image/exr_denoise.h"
#include "render/denoise_render.h"
#include "render/motion.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/raster/shadow_map.h"
#include "renderer/raster/splat_raster.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// Bytes an acceleration structure needs per stored triangle, for the budget before it is built
/// (Embree's and the own BVH's nodes, references and triangle copies stay below this).
constexpr uint64_t kAccelBytesPerTriangle = 96;

/// Bytes per rendered pixel of every buffer a render keeps until its outputs are written: the
/// film (RGBA float), the path tracer's accumulators and statistics, light groups (double sums
/// and float means), data AOVs (14 floats), cost AOVs (3 floats), the EXR's packed channels
/// (4 bytes each, twice with --multipart), the display image (float RGB and its encoding) and
/// with --deep one deep sample (the fewest a covered pixel has; the deep pass charges the rest as
/// it finds them).
uint64_t image_bytes_per_pixel(const RenderRequest& q, bool multipart) {
  const bool light_groups = q.aovs.count("light") > 0;
  uint64_t b = 16;
  if (q.path) b += kPathPixelBytes + 4 + 4;
  if (light_groups) b += kLightGroupChannels * (8 + 4);
  if (q.data_aovs) b += 14 * 4;
  if (q.cost_aov) b += 3 * 4 + 3;
  if (q.aovs.count("samples")) b += 4;  // the counts as floats for the EXR
  if (q.aovs.count("halves"))           // odd sums, colour and feature halves, their channels
    b += 4 * 8 + kHalfChannels * 4 + 2 * kDenoiseFeatures * 4 + (kHalfChannels + 2 * kDenoiseFeatures) * 4;
  const uint64_t crypto = q.crypto.size() * 4 * uint64_t((q.crypto_depth + 1) / 2);  // ranked (id, coverage)
  b += crypto * 4;
  const uint64_t channels = 4 + (q.data_aovs ? 14 : 0) + (light_groups ? kLightGroupChannels : 0) +
                            (q.cost_aov ? 3 : 0) + (q.aovs.empty() ? 0 : 2) + crypto;
  b += channels * 4 * (multipart ? 2 : 1);  // packed channels; --multipart also repacks them per part
  if (q.png) b += 12 + 3;
  if (q.deep) b += 4 + 2 * sizeof(DeepSample);  // at least one deep sample a pixel, in its tile and the image
  if (q.spec.wireframe)
    b += sizeof(Hit) + 4 + 4 + 4;  // the centre rays' hits and depths, coverage, its channel
  return b;
}

/// Whether the render denoises its frame itself (--denoise): a whole frame does; a crop or
/// stripe keeps the noisy beauty and the halves, and `penumbra merge` denoises the frame.
bool denoises_now(const RenderConfig& cfg) {
  const PixelWindow w = render_window(cfg);
  return w.x0 == 0 && w.y0 == 0 && w.x1 == cfg.width && w.y1 == cfg.height;
}

/// Charges the scene, the accelerator and every image buffer to the budget; returns the bytes
/// taken. Throws UsageError (exit 2) naming the image when they do not fit.
uint64_t charge_image_budget(const RenderJob& job, const RenderConfig& cfg) {
  const uint64_t budget = job.request.budget;
  const PixelWindow w = render_window(cfg);
  uint64_t image =
      uint64_t(w.width()) * uint64_t(w.height()) * image_bytes_per_pixel(job.request, job.args.multipart);
  // The denoiser runs on the noisy file once it is written (denoise_exr's own estimate); a
  // stripe or crop leaves it to the merge.
  if (job.args.spec.denoise && denoises_now(cfg))
    image += exr_denoise_bytes(w.width(), w.height(), denoise_config(cfg));
  const Scene& scene = job.loaded.scene;
  uint64_t scene_bytes = scene_memory_bytes(scene) + count_stored_triangles(scene) * kAccelBytesPerTriangle +
                         job.loaded.animation_bytes;
  // A point or line set's elements are shapes in the structure: each its Shape copy besides
  // the record a triangle has (Embree: the user geometry's copy).
  for (const Mesh& m : scene.meshes)
    if (m.points || m.lines) scene_bytes += uint64_t(m.indices.size() / 3) * (sizeof(Shape) + 16);
  if (job.request.raster) {
    // The rasteriser's setup triangles and tile buffers, the projected splats, and the shadow maps.
    scene_bytes += raster_memory_bytes(scene, camera_raster_pass(cfg)) + splat_raster_bytes(scene);
    if (cfg.raster.shadows == RasterShadows::Map)
      scene_bytes += shadow_map_bytes(scene, cfg.raster.shadow_map_size);
  }
  if (image > budget || scene_bytes > budget - image)
    throw UsageError("image " + std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " (" +
                     job.request.spec.integrator + (job.request.aovs.empty() ? "" : ", with AOVs") +
                     ") needs " + format_bytes(image) + " for the film and output buffers, over the " +
                     format_bytes(budget) + " budget with the rest of the scene (" +
                     format_bytes(scene_bytes) + ") (--max-memory)");
  return image + scene_bytes;
}

/// A loaded scene and its accelerator, kept from one frame of a range for the next: a scene
/// without animations, whose every frame loads the same geometry, or an animated one, posed at
/// the next frame's time with its accelerator's instances moved (reuse_kept_scene). The
/// accelerator's views point into the scene's vectors, whose storage moves with them.
struct KeptScene {
  LoadedScene loaded;  ///< empty when `reload`
  /// The structure (null accel: built anew for the next frame); its update says what became of
  /// it: "reused" or "instances moved".
  Structure structure;
  /// The next frame loads its scene anew (its animation moves vertices: skins, morph targets)
  /// and the structure is refitted to it or built anew (refit_or_rebuild_scene's policy).
  bool reload = false;
  /// Every frame poses the scene alike (a turntable's frames turn only the camera): reused as is.
  bool same_pose = false;
  double pose_s = 0;    ///< seconds spent posing the scene for the next frame
  double update_s = 0;  ///< seconds spent moving the accelerator's instances
};

/// Readies the kept scene for the frame of `q`: a static scene as it is; an animated one posed
/// at the frame's time (pose_gltf_scene) and its accelerator's instances moved (kept as it is
/// when only cameras and lights move), or dropped to be built anew where they cannot be. Drops
/// the whole scene (the frame loads the file) when the animation changes more than placements.
/// Returns the note for the frame's line. Throws InputError as loading the file at that time
/// would.
std::string reuse_kept_scene(std::optional<KeptScene>& kept, const RenderRequest& q) {
  if (!kept) return "";
  if (kept->same_pose) return " (turntable: loaded scene and acceleration structure reused)";
  if (kept->reload)
    return " (animated vertices: scene loaded anew, acceleration structure refitted or rebuilt)";
  if (!kept->loaded.animation) return " (static scene: loaded scene and acceleration structure reused)";
  const auto t0 = Clock::now();
  uint64_t moved_instances = 0;
  if (!q.time || !pose_gltf_scene(*kept->loaded.animation, *q.time, kept->loaded.scene, &moved_instances)) {
    if (!q.time || !kept->structure.accel) {
      kept.reset();
      return "";
    }
    // Posing moves only placements: the frame loads the file, and the structure is refitted.
    kept->reload = true;
    return " (animated vertices: scene loaded anew, acceleration structure refitted or rebuilt)";
  }
  kept->pose_s = seconds_since(t0);
  if (moved_instances == 0)
    return " (animated scene: loaded scene reused, cameras and lights moved, acceleration structure reused)";
  const auto t1 = Clock::now();
  Structure& s = kept->structure;
  const bool moved = s.accel && s.accel->update_instances(instance_views(kept->loaded.scene));
  if (!moved) s = Structure{};
  s.update = "instances moved";
  kept->update_s = seconds_since(t1);
  return moved ? " (animated scene: loaded scene reused, instances moved, top level rebuilt)"
               : " (animated scene: loaded scene reused, instances moved, acceleration structure rebuilt)";
}

/// The scene: the kept one, else loaded (with what posing it needs when `keep`: a later frame
/// follows).
void load_phase(RenderJob& job, std::optional<KeptScene>& kept, bool keep) {
  const RenderArgs& a = job.args;
  set_phase("loading the scene");
  ProgressReporter progress(job.progress, "load", job.frame);
  const auto t0 = Clock::now();
  if (kept && kept->reload) kept->loaded = LoadedScene{};
  const bool reuse = kept && !kept->reload;
  const double posed_s = reuse ? kept->pose_s : 0;
  if (reuse) {
    job.loaded = std::move(kept->loaded);
  } else {
    announce(job.progress, "loading " + a.scene_file);
    const bool json = job.progress == ProgressMode::Json;
    // Motion blur poses the scene over the shutter: it keeps the file's animation.
    job.loaded =
        load_scene(a.scene_file, a.scene, a.allow_external, a.flatten, job.request.budget, a.quiet || json,
                   job.request.time, keep || job.request.spec.motion_blur, a.variant);
    if (json && !a.quiet) print_json_warnings(a.scene_file, job.loaded.warnings);
  }
  job.load_s = posed_s + seconds_since(t0);
  progress.finish();
  // No output may replace a buffer or image the scene was loaded from.
  std::vector<std::pair<std::string, fs::path>> inputs;
  for (const auto& f : job.loaded.info.source_files) inputs.push_back({"the scene's file", f});
  check_distinct_files(job.request.outputs, inputs);
}

/// The render session's prepare phase: camera and resolution (the image aspect follows the
/// camera's hint unless both are given), the --crop or --tile window, the budget, the lights,
/// the default light and the render's identity.
void setup_phase(RenderJob& job) {
  const RenderArgs& a = job.args;
  const RenderRequest& q = job.request;
  Scene& scene = job.loaded.scene;
  const int cam = base_camera_index(scene, a.camera, a.cam, a.scene_file);
  RenderSpec spec = q.spec;
  const auto [width, height] = image_size(spec.width, spec.height, aspect_hint(scene, cam));
  spec.window = parse_window(a, width, height);
  if (!spec.window.empty() && q.cost_aov)
    throw UsageError("--aov cost renders the whole frame; not with --crop or --tile");
  // What this render is, for its resume state and the EXR's metadata (which `merge` checks
  // tiles by): the content of every file it loaded and every setting that decides its pixels.
  // The bytes as the loader read them, not the files as they are now.
  job.scene_sha256 = sha256_of_set(job.loaded.info.source_files, job.loaded.info.source_sha256);
  PrepareOptions o;
  o.scene_file = a.scene_file;
  o.camera_index = cam;
  o.place = [&](const Scene& sc, int index, int w, int h) { return choose_camera(q.rig, sc, index, w, h); };
  if (q.rig.turntable_frames > 0) {
    // The turn is placed many times over one scene (the shutter's keys): its bounds once.
    auto bounds = std::make_shared<std::pair<const Scene*, Bounds3f>>(nullptr, Bounds3f{});
    o.turn = [&q, bounds](const Scene& sc, int index, int w, int h, double frames) {
      if (bounds->first != &sc) *bounds = {&sc, compute_bounds(sc)};
      CameraRig rig = q.rig;
      rig.turntable_phase = frames;
      return choose_camera(rig, sc, index, w, h, &bounds->second);
    };
  }
  o.charge_budget = [&](const RenderConfig& cfg) {
    return job.bytes_left = q.budget - charge_image_budget(job, cfg);
  };
  o.identity = scene_identity(a, q, job.scene_sha256);
  o.time = q.time;
  o.load_at = [&](double t) {
    return load_scene(a.scene_file, a.scene, a.allow_external, a.flatten, q.budget, true, t, false,
                      a.variant);
  };
  o.identity.shutter = set_scene_motion(job.loaded, spec, q.time.value_or(0), a.scene_file, o.load_at);
  job.prepared = prepare_render(job.loaded, spec, o);
  // The environment map took part of what the image and scene left (the deep pass's share).
  if (const Environment* env = job.prepared.environment.get()) {
    const uint64_t env_bytes =
        (env->texels.size() * sizeof(Vec3f)) +
        (env->marginal_cdf.size() + env->conditional_cdf.size() + env->texel_pdf.size()) * sizeof(float);
    job.bytes_left -= std::min(job.bytes_left, env_bytes);
  }
  if (a.quiet) return;
  if (job.progress == ProgressMode::Json)
    print_json_warnings(a.scene_file, job.prepared.warnings);
  else
    for (const auto& w : job.prepared.warnings) std::fprintf(stderr, "penumbra: warning: %s\n", w.c_str());
}

/// The render session's structure phase: the kept frame's structure reused, refitted or
/// rebuilt, else one built anew.
void build_phase(RenderJob& job, std::optional<KeptScene>& kept) {
  if (!needs_structure(job.prepared.spec, !job.args.debug_pixel.empty())) {
    if (kept) job.build_s = kept->update_s;
    kept.reset();
    return;
  }
  set_phase("building the acceleration structure");
  ProgressReporter progress(job.progress, "build", job.frame);
  const auto t0 = Clock::now();
  const double moved_s = kept ? kept->update_s : 0;
  // An animated scene at a time keeps Embree's still placements apart from the instances that
  // later frames move (as a single --frame render does, so that both see the same structure).
  const bool world_apart = job.loaded.info.animation_count != 0 && job.request.time.has_value();
  const std::string& name = job.prepared.spec.accel;
  Structure previous;
  const bool moved_vertices = kept && kept->reload;
  if (kept && kept->structure.accel)
    previous = std::move(kept->structure);
  else
    announce(job.progress, "building " + name + " (" + describe_scene_size(job.loaded.scene) + ")");
  job.structure =
      build_structure(job.loaded.scene, job.prepared.spec, world_apart, std::move(previous), moved_vertices);
  if (job.structure.update == "refitted" || job.structure.update == "rebuilt")
    announce(job.progress, job.structure.update + " " + name + " (" + job.structure.reason + ")");
  kept.reset();
  job.build_s = moved_s + seconds_since(t0);
  progress.finish();
}

/// Keeps the frame's scene and accelerator for the next frame, as loaded (without the default
/// light setup_phase added): a scene without animations, or one loaded at a time with what
/// posing it needs (LoadedScene::animation).
void keep_scene(RenderJob& job, std::optional<KeptScene>& kept) {
  const bool same_pose = !job.args.cam.turntable.empty();
  if (job.loaded.info.animation_count != 0 && !job.loaded.animation && !same_pose) {
    // Posing cannot move what this animation moves: the next frame loads the file at its time,
    // and this frame's structure is refitted to it.
    if (!job.structure.accel || !job.request.time) return;
    kept.emplace();
    kept->reload = true;
    kept->structure = std::move(job.structure);
    return;
  }
  finish_render(job.loaded, job.prepared);
  kept.emplace();
  kept->loaded = std::move(job.loaded);
  kept->structure = std::move(job.structure);
  kept->structure.update = "reused";
  kept->same_pose = same_pose;
}

/// --debug-pixel: one pixel exactly as the full render would compute it, printed on stdout.
int render_debug_pixel(RenderJob& job) {
  const RenderRequest& q = job.request;
  const RenderConfig& cfg = job.prepared.config;
  if (q.debug_x < 0 || q.debug_y < 0 || q.debug_x >= cfg.width || q.debug_y >= cfg.height)
    throw UsageError("--debug-pixel " + job.args.debug_pixel + " is outside the " +
                     std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " image");
  float rgba[4];
  RayCounts counts;
  render_pixel(job.loaded.scene, job.structure.accel.get(), job.prepared, q.debug_x, q.debug_y, rgba, counts);
  std::printf("pixel %d,%d: R %.6g G %.6g B %.6g A %.6g (rays: camera %llu, shadow %llu, %s %llu)\n",
              q.debug_x, q.debug_y, rgba[0], rgba[1], rgba[2], rgba[3],
              static_cast<unsigned long long>(counts.camera), static_cast<unsigned long long>(counts.shadow),
              q.path ? "bounce" : "reflection", static_cast<unsigned long long>(counts.reflection));
  return kExitOk;
}

/// The render session's image phase: the path tracer with its signals, checkpoints and resume
/// (path_render.h), else the integrator at once.
void render_phase(RenderJob& job) {
  set_phase("rendering");
  ProgressReporter reporter(job.progress, "render", job.frame);
  if (job.request.path) {
    run_path_render(job, reporter);
  } else {
    RenderHooks hooks;
    hooks.progress = [&](int d, int t) { reporter(d, t); };
    job.image = render_image(job.loaded.scene, job.structure.accel.get(), job.prepared, hooks);
  }
  reporter.finish();
  job.mean_spp =
      double(job.image.stats.samples) / (double(job.image.film.width) * double(job.image.film.height));
}

/// What the summary and the statistics report of the job.
RenderReport report_of(const RenderJob& job) {
  RenderReport r{job.args.scene_file, job.loaded.scene, job.prepared, job.image, job.structure.update};
  r.traced = job.structure.accel != nullptr;
  r.load_s = job.load_s;
  r.build_s = job.build_s;
  r.write_s = job.write_s;
  r.deep = job.request.deep.has_value() && !job.interrupted;
  r.deep_s = job.deep_s;
  r.deep_write_s = job.deep_write_s;
  r.deep_samples = job.deep_samples;
  r.mean_spp = job.mean_spp;
  r.interrupted = job.interrupted != 0;
  return r;
}

/// The images as written with their hashes, for the statistics.
std::vector<WrittenImage> written_images(const RenderJob& job) {
  const RenderRequest& q = job.request;
  std::vector<WrittenImage> w = {{"exr", q.out.string(), job.hashes.exr}};
  if (q.png) w.push_back({"png", q.png->string(), job.hashes.png});
  if (q.cost_png) w.push_back({"cost_png", q.cost_png->string(), job.hashes.cost_png});
  if (q.deep && !job.interrupted) w.push_back({"deep", q.deep->string(), job.hashes.deep});
  return w;
}

/// The deep image (--deep): the beauty's camera samples traced again with their layers recorded,
/// within what the budget leaves; throws UsageError (exit 2, before any file is written) naming
/// --max-memory when they would not fit.
DeepResult trace_deep(const RenderJob& job) {
  set_phase("tracing the deep samples");
  DeepResult deep =
      render_deep_image(job.loaded, *job.structure.accel, job.prepared, job.image, job.bytes_left);
  if (deep.over_budget)
    throw UsageError(
        "the deep image needs more than the " + format_bytes(job.bytes_left) +
        " the --max-memory budget leaves beside the image and scene (" + std::to_string(deep.samples_found) +
        " deep samples found before it stopped, " + format_bytes(2 * deep.bytes) +
        " with the copy it is assembled into); raise --max-memory or " + "--deep-merge-tolerance");
  return deep;
}

/// The flat EXR's metadata without what describes its layers (Cryptomatte's keys and manifest
/// sidecars), for the deep EXR beside it.
ExrOptions deep_exr_options(const ExrOptions& flat) {
  ExrOptions o;
  o.compression = flat.compression;
  for (const auto& kv : flat.metadata)
    if (kv.first.rfind("cryptomatte/", 0) != 0) o.metadata.push_back(kv);
  o.float_metadata = flat.float_metadata;
  o.matrix_metadata = flat.matrix_metadata;
  return o;
}

/// The EXR with its layers, the deep image, the display image, the heat map, then the statistics
/// that record their hashes.
void write_phase(RenderJob& job) {
  const RenderRequest& q = job.request;
  ProgressReporter progress(job.progress, "write", job.frame);
  const auto t0 = Clock::now();
  LayerBuffers buffers;
  buffers.layers = render_layers(job.loaded, job.structure.accel.get(), job.prepared);
  overlay_wireframe(job.image, buffers.layers, job.prepared);
  // An interrupted render keeps its flat image so far; its deep image is traced once it completes.
  const bool deep_now = q.deep && !job.interrupted;
  const auto deep_t0 = Clock::now();
  const DeepResult deep = deep_now ? trace_deep(job) : DeepResult{};
  job.deep_s = seconds_since(deep_t0);
  job.deep_samples = deep.image.samples.size();
  const ExrOptions exr = make_exr_options(job, buffers);
  set_phase("writing the outputs");
  const bool hashes = !job.args.stats_json.empty();
  for (const auto& [sidecar, text] : buffers.sidecars)
    write_atomically(
        sidecar, [&](const fs::path& temp) { write_file_checked(temp, text.data(), text.size(), sidecar); });
  // The deep EXR first: a complete flat EXR then means its deep one was written too.
  if (deep_now) {
    const auto t = Clock::now();
    write_deep_exr(deep.image, *q.deep, deep_exr_options(exr), hashes ? &job.hashes.deep : nullptr);
    job.deep_write_s = seconds_since(t);
  }
  const Film* shown = &job.image.film;
  Film main;
  if (job.args.spec.denoise && denoises_now(job.prepared.config)) {
    // The noisy frame, then the denoiser on it: the bytes `penumbra denoise` and a merge give.
    ProgressReporter denoise_progress(job.progress, "denoise", job.frame);
    ExrDenoiseOptions d;
    d.noisy_main = job.args.spec.denoise_main == "noisy";
    d.config = denoise_config(job.prepared.config);
    d.max_memory_bytes = q.budget;
    d.progress = [&](int done, int total) { denoise_progress(done, total); };
    main = denoise_through_file(
        q.out, [&](const fs::path& noisy) { write_exr(job.image.film, noisy, exr); }, d,
        hashes ? &job.hashes.exr : nullptr);
    denoise_progress.finish();
    shown = &main;
  } else {
    write_exr(job.image.film, q.out, exr, hashes ? &job.hashes.exr : nullptr);
  }
  if (q.png) write_display_image(*shown, *q.png, q.display, hashes ? &job.hashes.png : nullptr);
  if (q.cost_png)
    write_heatmap(total_cost(buffers.layers.cost), job.prepared.config.width, job.prepared.config.height,
                  *q.cost_png, cost_caption(buffers.layers.cost, job.args.spec.accel),
                  hashes ? &job.hashes.cost_png : nullptr);
  job.write_s = seconds_since(t0) - job.deep_s;
  if (hashes) write_stats_json(report_of(job), written_images(job), job.args.stats_json);
  progress.finish();
}

/// One render: load, set up, build, render, write, report. `kept` is the previous frame's scene,
/// readied by reuse_kept_scene and used instead of loading (and building, if it has an
/// accelerator); on return it holds this frame's scene when `keep` is set and keep_scene keeps it.
int render_frame(const RenderArgs& a, RenderRequest request, std::optional<KeptScene>& kept, bool keep) {
  RenderJob job(a);
  job.request = std::move(request);
  install_signal_handlers();
  load_phase(job, kept, keep);
  setup_phase(job);
  build_phase(job, kept);
  if (!a.debug_pixel.empty()) return render_debug_pixel(job);
  render_phase(job);
  write_phase(job);
  if (job.remove_state) fs::remove(fs::path(job.request.out).concat(".resume"));
  if (prints_text(job.progress, a.quiet)) print_render_summary(report_of(job));
  if (keep && !job.interrupted) keep_scene(job, kept);
  const RenderRequest& q = job.request;
  if (q.paths_to_stdout) {
    std::printf("%s\n", q.out.string().c_str());
    if (q.png) std::printf("%s\n", q.png->string().c_str());
    if (q.cost_png) std::printf("%s\n", q.cost_png->string().c_str());
    if (q.deep && !job.interrupted) std::printf("%s\n", q.deep->string().c_str());
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
        job.interrupted, job.image.stats.passes, job.mean_spp);
  return 128 + job.interrupted;
}

/// One frame of the run: its number (none without --frame/--frames) and its arguments, with
/// --frame set and every `#` in the output paths replaced.
struct FramePlan {
  std::optional<int64_t> number;
  RenderArgs args;
};

/// The output paths a frame's number is substituted into, named by their options.
std::vector<std::pair<const char*, std::string RenderArgs::*>> patterned_outputs() {
  return {{"-o", &RenderArgs::output},
          {"--png", &RenderArgs::png},
          {"--cost-png", &RenderArgs::cost_png},
          {"--deep", &RenderArgs::deep},
          {"--stats-json", &RenderArgs::stats_json}};
}

FramePlan plan_frame(const RenderArgs& a, int64_t number) {
  FramePlan p{number, a};
  p.args.frames.reset();
  p.args.frame = std::to_string(number);
  for (const auto& [option, member] : patterned_outputs())
    p.args.*member = substitute_frame(a.*member, number);
  return p;
}

/// A frame range's outputs must each hold a `#` so that no two frames write one file; without
/// a range, a `#` needs --frame.
void check_patterns(const RenderArgs& a) {
  for (const auto& [option, member] : patterned_outputs()) {
    if (!a.frames && has_frame_pattern(a.*member) && !a.frame)
      throw UsageError(std::string("'#' in ") + option + " needs --frame or --frames");
    if (a.frames && !(a.*member).empty() && !has_frame_pattern(a.*member))
      throw UsageError(std::string("--frames needs a run of '#' in ") + option +
                       " (e.g. out.####.exr): " + "otherwise every frame writes " + a.*member);
  }
}

/// The frames to render: one without --frames (`#` then needs --frame), else every frame of
/// the range, whose outputs must each hold a `#` so that no two frames write one file.
std::vector<FramePlan> plan_frames(const RenderArgs& a) {
  check_patterns(a);
  if (!a.frames) {
    if (!a.frame) return {{std::nullopt, a}};
    return {plan_frame(a, parse_integer(*a.frame, -kMaxFrameNumber, kMaxFrameNumber, "--frame"))};
  }
  const FrameRange range = parse_frame_range(*a.frames);
  std::vector<FramePlan> plan;
  plan.reserve(size_t(range.count()));
  for (int64_t f = range.first; f <= range.last; f += range.step) plan.push_back(plan_frame(a, f));
  return plan;
}

/// The flags with --turntable N alone given the turntable's frames 0..N-1 as --frames.
RenderArgs with_turntable_frames(const RenderArgs& a) {
  RenderArgs r = a;
  if (!a.cam.turntable.empty() && !a.frames && !a.frame) {
    const int n = turntable_frames(a.cam);
    if (!has_frame_pattern(a.output))
      throw UsageError("--turntable " + std::to_string(n) + " renders " + std::to_string(n) +
                       " frames: -o needs a run of '#' for the frame number (e.g. turn.####.exr)");
    r.frames = "0-" + std::to_string(n - 1);
  }
  return r;
}

/// No file may be written by two frames (patterns of different options can meet).
void check_frames_distinct(const std::vector<FramePlan>& plan, const std::vector<RenderRequest>& requests) {
  std::map<std::string, int64_t> writer;
  for (size_t i = 0; i < plan.size(); ++i)
    for (const auto& [option, file] : requests[i].outputs) {
      const auto [it, fresh] =
          writer.emplace(fs::absolute(file).lexically_normal().string(), *plan[i].number);
      if (!fresh && it->second != *plan[i].number)
        throw UsageError(option + " " + file.string() + " would be written by frames " +
                         std::to_string(it->second) + " and " + std::to_string(*plan[i].number));
    }
}

/// --contact-sheet: needs a frame range whose frames all write a display image, and a sheet
/// path of its own in a display format.
void check_contact_sheet(const RenderArgs& a, const std::vector<RenderRequest>& requests) {
  if (a.contact_sheet.empty()) {
    if (a.contact_sheet_columns > 0) throw UsageError("--contact-sheet-columns needs --contact-sheet");
    return;
  }
  if (!a.frames) throw UsageError("--contact-sheet tiles the frames of --frames or --turntable");
  if (!a.debug_pixel.empty()) throw UsageError("--contact-sheet tiles whole frames: not with --debug-pixel");
  if (has_frame_pattern(a.contact_sheet))
    throw UsageError("--contact-sheet is one image for every frame: no '#' in " + a.contact_sheet);
  std::vector<std::pair<std::string, fs::path>> outputs = {{"--contact-sheet", a.contact_sheet}};
  for (const RenderRequest& q : requests) {
    if (!q.png) throw UsageError("--contact-sheet tiles the frames' display images: not with --no-png");
    outputs.insert(outputs.end(), q.outputs.begin(), q.outputs.end());
  }
  check_display_output(a.contact_sheet, requests.front().display);
  resolve_output(a.contact_sheet, "--contact-sheet");
  check_distinct_files(outputs, {{"the scene file", a.scene_file}});
  // The sheet's size, where the flags fix the image's (else after the first frame).
  if (a.spec.width > 0 && a.spec.height > 0)
    check_contact_sheet_size(requests.size(), a.contact_sheet_columns, a.spec.width, a.spec.height,
                             a.png_alpha ? 4 : 3, a.contact_sheet, memory_budget(a.max_memory));
}

/// With --skip-existing: true when the frame's EXR is complete; a file that is there but
/// incomplete is reported and rendered again.
bool frame_done(const RenderArgs& a, const FramePlan& p, const RenderRequest& q) {
  if (!a.skip_existing) return false;
  const bool text = prints_text(progress_mode(a.progress, a.quiet), a.quiet);
  std::string problem;
  const std::string label = p.number ? "frame " + std::to_string(*p.number) + ": " : "";
  if (is_complete_exr(q.out, problem)) {
    // The display image and statistics of a frame whose run ended after its EXR.
    std::vector<fs::path> others;
    if (q.png) others.push_back(*q.png);
    if (!a.stats_json.empty()) others.push_back(a.stats_json);
    std::error_code ec;
    std::string deep_problem;
    if (q.deep && !is_complete_exr(*q.deep, deep_problem)) {  // written first; absent if asked for later
      if (text)
        std::fprintf(stderr, "penumbra: warning: %s%s %s; rendering the frame again\n", label.c_str(),
                     q.deep->string().c_str(), deep_problem.c_str());
      return false;
    }
    for (const fs::path& other : others)
      if (!fs::exists(other, ec)) {
        if (text)
          std::fprintf(stderr, "penumbra: warning: %s%s is missing; rendering the frame again\n",
                       label.c_str(), other.string().c_str());
        return false;
      }
    if (text)
      std::fprintf(stderr, "penumbra: %s%s is complete; skipped\n", label.c_str(), q.out.string().c_str());
    return true;
  }
  std::error_code ec;
  if (fs::exists(q.out, ec) && text)
    std::fprintf(stderr, "penumbra: warning: %s%s %s; rendering it again\n", label.c_str(),
                 q.out.string().c_str(), problem.c_str());
  return false;
}

}  // namespace

int run_render(const RenderArgs& typed) {
  const auto t0 = Clock::now();
  const RenderArgs a = with_turntable_frames(typed);
  const std::vector<FramePlan> plan = plan_frames(a);
  // Every frame's flags and outputs are checked before the first frame loads.
  std::vector<RenderRequest> requests;
  requests.reserve(plan.size());
  for (const FramePlan& p : plan) requests.push_back(check_render_args(p.args));
  if (a.frames) check_frames_distinct(plan, requests);
  check_contact_sheet(a, requests);
  std::vector<fs::path> sheet_cells;
  for (const RenderRequest& q : requests)
    if (q.png) sheet_cells.push_back(*q.png);
  const bool paths_to_stdout = requests.front().paths_to_stdout;
  int64_t rendered = 0, skipped = 0;
  const bool text = prints_text(progress_mode(a.progress, a.quiet), a.quiet);
  std::optional<KeptScene> kept;
  for (size_t i = 0; i < plan.size(); ++i) {
    const FramePlan& p = plan[i];
    if (frame_done(a, p, requests[i])) {
      ++skipped;
      continue;
    }
    const std::string reuse = reuse_kept_scene(kept, requests[i]);
    if (a.frames && text)
      std::fprintf(stderr, "penumbra: frame %lld (%zu of %zu) -> %s%s\n", static_cast<long long>(*p.number),
                   i + 1, plan.size(), requests[i].out.string().c_str(), reuse.c_str());
    if (const int rc = render_frame(p.args, std::move(requests[i]), kept, i + 1 < plan.size()); rc != kExitOk)
      return rc;
    ++rendered;
    if (!a.contact_sheet.empty() && rendered + skipped == 1)  // the sheet's size, before the other frames
      check_contact_sheet_size(sheet_cells[i], sheet_cells.size(), a.contact_sheet_columns, a.contact_sheet,
                               memory_budget(a.max_memory));
  }
  if (a.frames && text)
    std::fprintf(stderr, "penumbra: frames %s: %lld rendered, %lld skipped, %.2f s in total\n",
                 a.frames->c_str(), static_cast<long long>(rendered), static_cast<long long>(skipped),
                 seconds_since(t0));
  if (!a.contact_sheet.empty()) {
    set_phase("writing the contact sheet");
    write_contact_sheet(sheet_cells, a.contact_sheet_columns, a.contact_sheet, memory_budget(a.max_memory));
    if (text)
      std::fprintf(stderr, "penumbra: contact sheet of %zu frames -> %s\n", sheet_cells.size(),
                   a.contact_sheet.c_str());
    if (paths_to_stdout) std::printf("%s\n", a.contact_sheet.c_str());
  }
  return kExitOk;
}

std::vector<std::pair<std::string, fs::path>> check_render(const RenderArgs& typed) {
  const RenderArgs a = with_turntable_frames(typed);
  const std::vector<FramePlan> plan = plan_frames(a);
  std::vector<RenderRequest> requests;
  std::vector<std::pair<std::string, fs::path>> outputs;
  for (const FramePlan& p : plan) {
    requests.push_back(check_render_args(p.args));
    outputs.insert(outputs.end(), requests.back().outputs.begin(), requests.back().outputs.end());
  }
  if (a.frames) check_frames_distinct(plan, requests);
  check_contact_sheet(a, requests);
  if (!a.contact_sheet.empty()) outputs.push_back({"--contact-sheet", a.contact_sheet});
  return outputs;
}

int check_frame_patterns(const RenderArgs& typed) {
  const RenderArgs a = with_turntable_frames(typed);
  check_patterns(a);
  if (a.frames) parse_frame_range(*a.frames);
  return 0;
}

}  // namespace penumbra::cli
