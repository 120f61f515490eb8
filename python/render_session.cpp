// Scene sessions, render settings, renders and their EXR for the Python module.
#include "python/render_session.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "io/files/error.h"
#include "io/gltf/id_manifest.h"
#include "io/image/environment_io.h"
#include "render/accel_params.h"
#include "renderer/accel/factory.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/lights/environment.h"
#include "renderer/scene/camera.h"

namespace penumbra::python {

namespace {

std::string join(const auto& names) {
  std::string r;
  for (const auto& n : names) r += (r.empty() ? "" : ", ") + std::string(n);
  return r;
}

bool contains(const auto& names, const std::string& name) {
  for (const auto& n : names)
    if (name == n) return true;
  return false;
}

void check_choice(const char* setting, const std::string& value, const std::vector<std::string>& known) {
  if (!contains(known, value))
    throw std::invalid_argument(std::string(setting) + ": unknown value '" + value +
                                "' (known: " + join(known) + ")");
}

void check_non_negative(const char* setting, double v, const char* what = "") {
  if (!std::isfinite(v) || v < 0)
    throw std::invalid_argument(std::string(setting) + " must be finite and >= 0" + what);
}

void check_colour(const char* setting, const std::optional<Vec3f>& c) {
  if (!c) return;
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite((*c)[k]) || (*c)[k] < 0)
      throw std::invalid_argument(std::string(setting) + " must be finite and >= 0 in every channel");
}

bool is_path(const RenderSettings& s) {
  return s.integrator == "path";
}

/// The accelerator's name checked and its parameters applied, each of that structure.
AccelConfig accel_config(const RenderSettings& s) {
  check_choice("accel", s.accel, accelerator_names());
  AccelConfig config;
  for (const auto& p : s.accel_params) {
    apply_accel_param(config, p);
    const std::string prefix = p.substr(0, p.find('.'));
    if (prefix != s.accel)
      throw std::invalid_argument("accel_params " + p + ": a parameter of '" + prefix + "', but accel is '" +
                                  s.accel + "'");
  }
  validate(config.embree);
  validate(config.bvh);
  validate(config.kdtree);
  validate(config.grid);
  return config;
}

FilterType filter_type(const RenderSettings& s) {
  FilterType type = is_path(s) ? FilterType::BlackmanHarris : FilterType::Box;
  if (!s.filter.empty() && !parse_filter_type(s.filter, type))
    throw std::invalid_argument("filter: unknown value '" + s.filter +
                                "' (known: box, tent, gaussian, blackman-harris)");
  return type;
}

/// The renderer's configuration for an image whose aspect follows `hint` where the settings
/// leave the width or height open (as make_render_config in the command).
RenderConfig make_config(const RenderSettings& s, const std::set<std::string>& aovs, float hint) {
  RenderConfig cfg;
  const bool path = is_path(s);
  cfg.width = s.width;
  cfg.height = s.height;
  if (!cfg.width && !cfg.height) cfg.width = 960;
  if (!cfg.height) cfg.height = std::max(1, int(std::lround(float(cfg.width) / hint)));
  if (!cfg.width) cfg.width = std::max(1, int(std::lround(float(cfg.height) * hint)));
  cfg.window = s.window;
  cfg.spp = s.spp > 0 ? s.spp : (path ? 64 : 4);
  cfg.threads = s.threads;
  cfg.tile_size = s.tile_size;
  cfg.seed = s.seed;
  const FilterType type = filter_type(s);
  cfg.filter = make_filter(type, s.filter_width > 0 ? s.filter_width : default_filter_width(type));
  cfg.whitted.max_depth = s.max_depth >= 0 ? s.max_depth : 5;
  cfg.whitted.background = s.background.value_or(Vec3f{0, 0, 0});
  cfg.whitted.ambient = s.ambient.value_or(Vec3f{0.05f, 0.05f, 0.05f});
  cfg.raster.shadows = s.raster_shadows == "map"    ? RasterShadows::Map
                       : s.raster_shadows == "none" ? RasterShadows::None
                                                    : RasterShadows::Ray;
  cfg.path.max_depth = s.max_depth >= 0 ? s.max_depth : 12;
  cfg.path.rr_depth = s.rr_depth;
  cfg.path.clamp_indirect = s.clamp_indirect;
  cfg.path.strategy = s.light_sampling == "bsdf"    ? LightStrategy::Bsdf
                      : s.light_sampling == "light" ? LightStrategy::Light
                                                    : LightStrategy::Mis;
  cfg.sampler = s.sampler == "independent" ? SamplerType::Independent : SamplerType::Sobol;
  cfg.time_limit = s.time_limit;
  cfg.adaptive_threshold = s.adaptive;
  cfg.adaptive_min_spp = s.adaptive_min_spp;
  cfg.light_groups = aovs.count("light") > 0;
  return cfg;
}

/// The camera `spec` names: an index as Scene.cameras lists them, or a camera name. Throws
/// InputError listing the cameras if there is no such camera or the name is ambiguous.
int find_camera(const Scene& scene, const std::string& spec, const std::string& file) {
  std::string known;
  for (size_t i = 0; i < scene.cameras.size(); ++i)
    known += (known.empty() ? "" : ", ") + std::to_string(i) + " '" + scene.cameras[i].name + "'";
  const std::string listing = scene.cameras.empty() ? "the scene has no camera" : "cameras: " + known;
  if (spec.find_first_not_of("0123456789") == std::string::npos) {
    const unsigned long long i = spec.size() <= 9 ? std::stoull(spec) : ~0ull;
    if (i >= scene.cameras.size())
      throw InputError(file, "camera", "camera " + spec + " does not exist (" + listing + ")");
    return int(i);
  }
  int found = -1;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    if (scene.cameras[i].name != spec) continue;
    if (found >= 0)
      throw InputError(file, "camera",
                       "camera name '" + spec + "' is ambiguous (" + listing + "); use an index");
    found = int(i);
  }
  if (found < 0) throw InputError(file, "camera", "no camera named '" + spec + "' (" + listing + ")");
  return found;
}

/// Removes the default key light a render added, however the render ends.
struct DefaultLightGuard {
  Scene& scene;
  bool added = false;
  ~DefaultLightGuard() {
    if (added) scene.lights.pop_back();
  }
};

}  // namespace

uint64_t default_memory_budget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 8ull << 30;
  return uint64_t(pages) * uint64_t(page) / 2;
}

std::shared_ptr<SceneSession> load_session(const std::string& file, const GltfLoadOptions& options) {
  auto session = std::make_shared<SceneSession>();
  session->file = file;
  session->loaded = load_gltf(file, options);
  session->loaded_at_time = options.time.has_value();
  return session;
}

bool pose_session(SceneSession& session, double time) {
  if (!session.loaded.animation) return false;
  uint64_t moved = 0;
  if (!pose_gltf_scene(*session.loaded.animation, time, session.loaded.scene, &moved)) return false;
  if (moved == 0) return true;
  session.area_lights.reset();
  try {
    if (session.accel && !session.accel->update_instances(instance_views(session.loaded.scene)))
      session.accel.reset();
  } catch (...) {
    session.accel.reset();
    throw;
  }
  return true;
}

std::set<std::string> check_settings(const RenderSettings& s, const std::vector<std::string>& aov_names) {
  check_choice("integrator", s.integrator, {"whitted", "path", "raster"});
  check_choice("raster_shadows", s.raster_shadows, {"ray", "map", "none"});
  if (s.integrator != "raster" && s.raster_shadows != "ray")
    throw std::invalid_argument("raster_shadows needs integrator 'raster'");
  const bool path = is_path(s);
  if (s.width < 0 || s.width > kMaxImageSize || s.height < 0 || s.height > kMaxImageSize)
    throw std::invalid_argument("width and height must be in [1, 16384] (0: from the camera's aspect)");
  if (s.spp < 0 || s.spp > kMaxSpp) throw std::invalid_argument("spp must be in [1, 65536] (0: the default)");
  if (s.max_depth < -1 || s.max_depth > kMaxDepth)
    throw std::invalid_argument("max_depth must be in [0, 64] (-1: the default)");
  accel_config(s);
  const FilterType type = filter_type(s);
  const float width = s.filter_width > 0 ? s.filter_width : default_filter_width(type);
  if (!std::isfinite(s.filter_width) || s.filter_width < 0 || width > kMaxFilterWidth)
    throw std::invalid_argument("filter_width must be in (0, 16] pixels (0: the filter's default)");
  check_choice("light_sampling", s.light_sampling, {"mis", "bsdf", "light"});
  check_choice("sampler", s.sampler, {"sobol", "independent"});
  check_colour("background", s.background);
  check_colour("ambient", s.ambient);
  check_colour("env_color", s.env_color);
  check_non_negative("clamp_indirect", s.clamp_indirect, " (0 = off)");
  check_non_negative("adaptive", s.adaptive, " (0 = off)");
  check_non_negative("time_limit", s.time_limit, " (seconds, 0 = none)");
  check_non_negative("env_intensity", s.env_intensity);
  if (!std::isfinite(s.env_rotation)) throw std::invalid_argument("env_rotation must be finite");
  if (s.env_color && !s.env_map.empty())
    throw std::invalid_argument("env_color and env_map exclude each other");
  if (path && (s.background || s.ambient))
    throw std::invalid_argument(std::string(s.background ? "background" : "ambient") +
                                " applies to integrator 'whitted'; the path tracer is lit by the scene's "
                                "lights and env_color / env_map");
  if (!path)
    for (const auto& [given, name] : {std::pair{s.env_color.has_value(), "env_color"},
                                      {!s.env_map.empty(), "env_map"},
                                      {s.time_limit > 0, "time_limit"},
                                      {s.adaptive > 0, "adaptive"},
                                      {s.clamp_indirect > 0, "clamp_indirect"},
                                      {s.light_sampling != "mis", "light_sampling"},
                                      {s.sampler != "sobol", "sampler"}})
      if (given) throw std::invalid_argument(std::string(name) + " needs integrator 'path'");
  std::set<std::string> aovs;
  for (const auto& name : aov_names) {
    if (name == "all") {
      aovs.insert(std::begin(kDataAovNames), std::end(kDataAovNames));
      if (path) aovs.insert(std::begin(kPathAovNames), std::end(kPathAovNames));
      continue;
    }
    if (!contains(kDataAovNames, name) && !contains(kPathAovNames, name))
      throw std::invalid_argument("aovs: unknown AOV '" + name + "' (known: " + join(kDataAovNames) + ", " +
                                  join(kPathAovNames) + ", all)");
    if (!path && contains(kPathAovNames, name))
      throw std::invalid_argument("aovs: '" + name + "' needs integrator 'path'");
    aovs.insert(name);
  }
  // The library's own range checks (tile size, threads, depths, adaptive_min_spp) on a
  // stand-in size.
  RenderConfig probe = make_config(s, aovs, 16.0f / 9.0f);
  probe.window = {};
  validate(probe);
  return aovs;
}

RenderOutput render_session(SceneSession& session, const RenderSettings& settings,
                            const std::vector<std::string>& aov_names) {
  RenderOutput out;
  out.aovs = check_settings(settings, aov_names);
  out.settings = settings;
  out.scene_file = session.file;
  const bool path = is_path(settings);
  AccelConfig accel_cfg = accel_config(settings);

  std::lock_guard<std::mutex> lock(session.mutex);
  Scene& scene = session.loaded.scene;
  // Phase: camera, image size and the renderer's configuration.
  out.camera_index = settings.camera.empty() ? (scene.cameras.empty() ? -1 : 0)
                                             : find_camera(scene, settings.camera, session.file);
  const Camera* chosen = out.camera_index >= 0 ? &scene.cameras[size_t(out.camera_index)] : nullptr;
  const float hint = chosen && chosen->aspect > 0 ? chosen->aspect : 16.0f / 9.0f;
  out.config = make_config(settings, out.aovs, hint);
  validate(out.config);
  const RenderConfig& cfg = out.config;
  out.camera = chosen ? *chosen : frame_bounds(compute_bounds(scene), float(cfg.width) / float(cfg.height));
  try {
    validate_camera(out.camera, cfg.width, cfg.height);
  } catch (const std::invalid_argument& e) {
    throw InputError(session.file,
                     out.camera_index >= 0 ? "cameras[" + std::to_string(out.camera_index) + "]" : "the view",
                     e.what());
  }

  // Phase: lights: the environment, the emissive triangles, the default key light.
  Environment own_env;
  const Environment* env = &own_env;
  if (settings.env_color)
    own_env = make_constant_environment(*settings.env_color * settings.env_intensity);
  else if (!settings.env_map.empty())
    own_env = load_environment(settings.env_map, settings.env_intensity, settings.env_rotation,
                               default_memory_budget());
  else if (session.loaded.environment)
    env = session.loaded.environment.get();
  if (path && !session.area_lights) session.area_lights = build_area_lights(scene);
  DefaultLightGuard guard{scene};
  if (scene.lights.empty() && (!path || (session.area_lights->pmf.empty() && is_black(*env)))) {
    scene.lights.push_back(default_key_light(out.camera));
    guard.added = true;
    out.default_light = true;
  }

  // Phase: the acceleration structure, kept while the name and parameters stay the same. An
  // animated scene loaded at a time keeps Embree's still placements apart, as the command does.
  accel_cfg.embree.world_apart = session.loaded.info.animation_count != 0 && session.loaded_at_time;
  std::string key = settings.accel;
  for (const auto& p : settings.accel_params) key += " " + p;
  if (!session.accel || session.accel_key != key) {
    session.accel.reset();
    session.accel = make_scene_accelerator(settings.accel, scene, accel_cfg);
    session.accel_key = key;
  }
  const Accelerator& accel = *session.accel;

  // Phase: the beauty, then the layers from the same camera samples.
  if (path) {
    const AreaLights& area = *session.area_lights;
    PathImage image = render_path(scene, accel, PathLights{&area, env}, out.camera, cfg, &out.stats);
    out.film = std::move(image.film);
    if (out.aovs.count("samples")) {
      out.samples = std::move(image.samples);
      out.samples_f.assign(out.samples.begin(), out.samples.end());
    }
    if (out.aovs.count("variance")) out.variance = std::move(image.variance);
    if (out.aovs.count("light")) out.groups = std::move(image.groups);
  } else if (settings.integrator == "raster") {
    out.film = render_raster(scene, &accel, out.camera, cfg, &out.stats);
  } else {
    out.film = render_whitted(scene, accel, out.camera, cfg, &out.stats);
  }
  bool data = false;
  for (const char* name : kDataAovNames) data |= out.aovs.count(name) > 0;
  if (data)
    out.data = settings.integrator == "raster"
                   ? render_raster_aovs(scene, out.camera, cfg)
                   : render_data_aovs(scene, accel, out.camera, cfg,
                                      path ? IntegratorType::Path : IntegratorType::Whitted);
  if (out.aovs.count("id")) out.id_manifest = penumbra::id_manifest(scene, session.loaded.info);
  return out;
}

void write_render_exr(const RenderOutput& out, const std::filesystem::path& path,
                      const ExrWriteOptions& options) {
  const RenderConfig& cfg = out.config;
  ExrOptions exr;
  exr.half = options.half;
  exr.compression = options.compression;
  exr.multipart = options.multipart;
  exr.metadata = {
      {"penumbra:scene", out.scene_file},
      {"penumbra:camera", out.camera.name},
      {"penumbra:spp", std::to_string(cfg.spp)},
      {"penumbra:integrator", out.settings.integrator},
      {"penumbra:filter", std::string(filter_name(cfg.filter.type)) + " " + std::to_string(cfg.filter.width)},
      {"penumbra:version", PENUMBRA_VERSION}};
  exr.metadata.insert(exr.metadata.end(), options.metadata.begin(), options.metadata.end());
  const auto& aovs = out.aovs;
  const ChannelType colour = options.half ? ChannelType::Half : ChannelType::Float;
  const DataAovs& d = out.data;
  if (aovs.count("albedo"))
    for (int c = 0; c < 3; ++c)
      exr.extra.push_back({std::string("albedo.") + "RGB"[c], &d.albedo, colour, 3, c});
  if (aovs.count("N"))
    for (int c = 0; c < 3; ++c)
      exr.extra.push_back({std::string("N.") + "XYZ"[c], &d.normal, ChannelType::Float, 3, c});
  if (aovs.count("P"))
    for (int c = 0; c < 3; ++c)
      exr.extra.push_back({std::string("P.") + "XYZ"[c], &d.position, ChannelType::Float, 3, c});
  if (aovs.count("Z")) exr.extra.push_back({"Z", &d.depth, ChannelType::Float});
  if (aovs.count("UV"))
    for (int c = 0; c < 2; ++c)
      exr.extra.push_back({std::string("UV.") + "UV"[c], &d.uv, ChannelType::Float, 2, c});
  if (aovs.count("id")) {
    exr.extra.push_back({"object_id.X", &d.object_id, ChannelType::Float});
    exr.extra.push_back({"material_id.X", &d.material_id, ChannelType::Float});
    exr.metadata.push_back({"penumbra:manifest", out.id_manifest});
  }
  if (aovs.count("samples")) exr.extra.push_back({"samples.X", &out.samples_f, ChannelType::Float});
  if (aovs.count("variance")) exr.extra.push_back({"variance.X", &out.variance, ChannelType::Float});
  if (aovs.count("light"))
    for (int g = 0; g < kLightGroupCount; ++g)
      for (int c = 0; c < 3; ++c)
        exr.extra.push_back({std::string(kLightGroupNames[g]) + "." + "RGB"[c], &out.groups, colour,
                             kLightGroupChannels, g * 3 + c});
  write_exr(out.film, path, exr);
}

}  // namespace penumbra::python
