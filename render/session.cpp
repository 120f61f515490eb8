// The render session's phases.
#include "render/session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <stdexcept>

#include "io/files/error.h"
#include "io/files/hash.h"
#include "io/gltf/id_manifest.h"
#include "io/image/environment_io.h"
#include "render/accel_params.h"
#include "render/denoise_render.h"
#include "render/motion.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/scene/curve_size.h"

namespace penumbra {

namespace {

/// A camera's frame (eye, u, v, w) as exact text.
std::string frame_text(const Camera& c) {
  char text[320];
  std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g u %.9g,%.9g,%.9g v %.9g,%.9g,%.9g w %.9g,%.9g,%.9g",
                double(c.eye.x), double(c.eye.y), double(c.eye.z), double(c.u.x), double(c.u.y),
                double(c.u.z), double(c.v.x), double(c.v.y), double(c.v.z), double(c.w.x), double(c.w.y),
                double(c.w.z));
  return text;
}

/// Removes the default key light a render added, however the render ends.
struct DefaultLightGuard {
  LoadedScene& loaded;
  const PreparedRender* prepared = nullptr;
  ~DefaultLightGuard() {
    if (prepared) finish_render(loaded, *prepared);
  }
};

/// Whether any mesh keeps vertex positions per motion step.
bool scene_deforms(const Scene& scene) {
  return std::any_of(scene.meshes.begin(), scene.meshes.end(),
                     [](const Mesh& m) { return m.motion_steps >= 2; });
}

/// The structure's key: its name and parameters, and whether it was built over moving instances
/// or deforming meshes.
std::string structure_key(const RenderSpec& spec, const Scene& scene) {
  std::string key = spec.accel;
  for (const auto& p : spec.accel_params) key += " " + p;
  if (!scene.instance_motion.empty()) key += " (motion)";
  if (scene_deforms(scene)) key += " (deforming)";
  // Point and line radii follow the camera when given in pixels: a structure is kept only for
  // the same radii (an FNV-1a hash of their bits).
  uint64_t h = 1469598103934665603ull;
  bool curves = false;
  for (const Mesh& m : scene.meshes)
    if (renders_as_curves(m)) {
      curves = true;
      for (float r : m.radii) {
        uint32_t bits;
        std::memcpy(&bits, &r, 4);
        h = (h ^ bits) * 1099511628211ull;
      }
    }
  if (curves) key += " (curves " + std::to_string(h) + ")";
  // Splats: a structure is kept only for the same clouds in the same places.
  if (!scene.splat_instances.empty()) {
    uint64_t g = 1469598103934665603ull;
    auto mix = [&g](const void* p, size_t n) {
      for (size_t i = 0; i < n; ++i) g = (g ^ static_cast<const uint8_t*>(p)[i]) * 1099511628211ull;
    };
    for (const SplatInstance& si : scene.splat_instances) {
      mix(&si.to_world, sizeof si.to_world);
      const uint64_t n = scene.splat_clouds[size_t(si.cloud)].positions.size();
      mix(&n, sizeof n);
    }
    key += " (splats " + std::to_string(g) + ")";
  }
  return key;
}

/// The environment: a constant colour, a map file, else the file's image-based light, else black.
std::shared_ptr<const Environment> choose_environment(const LoadedScene& loaded, const RenderSpec& s,
                                                      uint64_t budget) {
  if (s.env_color)
    return std::make_shared<Environment>(make_constant_environment(*s.env_color * s.env_intensity));
  if (!s.env_map.empty())
    return std::make_shared<Environment>(
        load_environment(s.env_map, s.env_intensity, s.env_rotation, budget));
  if (loaded.environment) return loaded.environment;
  return std::make_shared<Environment>();
}

/// The depth (along the view axis) of what pixel `at` shows through the pinhole (a layer of
/// splats where its transmittance falls below 1/2), else of the scene bounds' centre; found with
/// a brute-force scan (one ray, no build).
float autofocus_depth(const Scene& scene, const Camera& cam, const RenderConfig& cfg, Vec2f at) {
  const std::unique_ptr<Accelerator> accel = make_scene_accelerator("brute", scene, AccelConfig{});
  const Ray ray = generate_camera_ray(cam, cfg.width, cfg.height, at.x + 0.5f, at.y + 0.5f);
  Hit hit;
  SplatLayer splats;
  float depth = 0;
  const bool found = intersect_visible(scene, *accel, ray, hit, scene_needs_hit_filter(scene), &splats);
  if (splats.median.valid())
    depth = dot(ray.org + ray.dir * splats.median.t - cam.eye, -cam.w);
  else if (found)
    depth = dot(ray.org + ray.dir * hit.t - cam.eye, -cam.w);
  else if (!compute_bounds(scene).empty())
    depth = dot(compute_bounds(scene).center() - cam.eye, -cam.w);
  return depth > 0 && std::isfinite(depth) ? depth : 1.0f;
}

/// The thin lens the spec asks for, on the prepared camera (a pinhole for the raster preview,
/// which says so in `warnings`).
void set_lens(PreparedRender& p, const Scene& scene, const std::string& file) {
  const RenderSpec& s = p.spec;
  if (!wants_depth_of_field(s)) return;
  if (p.integrator() == IntegratorType::Raster) {
    p.warnings.push_back(s.fstop > 0
                             ? "the raster preview renders through a pinhole: it ignores depth of "
                               "field (fstop); use integrator 'whitted' or 'path' to see it"
                             : "the raster preview renders through a pinhole: it ignores depth of "
                               "field (aperture_radius); use integrator 'whitted' or 'path' to see it");
    return;
  }
  const RenderConfig& cfg = p.config;
  ThinLens lens;
  if (s.fstop > 0) {
    if (p.camera.projection == Projection::Orthographic)
      throw std::invalid_argument(
          "fstop needs a perspective camera (an f-number needs a focal length); give an orthographic camera "
          "aperture_radius");
    lens.radius = fstop_lens_radius(p.camera, s.fstop, cfg.width, cfg.height);
  } else {
    lens.radius = s.aperture_radius;
  }
  lens.blades = s.aperture_blades;
  lens.rotation = s.aperture_rotation * kPi / 180;
  lens.ratio = s.aperture_ratio;
  if (s.focus_distance > 0) {
    lens.focus_distance = s.focus_distance;
  } else {
    Vec2f at{0.5f * float(cfg.width) - 0.5f, 0.5f * float(cfg.height) - 0.5f};
    if (!s.focus_at.empty()) {
      at = parse_focus_at(s.focus_at);
      if (!(at.x >= 0 && at.y >= 0 && at.x < float(cfg.width) && at.y < float(cfg.height)))
        throw std::invalid_argument("focus_at: pixel " + s.focus_at + " lies outside the " +
                                    std::to_string(cfg.width) + " x " + std::to_string(cfg.height) +
                                    " image");
    }
    lens.focus_distance = autofocus_depth(scene, p.camera, cfg, at);
  }
  p.camera.lens = lens;
  try {
    validate_camera(p.camera, cfg.width, cfg.height);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, "the lens", e.what());
  }
}

/// The keys of a camera that `turn` moves over the render's shutter (spec.shutter frame
/// intervals centred spec.shutter_offset frames after the frame): at spec.motion_steps times at
/// least, and more (up to 65) until consecutive keys turn by at most a degree, so that the eye
/// follows its arc closely rather than one chord between the shutter's ends. Empty when the
/// camera does not move over the shutter.
std::vector<MotionKey> turning_camera_motion(const PreparedRender& p, const Scene& scene,
                                             const TurnCamera& turn) {
  const double open = double(p.spec.shutter_offset) - 0.5 * double(p.spec.shutter);
  const double length = double(p.spec.shutter);
  const float cos_degree = float(std::cos(kPi / 180.0));
  for (int steps = std::max(p.spec.motion_steps, 2);; steps = 2 * steps - 1) {
    std::vector<Camera> cams;
    for (int k = 0; k < steps; ++k)
      cams.push_back(turn(scene, p.camera_index, p.config.width, p.config.height,
                          open + length * double(k) / double(steps - 1)));
    bool moves = false, fine = true;
    for (size_t k = 1; k < cams.size(); ++k) {
      moves = moves || frame_text(cams[k]) != frame_text(cams[0]);
      fine =
          fine && dot(cams[k].w, cams[k - 1].w) >= cos_degree && dot(cams[k].u, cams[k - 1].u) >= cos_degree;
    }
    if (!moves) return {};
    if (fine || steps >= 65) {
      std::vector<Affine3f> maps;
      for (const Camera& c : cams) maps.push_back(camera_frame(c));
      return make_motion_keys(maps);
    }
  }
}

}  // namespace

int find_camera(const Scene& scene, const std::string& spec, const std::string& file,
                const std::string& element) {
  std::string known;
  for (size_t i = 0; i < scene.cameras.size(); ++i)
    known += (known.empty() ? "" : ", ") + std::to_string(i) + " '" + scene.cameras[i].name + "'";
  const std::string listing = scene.cameras.empty() ? "the scene has no camera" : "cameras: " + known;
  if (!spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos) {
    const unsigned long long i = spec.size() <= 9 ? std::stoull(spec) : ~0ull;
    if (i >= scene.cameras.size())
      throw InputError(file, element, "camera " + spec + " does not exist (" + listing + ")");
    return int(i);
  }
  int found = -1;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    if (scene.cameras[i].name != spec) continue;
    if (found >= 0)
      throw InputError(file, element,
                       "camera name '" + spec + "' is ambiguous (" + listing + "); use an index");
    found = int(i);
  }
  if (found < 0) throw InputError(file, element, "no camera named '" + spec + "' (" + listing + ")");
  return found;
}

IntegratorType PreparedRender::integrator() const {
  return spec.integrator == "path"     ? IntegratorType::Path
         : spec.integrator == "raster" ? IntegratorType::Raster
                                       : IntegratorType::Whitted;
}

RenderView render_view(const Scene& scene, const RenderSpec& spec, const PrepareOptions& o) {
  validate(spec);
  RenderView v;
  v.camera_index = o.camera_index >= -1  ? o.camera_index
                   : spec.camera.empty() ? (scene.cameras.empty() ? -1 : 0)
                                         : find_camera(scene, spec.camera, o.scene_file);
  const Camera* chosen = v.camera_index >= 0 ? &scene.cameras[size_t(v.camera_index)] : nullptr;
  const float hint = chosen && chosen->aspect > 0 ? chosen->aspect : 16.0f / 9.0f;
  v.spec = resolve(spec, hint);
  v.config = make_render_config(v.spec);
  validate(v.config);
  const RenderConfig& cfg = v.config;
  v.camera = o.place  ? o.place(scene, v.camera_index, cfg.width, cfg.height)
             : chosen ? *chosen
                      : frame_bounds(compute_bounds(scene), float(cfg.width) / float(cfg.height));
  try {
    validate_camera(v.camera, cfg.width, cfg.height);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.scene_file,
                     v.camera_index >= 0 ? "cameras[" + std::to_string(v.camera_index) + "]" : "the view",
                     e.what());
  }
  return v;
}

PreparedRender prepare_render(LoadedScene& loaded, const RenderSpec& spec, const PrepareOptions& o) {
  Scene& scene = loaded.scene;
  RenderView view = render_view(scene, spec, o);
  PreparedRender p;
  p.camera_index = view.camera_index;
  p.spec = std::move(view.spec);
  p.config = view.config;
  p.camera = view.camera;
  const uint64_t env_budget = o.charge_budget ? o.charge_budget(p.config) : o.env_budget;
  const RenderConfig& cfg = p.config;
  if (p.spec.wireframe) wireframe_config(p.spec, loaded.info);  // names the nodes before any work
  set_curve_radii(scene, p.camera, cfg.height, parse_curve_size(p.spec.point_size, "point_size"),
                  parse_curve_size(p.spec.line_width, "line_width"));
  set_lens(p, scene, o.scene_file);
  if (p.spec.motion_blur && p.integrator() == IntegratorType::Raster)
    p.warnings.push_back(
        "the raster preview renders the frame's time: it ignores motion blur (motion_blur); "
        "use integrator 'whitted' or 'path' to see it");
  // The lights: the environment, the emissive triangles and shapes, the default key light.
  const bool path = p.integrator() == IntegratorType::Path;
  p.environment = choose_environment(loaded, p.spec, env_budget);
  if (path)
    p.area_lights = o.area_lights ? o.area_lights : std::make_shared<AreaLights>(build_area_lights(scene));
  if (scene.lights.empty() && (!path || (p.area_lights->pmf.empty() && is_black(*p.environment)))) {
    scene.lights.push_back(default_key_light(p.camera));
    p.default_light = true;
  }
  if (o.turn && p.spec.motion_blur) p.camera.motion = turning_camera_motion(p, scene, o.turn);
  SceneIdentity identity = o.identity;
  if (wants_motion_layers(p.spec.aovs)) {
    if (o.turn) {
      auto m = std::make_shared<MotionFrames>();
      m->same_scene = true;
      m->previous_camera = o.turn(scene, p.camera_index, cfg.width, cfg.height, -1);
      m->next_camera = o.turn(scene, p.camera_index, cfg.width, cfg.height, 1);
      identity.vector_cameras = frame_text(m->previous_camera) + " | " + frame_text(m->next_camera);
      p.motion = std::move(m);
    } else if (o.time)
      p.motion = std::make_shared<const MotionFrames>(load_motion_frames(scene, p, *o.time, o));
    else
      p.warnings.push_back(
          std::string(p.spec.aovs.count("vector") ? "the vector layer" : "the velocity layer") +
          " of a render at the file's static pose is 0 everywhere (the static pose is no point of the "
          "animation's timeline): give the render a time for motion");
  }
  if (!p.spec.env_color && !p.spec.env_map.empty()) identity.env_sha256 = sha256_file(p.spec.env_map);
  p.identity = render_identity(p.spec, p.camera, identity);
  return p;
}

MotionFrames load_motion_frames(const Scene& scene, const PreparedRender& p, double time,
                                const PrepareOptions& o) {
  if (!o.load_at)
    throw std::invalid_argument(
        "the vector layer needs the scene at other times: this front end cannot load it");
  const RenderConfig& cfg = p.config;
  const auto load = [&](double t, LoadedScene& loaded, Camera& camera) {
    loaded = o.load_at(t);
    char at[64];
    std::snprintf(at, sizeof at, "the scene at %.9g s", t);
    const std::string why = check_motion_frame(scene, loaded.scene);
    if (!why.empty())
      throw InputError(o.scene_file, at,
                       "the vector layer cannot follow the surfaces to this time (" + why + ")");
    // The file's camera as posed at that time; a camera placed from the command line or
    // framed from the bounds stays where the render has it.
    const Scene& posed = loaded.scene;
    camera = p.camera;
    if (p.camera_index < 0) return;
    if (size_t(p.camera_index) >= posed.cameras.size())
      throw InputError(o.scene_file, at,
                       "the vector layer's camera " + std::to_string(p.camera_index) +
                           " is not in the scene at this time");
    camera = o.place ? o.place(posed, p.camera_index, cfg.width, cfg.height)
                     : posed.cameras[size_t(p.camera_index)];
  };
  MotionFrames m;
  load(time - 1.0 / p.spec.fps, m.previous, m.previous_camera);
  load(time + 1.0 / p.spec.fps, m.next, m.next_camera);
  return m;
}

void finish_render(LoadedScene& loaded, const PreparedRender& prepared) {
  if (prepared.default_light && !loaded.scene.lights.empty()) loaded.scene.lights.pop_back();
}

bool needs_structure(const RenderSpec& spec, bool probe) {
  return spec.integrator != "raster" || spec.raster_shadows == "ray" || spec.aovs.count("cost") ||
         spec.wireframe || wants_motion_layers(spec.aovs) || !crypto_layers(spec.aovs).empty() || probe;
}

Structure build_structure(const Scene& scene, const RenderSpec& spec, bool world_apart, Structure previous,
                          bool moved_vertices) {
  AccelConfig config = accel_config(spec.accel, spec.accel_params);
  config.embree.world_apart = world_apart;
  const std::string key = structure_key(spec, scene);
  // A structure over moving instances or deforming meshes is built for its shutter: never kept
  // for another.
  if (previous.accel && previous.key == key && scene.instance_motion.empty() && !scene_deforms(scene)) {
    if (!moved_vertices) return previous;
    const RefitReport r =
        refit_or_rebuild_scene(previous.accel, previous.built_sah, spec.accel, scene, config);
    previous.update = r.refitted ? "refitted" : "rebuilt";
    if (r.refitted) {
      char growth[64];
      std::snprintf(growth, sizeof growth, "SAH cost %.3gx its last build's", r.growth);
      previous.reason = growth;
    } else {
      previous.reason = r.reason;
    }
    return previous;
  }
  previous.accel.reset();  // its memory is free before the new one is built
  Structure s;
  s.accel = make_scene_accelerator(spec.accel, scene, config);
  s.key = key;
  s.built_sah = s.accel->stats().sah_cost;
  return s;
}

RenderImage render_image(const Scene& scene, const Accelerator* accel, const PreparedRender& p,
                         const RenderHooks& hooks) {
  RenderImage out;
  RenderConfig cfg = p.config;
  if (hooks.stop) cfg.stop = hooks.stop;
  switch (p.integrator()) {
    case IntegratorType::Path: {
      PathAccumulators own;
      PathAccumulators* state = hooks.resume ? hooks.resume : &own;
      PathImage image = render_path(scene, *accel, p.path_lights(), p.camera, cfg, &out.stats, hooks.progress,
                                    state, hooks.after_pass);
      out.film = std::move(image.film);
      out.samples = std::move(image.samples);
      out.variance = std::move(image.variance);
      out.groups = std::move(image.groups);
      out.halves = std::move(image.halves);
      out.complete = state->complete;
      break;
    }
    case IntegratorType::Raster:
      out.film = render_raster(scene, accel, p.camera, cfg, &out.stats, hooks.progress);
      break;
    case IntegratorType::Whitted:
      out.film = render_whitted(scene, *accel, p.camera, cfg, &out.stats, hooks.progress);
      break;
  }
  return out;
}

void render_pixel(const Scene& scene, const Accelerator* accel, const PreparedRender& p, int x, int y,
                  float rgba[4], RayCounts& counts) {
  switch (p.integrator()) {
    case IntegratorType::Path:
      render_path_pixel(scene, *accel, p.path_lights(), p.camera, p.config, x, y, rgba, counts);
      break;
    case IntegratorType::Raster: {
      RenderConfig one = p.config;
      one.window = {x, y, x + 1, y + 1};
      RenderStats st;
      const Film f = render_raster(scene, accel, p.camera, one, &st);
      for (int c = 0; c < 4; ++c) rgba[c] = f.rgba[size_t(c)];
      counts = st.rays;
      break;
    }
    case IntegratorType::Whitted:
      render_whitted_pixel(scene, *accel, p.camera, p.config, x, y, rgba, counts);
      break;
  }
}

std::vector<std::string> crypto_layers(const std::set<std::string>& aovs) {
  std::vector<std::string> layers;
  for (const auto& [aov, layer] : {std::pair{"crypto_object", "CryptoObject"},
                                   {"crypto_material", "CryptoMaterial"},
                                   {"crypto_asset", "CryptoAsset"}})
    if (aovs.count(aov)) layers.push_back(layer);
  return layers;
}

bool wants_data_aovs(const std::set<std::string>& aovs) {
  for (const char* name : {"albedo", "N", "P", "Z", "UV", "id", "halves"})
    if (aovs.count(name)) return true;
  return false;
}

bool wants_motion_layers(const std::set<std::string>& aovs) {
  return aovs.count("vector") || aovs.count("velocity");
}

std::vector<std::string> crypto_instance_names(const Scene& scene, const GltfInfo& info,
                                               const std::string& layer) {
  auto node_name = [&](int n) {
    return size_t(n) < info.node_names.size() ? info.node_names[size_t(n)]
                                              : "nodes[" + std::to_string(n) + "]";
  };
  // An object's name in the object and asset layers: its node's, or its topmost ancestor's
  // (bounded: the loader rejects cycles); `unnamed` without a node.
  auto object_name = [&](int node, const std::string& unnamed) {
    if (node < 0) return unnamed;
    if (layer != "CryptoAsset") return node_name(node);
    int root = node;
    for (size_t step = 0; step < info.node_parents.size() && size_t(root) < info.node_parents.size() &&
                          info.node_parents[size_t(root)] >= 0;
         ++step)
      root = info.node_parents[size_t(root)];
    return node_name(root);
  };
  std::vector<std::string> names;
  names.reserve(scene.instances.size() + scene.splat_instances.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (layer == "CryptoMaterial") {
      const int m = instance_material(scene, inst);
      names.push_back(m >= 0 ? scene.materials[size_t(m)].name : "default");
    } else {
      names.push_back(object_name(inst.node, "instances[" + std::to_string(i) + "]"));
    }
  }
  // The splat clouds' placements, named likewise ("splats" as their material).
  for (size_t i = 0; i < scene.splat_instances.size(); ++i)
    names.push_back(layer == "CryptoMaterial" ? std::string("splats")
                                              : object_name(scene.splat_instances[i].node,
                                                            "splat_instances[" + std::to_string(i) + "]"));
  return names;
}

WireframeConfig wireframe_config(const RenderSpec& spec, const GltfInfo& info) {
  WireframeConfig w;
  w.width = spec.wireframe_width;
  w.hidden = spec.wireframe_hidden == "dim"      ? WireframeHidden::Dim
             : spec.wireframe_hidden == "dashed" ? WireframeHidden::Dashed
                                                 : WireframeHidden::Off;
  size_t start = 0;
  while (start < spec.wireframe_nodes.size()) {
    size_t end = spec.wireframe_nodes.find(',', start);
    if (end == std::string::npos) end = spec.wireframe_nodes.size();
    const std::string item = spec.wireframe_nodes.substr(start, end - start);
    start = end + 1;
    int found = -1;
    for (size_t i = 0; i < info.node_names.size() && found < 0; ++i)
      if (info.node_names[i] == item) found = int(i);
    if (found < 0 && !item.empty() && item.find_first_not_of("0123456789") == std::string::npos &&
        item.size() < 10 && std::stoul(item) < info.node_names.size())
      found = int(std::stoul(item));
    if (found < 0)
      throw std::invalid_argument("wireframe_nodes: no node '" + item + "' (the file has " +
                                  std::to_string(info.node_names.size()) +
                                  " nodes: give their names or indices, comma-separated)");
    w.nodes.push_back(found);
  }
  return w;
}

void overlay_wireframe(RenderImage& image, const RenderLayers& layers, const PreparedRender& p) {
  if (!p.spec.wireframe || layers.wireframe.empty()) return;
  overlay_wireframe(image.film, layers.wireframe, parse_wireframe_color(p.spec.wireframe_color));
}

RenderLayers render_layers(const LoadedScene& loaded, const Accelerator* accel, const PreparedRender& p) {
  RenderLayers out;
  const Scene& scene = loaded.scene;
  const IntegratorType integrator = p.integrator();
  if (p.spec.wireframe)
    out.wireframe =
        render_wireframe(scene, *accel, p.camera, p.config, wireframe_config(p.spec, loaded.info));
  if (wants_data_aovs(p.spec.aovs))
    out.data = integrator == IntegratorType::Raster
                   ? render_raster_aovs(scene, p.camera, p.config)
                   : render_data_aovs(scene, *accel, p.camera, p.config, integrator);
  if (p.spec.aovs.count("id")) out.id_manifest = id_manifest(scene, loaded.info);
  if (p.spec.aovs.count("cost")) out.cost = render_cost(*accel, p.camera, p.config, integrator);
  if (wants_motion_layers(p.spec.aovs)) {
    const bool velocity = p.spec.aovs.count("velocity") != 0;
    if (p.motion) {
      const MotionFrames& m = *p.motion;
      out.vector = render_motion_vectors(
          scene, *accel, p.camera, p.config, {&m.previous_scene(scene), m.previous_camera},
          {&m.next_scene(scene), m.next_camera}, velocity ? &out.velocity : nullptr, 1.0 / p.spec.fps);
    } else {
      const PixelWindow win = render_window(p.config);
      out.vector.assign(size_t(win.width()) * size_t(win.height()) * kMotionVectorChannels, 0.0f);
      if (velocity) out.velocity.assign(size_t(win.width()) * size_t(win.height()) * kVelocityChannels, 0.0f);
    }
    if (!p.spec.aovs.count("vector")) out.vector = {};
  }
  const std::vector<std::string> crypto = crypto_layers(p.spec.aovs);
  if (crypto.empty()) return out;
  std::vector<CryptoLayerIds> layers;
  for (const std::string& layer : crypto) {
    CryptoLayerIds ids{layer, {}};
    std::set<std::string> names;
    for (const std::string& name : crypto_instance_names(scene, loaded.info, layer)) {
      ids.instance_ids.push_back(crypto_id(name));
      names.insert(name);
    }
    std::string manifest = "{";
    for (const std::string& name : names) {
      if (manifest.size() > 1) manifest += ',';
      manifest += json_quote(name);
      manifest += ':';
      manifest += json_quote(crypto_hex(crypto_id(name)));
    }
    out.crypto_manifests.push_back(manifest + "}");
    layers.push_back(std::move(ids));
  }
  out.crypto = render_cryptomatte(scene, *accel, p.camera, p.config, integrator, layers, p.spec.crypto_depth);
  return out;
}

DeepResult render_deep_image(const LoadedScene& loaded, const Accelerator& accel, const PreparedRender& p,
                             const RenderImage& image, uint64_t max_bytes) {
  DeepConfig deep;
  deep.merge_tolerance = p.spec.deep_merge_tolerance;
  deep.max_bytes = max_bytes;
  const PathLights lights = p.path_lights();
  const IntegratorType integrator = p.integrator();
  const bool path = integrator == IntegratorType::Path;
  return render_deep(loaded.scene, accel, path ? &lights : nullptr, p.camera, p.config, integrator,
                     path ? &image.samples : nullptr, deep);
}

RenderResult render_scene(Session& session, const RenderSpec& spec, uint64_t env_budget) {
  std::lock_guard<std::mutex> lock(session.mutex);
  PrepareOptions options;
  options.scene_file = session.file;
  options.env_budget = env_budget;
  validate(spec);
  // Loads at the shutter's times match the scene only when it too was loaded at a time.
  options.identity.shutter = set_scene_motion(session.loaded, spec, session.time, session.file,
                                              session.loaded_at_time ? session.load_at : LoadAtTime{});
  // The lights move with the shutter: those of another shutter or step count are built again.
  const std::string lights_key = options.identity.shutter + " steps " + std::to_string(spec.motion_steps);
  if (session.area_lights_key == lights_key) options.area_lights = session.area_lights;
  options.time = session.loaded_at_time ? std::optional<double>(session.time) : std::nullopt;
  options.load_at = session.load_at;
  RenderResult r;
  r.prepared = prepare_render(session.loaded, spec, options);
  DefaultLightGuard guard{session.loaded, &r.prepared};
  if (r.prepared.area_lights) {
    session.area_lights = r.prepared.area_lights;
    session.area_lights_key = lights_key;
  }
  const Scene& scene = session.loaded.scene;
  // An animated scene loaded at a time keeps Embree's still placements apart, as the command does.
  const bool world_apart = session.loaded.info.animation_count != 0 && session.loaded_at_time;
  session.structure = build_structure(scene, spec, world_apart, std::move(session.structure));
  const Accelerator* accel = session.structure.accel.get();
  r.image = render_image(scene, accel, r.prepared);
  r.layers = render_layers(session.loaded, accel, r.prepared);
  overlay_wireframe(r.image, r.layers, r.prepared);
  if (r.prepared.spec.deep)
    r.deep = render_deep_image(session.loaded, *accel, r.prepared, r.image, env_budget);
  if (r.deep.over_budget)
    throw std::invalid_argument("the deep image needs more than the " + std::to_string(env_budget >> 20) +
                                " MiB memory budget (" + std::to_string(r.deep.samples_found) +
                                " deep samples found before it stopped); raise deep_merge_tolerance");
  if (r.prepared.spec.denoise) r.image.denoised = denoise_render(r.image, r.layers.data, r.prepared.config);
  return r;
}

}  // namespace penumbra
