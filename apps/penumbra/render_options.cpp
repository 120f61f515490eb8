// `penumbra render`'s flags, and every check on them that needs no scene.
#include "apps/penumbra/render_options.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <tuple>
#include <type_traits>
#include <variant>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/exr_layers.h"
#include "apps/penumbra/progress.h"
#include "apps/penumbra/scene_setup.h"
#include "io/files/atomic_file.h"
#include "render/session.h"

namespace penumbra::cli {

namespace fs = std::filesystem;

namespace {

/// -o, --png, --cost-png and --stats-json: extensions, folders and the display transform.
void check_output_paths(const RenderArgs& a, RenderRequest& q) {
  q.out = a.output;
  std::string ext = q.out.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw UsageError("-o " + a.output + ": the output must be an .exr file");
  // Each output's folder must exist and its target must be replaceable or streamable.
  resolve_output(q.out, "-o");
  if (!a.stats_json.empty()) resolve_output(a.stats_json, "--stats-json");
  if (!a.deep.empty()) {
    q.deep = fs::path(a.deep);
    std::string deep_ext = q.deep->extension().string();
    for (auto& c : deep_ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (deep_ext != ".exr") throw UsageError("--deep " + a.deep + ": the deep image must be an .exr file");
    resolve_output(*q.deep, "--deep");
  }
  if (!a.no_png) q.png = a.png.empty() ? fs::path(q.out).replace_extension(".png") : fs::path(a.png);
  q.display.ocio_config = a.ocio_config;
  q.display.display = a.display;
  q.display.view = a.view;
  q.display.look = a.look;
  q.display.exposure = a.exposure;
  q.display.half_beauty = !a.use_float;  // the display image shows what the EXR holds
  q.display.alpha = a.png_alpha;
  if (q.png) {
    resolve_output(*q.png, "--png");
    check_display_output(*q.png, q.display);  // a typo must not cost a whole render
  }
}

/// Colours, integrator-specific flags, numbers and the pixel filter.
void check_integrator_flags(const RenderArgs& a, RenderRequest& q) {
  if (!std::isfinite(a.exposure) || std::fabs(a.exposure) > 64)
    throw UsageError("--exposure must be finite and within [-64, 64]");
  q.background = parse_colour(a.background, "--background");
  q.ambient = parse_colour(a.ambient, "--ambient");
  q.path = a.spec.integrator == "path";
  q.raster = a.spec.integrator == "raster";
  if (!q.raster && (a.raster_shadows_given || a.shadow_map_size_given))
    throw UsageError(std::string(a.raster_shadows_given ? "--raster-shadows" : "--shadow-map-size") +
                     " needs --integrator raster");
  if (q.raster && a.depth_given)
    throw UsageError("--max-depth does not apply to --integrator raster (local shading: no reflected rays)");
  if (a.shadow_map_size_given && a.spec.raster_shadows != "map")
    throw UsageError("--shadow-map-size needs --raster-shadows map");
  if (q.path && (a.background_given || a.ambient_given))
    throw UsageError(
        std::string(a.background_given ? "--background" : "--ambient") +
        " applies to --integrator whitted; the path tracer is lit by the scene's lights and --env");
  if (!q.path) {
    for (const auto& [given, name] : {std::pair{!a.env.empty(), "--env"},
                                      {a.spec.time_limit > 0, "--time-limit"},
                                      {a.spec.adaptive > 0, "--adaptive"},
                                      {a.spec.clamp_indirect > 0, "--clamp-indirect"},
                                      {a.spec.light_sampling != "mis", "--light-sampling"},
                                      {a.spec.sampler != "sobol", "--sampler"},
                                      {a.spec.energy_compensation != "on", "--energy-compensation"},
                                      {a.spec.light_sampler != "power", "--light-sampler"},
                                      {a.spec.light_samples != 1, "--light-samples"},
                                      {a.spec.env_intensity != 1, "--env-intensity"},
                                      {a.spec.env_rotation != 0, "--env-rotation"},
                                      {a.checkpoint > 0, "--checkpoint"},
                                      {a.resume, "--resume"}})
      if (given) throw UsageError(std::string(name) + " needs --integrator path");
  }
  if (!std::isfinite(a.spec.clamp_indirect) || a.spec.clamp_indirect < 0)
    throw UsageError("--clamp-indirect must be finite and >= 0 (0 = off)");
  if (!std::isfinite(a.spec.adaptive) || a.spec.adaptive < 0)
    throw UsageError("--adaptive must be finite and >= 0 (0 = off)");
  if (!std::isfinite(a.spec.time_limit) || a.spec.time_limit < 0)
    throw UsageError("--time-limit must be a finite number of seconds >= 0");
  if (!std::isfinite(a.checkpoint) || a.checkpoint < 0)
    throw UsageError("--checkpoint must be a finite number of seconds >= 0");
  if (!std::isfinite(a.spec.env_intensity) || a.spec.env_intensity < 0)
    throw UsageError("--env-intensity must be finite and >= 0");
  if (!std::isfinite(a.spec.env_rotation)) throw UsageError("--env-rotation must be finite");
  q.filter_type = q.path ? FilterType::BlackmanHarris : FilterType::Box;
  if (!a.spec.filter.empty() && !parse_filter_type(a.spec.filter, q.filter_type))
    throw UsageError("--filter: unknown filter '" + a.spec.filter +
                     "' (known: box, tent, gaussian, blackman-harris)");
  q.filter_width = a.spec.filter_width > 0 ? a.spec.filter_width : default_filter_width(q.filter_type);
  if (!std::isfinite(a.spec.filter_width) || a.spec.filter_width < 0 || q.filter_width > 16)
    throw UsageError("--filter-width must be in (0, 16] pixels");
}

/// --env as a colour, --debug-pixel, --accel with its parameters and --seed.
void check_scalar_flags(const RenderArgs& a, RenderRequest& q) {
  // --env: a colour ("r,g,b" or one value) or an image file.
  if (!a.env.empty() && a.env.find_first_not_of("0123456789.,eE+- ") == std::string::npos)
    q.env_colour = parse_colour(a.env, "--env");
  if (!a.debug_pixel.empty()) {
    const auto [x, y] = split_pair(a.debug_pixel, ',', "--debug-pixel", "x,y");
    q.debug_x = int(parse_integer(x, INT_MIN, INT_MAX, "--debug-pixel x"));
    q.debug_y = int(parse_integer(y, INT_MIN, INT_MAX, "--debug-pixel y"));
  }
  q.accel_config = parse_accel(a.spec.accel, a.accel_params);
  const char* end = a.seed.data() + a.seed.size();
  if (const auto r = std::from_chars(a.seed.data(), end, q.seed);
      a.seed.empty() || a.seed[0] == '-' || a.seed[0] == '+' || r.ec != std::errc() || r.ptr != end)
    throw UsageError("--seed: '" + a.seed + "' is not an integer in [0, 2^64 - 1]");
}

/// --aov NAME[,NAME...] (repeatable); "all" = every compositing AOV of the integrator; and the
/// heat map path of --aov cost.
void check_aovs(const RenderArgs& a, RenderRequest& q) {
  std::vector<std::string> names;
  for (const auto& item : a.aovs) {
    std::stringstream ss(item);
    std::string name;
    while (std::getline(ss, name, ',')) names.push_back(name);
  }
  for (const std::string& name : names) {
    try {
      penumbra::check_aovs({name}, "path");
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--aov: ") + e.what());
    }
    if (!q.path && (name == "samples" || name == "variance" || name == "light" || name == "halves"))
      throw UsageError("--aov " + name + " needs --integrator path");
  }
  q.aovs = penumbra::check_aovs(names, a.spec.integrator);
  if (a.spec.denoise && q.path) q.aovs.insert("halves");  // what the denoiser reads, kept in the EXR
  q.crypto = crypto_layers(q.aovs);
  if (a.crypto_depth_given && q.crypto.empty())
    throw UsageError("--crypto-depth needs --aov crypto_object, crypto_material or crypto_asset");
  q.crypto_depth = a.spec.crypto_depth;
  const std::string& c = a.compression;
  if (!q.crypto.empty() && !a.multipart && (c == "pxr24" || c == "dwaa" || c == "dwab"))
    throw UsageError("--compression " + c +
                     " is lossy for float channels and would change the Cryptomatte ids; use a lossless one "
                     "or --multipart (which keeps data layers lossless)");
  q.cost_aov = q.aovs.count("cost") > 0;
  q.data_aovs = wants_data_aovs(q.aovs);
  if (q.cost_aov) {
    if (!a.no_png) {
      q.cost_png = a.cost_png.empty() ? fs::path(q.out).replace_extension(".cost.png") : fs::path(a.cost_png);
      resolve_output(*q.cost_png, "--cost-png");
      check_display_output(*q.cost_png, q.display);
    }
  } else if (!a.cost_png.empty()) {
    throw UsageError("--cost-png needs --aov cost");
  }
}

/// No two outputs may be one file, and no output may be a file this run reads; stdout carries
/// the paths written unless an output streams there.
void check_output_collisions(const RenderArgs& a, RenderRequest& q) {
  q.out_streams = resolve_output(q.out, "-o").kind == OutputKind::Stream;
  if (q.out_streams && (a.checkpoint > 0 || a.resume))
    throw UsageError(
        "--checkpoint and --resume keep their state beside -o, which must then be a regular file");
  std::vector<std::pair<std::string, fs::path>> outputs = {{"-o", q.out}};
  if (q.path && !q.out_streams) {
    // The resume state is written beside a regular-file output only; a FIFO or device at its
    // path is never written or removed.
    const fs::path state = fs::path(q.out).concat(".resume");
    q.state_beside_output = resolve_output(state, "the resume state").kind == OutputKind::Replace;
    if (!q.state_beside_output && (a.checkpoint > 0 || a.resume))
      throw UsageError("the resume state " + state.string() +
                       " is not a regular file; --checkpoint and --resume need one");
    if (q.state_beside_output) outputs.push_back({"the resume state", state});
  }
  if (q.png) outputs.push_back({"--png", *q.png});
  if (q.cost_png) outputs.push_back({"--cost-png", *q.cost_png});
  if (q.deep) outputs.push_back({"--deep", *q.deep});
  if (!a.stats_json.empty()) outputs.push_back({"--stats-json", a.stats_json});
  if (!q.out_streams)
    for (const std::string& layer : q.crypto)
      outputs.push_back({"the " + layer + " manifest", crypto_sidecar_path(q.out, layer)});
  std::vector<std::pair<std::string, fs::path>> inputs = {{"the scene file", a.scene_file}};
  if (!a.env.empty() && !q.env_colour) inputs.push_back({"--env", a.env});
  if (!a.ocio_config.empty())
    inputs.push_back({"--ocio-config", a.ocio_config});
  else if (const char* ocio = std::getenv("OCIO"); ocio && *ocio)
    inputs.push_back({"$OCIO", ocio});
  check_distinct_files(outputs, inputs);
  q.outputs = outputs;
  struct stat stdout_stat {};
  if (::fstat(STDOUT_FILENO, &stdout_stat) == 0)
    for (const auto& [option, file] : outputs) {
      const OutputTarget t = resolve_output(file, option);
      if (t.kind == OutputKind::Stream && t.device == stdout_stat.st_dev && t.inode == stdout_stat.st_ino)
        q.paths_to_stdout = false;
    }
}

/// The render spec of the checked flags, validated by the library as every front end's is.
RenderSpec render_spec(const RenderArgs& a, const RenderRequest& q) {
  RenderSpec spec = a.spec;
  spec.camera = a.camera;
  spec.seed = q.seed;
  if (a.background_given) spec.background = q.background;
  if (a.ambient_given) spec.ambient = q.ambient;
  if (q.env_colour)
    spec.env_color = q.env_colour;
  else
    spec.env_map = a.env;
  spec.accel_params = a.accel_params;
  spec.aovs = q.aovs;
  spec.deep = q.deep.has_value();
  try {
    validate(spec);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("render settings: ") + e.what());
  }
  return spec;
}

}  // namespace

namespace {

/// The flags hand-declared below, with their own parsing and messages (not from spec_fields()).
bool hand_declared(const SpecField& f) {
  return std::string(f.name) == "seed" || std::string(f.name) == "deep";  // --deep takes the file
}

/// One flag per field of the render spec's table (render/spec.h): --name-with-dashes bound to
/// the field, with its help; integer ranges and the choices of string fields checked by the
/// parser, except the structure's and the filter's names, which check_render_args checks with
/// the valid names listed.
void add_spec_options(CLI::App& render, RenderSpec& spec) {
  for (const SpecField& f : spec_fields()) {
    if (hand_declared(f)) continue;
    std::visit(
        [&](auto member) {
          using T = std::remove_cvref_t<decltype(spec.*member)>;
          if constexpr (std::is_same_v<T, bool>) {
            render.add_flag(flag_name(f), spec.*member, f.help);
            return;
          }
          CLI::Option* o = render.add_option(flag_name(f), spec.*member, f.help);
          if constexpr (std::is_integral_v<T>) {
            if (f.lo != 0 || f.hi != 0) o->check(CLI::Range(T(f.lo), T(f.hi)));
          } else if constexpr (std::is_same_v<T, std::string>) {
            const std::string name = f.name;
            if (!f.choices.empty() && name != "accel" && name != "filter") o->check(CLI::IsMember(f.choices));
          }
        },
        f.member);
  }
}

/// The scene file, the outputs' paths, the image size and every integrator and sampling flag.
void add_sampling_options(CLI::App& render, RenderArgs& args) {
  render.add_option("scene", args.scene_file, "glTF scene (.gltf or .glb)")->required();
  render.add_option("-o,--output", args.output, "output EXR path (written atomically)")->required();
  render.add_option("--png", args.png,
                    "display image path (.png/.jpg/.tif); default: the EXR path with .png");
  render.add_flag("--no-png", args.no_png, "write only the EXR");
  add_spec_options(render, args.spec);
  render.add_option("--env", args.env,
                    "path: environment light: a radiance r,g,b or grey, or an equirectangular map (.exr, "
                    ".hdr, any float image OpenImageIO reads)");
}

/// Threads, scene and camera choice, and the acceleration structure.
void add_scene_options(CLI::App& render, RenderArgs& args) {
  render.add_option("--scene", args.scene, "glTF scene index (default: the file's default scene)")
      ->check(CLI::Range(0, 1 << 30));
  render.add_option("--variant", args.variant,
                    "KHR_materials_variants variant to render (names: `penumbra info`; default: the "
                    "primitives' own materials)");
  render.add_option("--camera", args.camera,
                    "camera instance: index as listed by `penumbra info`, or name (default 0; none in the "
                    "file: frame the bounds); with --look-at, --orbit, --euler or --turntable it lends only "
                    "its lens");
  render.add_option("--accel-param", args.accel_params, accel_param_help())->type_name("KEY=VALUE");
}

/// The EXR's layout and compression, the display transform, animation time, memory, resume,
/// windows, debugging, quiet and AOVs.
void add_output_options(CLI::App& render, RenderArgs& args) {
  render.add_flag("--multipart", args.multipart,
                  "write one EXR part per layer (rgba, albedo, N, Z, ...); lossy --compression then applies "
                  "to colour parts only");
  render.add_flag("--float", args.use_float, "write 32-bit float EXR channels (default half)");
  render.add_option("--compression", args.compression, "EXR compression (default zip)")
      ->check(CLI::IsMember({"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"}));
  render.add_option("--exposure", args.exposure, "exposure in stops for the display image (default 0)");
  render.add_option("--ocio-config", args.ocio_config,
                    "OpenColorIO config (default: $OCIO, else the shipped config)");
  render.add_option("--display", args.display, "OCIO display (default: the config's default)");
  render.add_option(
      "--view", args.view,
      "OCIO view: Standard (default), Filmic (ACES 1.0 SDR tone mapping) or Raw with the shipped config");
  render.add_option("--look", args.look,
                    "OCIO look applied before the view: High Contrast, Low Contrast, Plus 1 EV, Minus 1 EV "
                    "with the shipped config");
  render.add_flag(
      "--png-alpha", args.png_alpha,
      "keep the beauty's alpha in the display image (RGBA, colour un-premultiplied; .png and .tif)");
  render.add_option(
      "--background", args.background,
      "whitted: background radiance r,g,b or grey (default 0); background alpha stays 0 (path: use --env)");
  render.add_option("--ambient", args.ambient, "whitted: ambient intensity Ia, r,g,b or grey (default 0.05)");
  render.add_option("--seed", args.seed, "sampler seed, an integer in [0, 2^64 - 1] (default 0)");
  render.add_option("--time", args.time,
                    "animation time in seconds: animations (node TRS, skins, morph weights) "
                    "are evaluated there (default: the file's static pose)");
  // --time with --frame or --frames is refused by check_render_args (a turntable's frames allow it).
  auto* frame_opt = render.add_option("--frame", args.frame, "animation frame N, at time N / --fps");
  render
      .add_option("--frames", args.frames,
                  "render frames A to B inclusive (A-B, A-B:STEP or N), each at time N / --fps; every "
                  "output path needs a run of '#' for the frame number (#### -> 0012)")
      ->excludes(frame_opt);
  render.add_option("--contact-sheet", args.contact_sheet,
                    "after --frames or --turntable, tile every frame's display image in order into this "
                    "image (.png, .jpg, .tif), left to right and top to bottom");
  render
      .add_option("--contact-sheet-columns", args.contact_sheet_columns,
                  "columns of the contact sheet (default: the fewest that keep it no taller than wide)")
      ->check(CLI::Range(1, 4096));
  auto* skip_opt = render.add_flag("--skip-existing", args.skip_existing,
                                   "keep a frame whose -o already is a complete, readable EXR; render it "
                                   "again (with a warning) when the file is truncated or unreadable");
  render.add_flag("--overwrite", args.overwrite, "replace existing outputs (the default)")
      ->excludes(skip_opt);
  render.add_flag("--reproducible", args.reproducible,
                  "record no command line or render time in the EXR, so that renders of the same scene and "
                  "settings (and merges of their tiles) are the same bytes");
  render.add_option(
      "--max-memory", args.max_memory,
      "one memory budget for the scene, the acceleration structure, --env and the image buffers, e.g. 4G; "
      "what does not fit is refused before it is allocated (default: half the RAM)");
  render.add_flag("--allow-external-uris", args.allow_external,
                  "let buffer URIs reach files outside the scene's folder");
  render.add_flag("--flatten", args.flatten,
                  "give every placement of a mesh its own world-space copy instead of instancing it");
  render.add_option("--checkpoint", args.checkpoint,
                    "path: every this many seconds (after a whole pass) write the image so far and the "
                    "resume state OUT.exr.resume, atomically (default 0 = never)");
  render.add_flag("--resume", args.resume,
                  "path: continue from OUT.exr.resume (written by --checkpoint, --time-limit or an "
                  "interrupt) to the requested spp; the result equals an uninterrupted render");
  render.add_option(
      "--stats-json", args.stats_json,
      "also write the run's statistics (times per phase, rays, spp, memory) as JSON to this file");
  render
      .add_option("--crop", args.crop,
                  "render only x0 x1 y0 y1 (pixels, or fractions with a '.'; x1, y1 exclusive): an EXR data "
                  "window inside the full frame")
      ->expected(4)
      ->type_name("X0 X1 Y0 Y1");
  render.add_option(
      "--tile", args.tile,
      "render stripe i of N (i/N, rows split evenly, 0 = top) for farms; `penumbra merge` assembles them");
  render.add_option("--debug-pixel", args.debug_pixel, "render only pixel x,y and print its value");
  render.add_flag("-q,--quiet", args.quiet, "no progress, warnings or summary on stderr");
  render.add_option("--progress", args.progress, progress_option_help())
      ->check(CLI::IsMember(progress_modes()));
  render.add_option(
      "--aov", args.aovs,
      "extra EXR layers, comma-separated or repeated: albedo, N, P, Z, UV, id (object_id, material_id + "
      "a name manifest), and for the path tracer samples, variance, light (emission, diffuse/specular "
      "direct/indirect); crypto_object, crypto_material, crypto_asset = Cryptomatte mattes of node, "
      "material and root node names; all = every one of these; cost = traversal cost of the camera rays "
      "(cost_nodes, cost_triangles, cost_shapes, cost_ns) and a heat map; vector = motion vectors in "
      "pixels to the frames 1/--fps before and after --time or --frame (vector.XYZW, Blender's Vector "
      "pass); velocity = the same surface's camera-space velocity in scene units per second "
      "(velocity.XYZ)");
  render.add_option("--deep", args.deep,
                    "also write a deep OpenEXR (R G B A Z ZBack id N albedo per surface and pixel) to this "
                    ".exr path; whitted and path");
  render.add_option("--cost-png", args.cost_png,
                    "heat map path for --aov cost (default: the EXR path with .cost.png)");
}

}  // namespace

void add_render_options(CLI::App& render, RenderArgs& args) {
  add_sampling_options(render, args);
  add_scene_options(render, args);
  add_output_options(render, args);
  add_camera_options(render, args.cam);
}

void note_given_options(const CLI::App& render, int argc, char** argv, RenderArgs& args) {
  for (int i = 0; i < argc; ++i) args.command_line += (i ? " " : "") + std::string(argv[i]);
  args.spp_given = render.count("--spp") > 0;
  args.depth_given = render.count("--max-depth") > 0;
  args.background_given = render.count("--background") > 0;
  args.ambient_given = render.count("--ambient") > 0;
  args.raster_shadows_given = render.count("--raster-shadows") > 0;
  args.shadow_map_size_given = render.count("--shadow-map-size") > 0;
  args.crypto_depth_given = render.count("--crypto-depth") > 0;
}

RenderRequest check_render_args(const RenderArgs& a) {
  RenderRequest q;
  check_output_paths(a, q);
  check_integrator_flags(a, q);
  check_scalar_flags(a, q);
  check_aovs(a, q);
  check_output_collisions(a, q);
  q.time = a.time;
  if (q.time && !std::isfinite(*q.time)) throw UsageError("--time must be a finite number of seconds");
  if (!(std::isfinite(a.spec.fps) && a.spec.fps > 0)) throw UsageError("--fps must be a finite number > 0");
  if (a.time && (a.frame || a.frames) && a.cam.turntable.empty())
    throw UsageError(
        "--time excludes --frame and --frames (which set the time), except with --turntable, whose "
        "frames turn the camera");
  const long long frame = a.frame ? parse_integer(*a.frame, -(1ll << 40), 1ll << 40, "--frame") : 0;
  // A turntable's frames turn the camera; the scene stays at --time or its static pose.
  if (a.frame && a.cam.turntable.empty()) q.time = double(frame) / a.spec.fps;
  q.rig = check_camera_args(a.cam, frame);
  q.budget = memory_budget(a.max_memory);
  q.spec = render_spec(a, q);
  // Motion blur poses the animation around a frame: frame 0 unless a time or frame is given.
  if (q.spec.motion_blur && !q.time) q.time = 0.0;
  return q;
}

PixelWindow parse_window(const RenderArgs& a, int width, int height) {
  if (!a.crop.empty() && !a.tile.empty()) throw UsageError("--crop and --tile exclude each other");
  if (!a.crop.empty()) {
    int v[4];
    for (int k = 0; k < 4; ++k) {
      const std::string& t = a.crop[size_t(k)];
      const int extent = k < 2 ? width : height;
      try {
        if (t.find('.') != std::string::npos) {
          size_t pos = 0;
          const double x = std::stod(t, &pos);
          if (pos != t.size() || !std::isfinite(x) || t.find_first_not_of("0123456789.") != std::string::npos)
            throw std::invalid_argument(t);
          if (x < 0 || x > 1) throw UsageError("--crop: fraction " + t + " is outside [0, 1]");
          v[k] = int(std::lround(x * extent));
        } else {
          v[k] = int(parse_integer(t, 0, extent, "--crop"));
        }
      } catch (const UsageError&) {
        throw;
      } catch (...) {
        throw UsageError("--crop: cannot parse '" + t + "' (expected x0 x1 y0 y1 in pixels or fractions)");
      }
    }
    const PixelWindow w{v[0], v[2], v[1], v[3]};
    if (w.empty()) throw UsageError("--crop: empty region (need x0 < x1 and y0 < y1)");
    return w;
  }
  if (!a.tile.empty()) {
    const auto [index, count] = split_pair(a.tile, '/', "--tile", "i/N with 0 <= i < N");
    const long long n = parse_integer(count, 1, 1ll << 40, "--tile N");
    if (n > height)
      throw UsageError("--tile: " + std::to_string(n) + " stripes exceed the " + std::to_string(height) +
                       " rows");
    long long i = -1;
    try {
      i = parse_integer(index, 0, n - 1, "--tile i");
    } catch (const UsageError&) {
      throw UsageError("--tile: expected i/N with 0 <= i < N, got '" + a.tile + "'");
    }
    return {0, int(int64_t(i) * height / n), width, int(int64_t(i + 1) * height / n)};
  }
  return {};
}

}  // namespace penumbra::cli
