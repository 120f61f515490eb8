// The canonical settings of a render.
#include "apps/penumbra/render_identity.h"

#include <map>

#include "apps/penumbra/cli_support.h"

namespace penumbra::cli {

RenderSettings pixel_settings(const RenderArgs& a, const RenderConfig& cfg, const Camera& camera,
                              const std::string& scene_sha256, const std::string& env_sha256) {
  std::map<std::string, std::string> e;
  e["version"] = PENUMBRA_VERSION;  // another renderer version may sample differently
  e["scene.sha256"] = scene_sha256;
  e["scene.index"] = std::to_string(a.scene);
  e["scene.flatten"] = a.flatten ? "1" : "0";
  e["scene.variant"] = a.variant.empty() ? "none" : a.variant;
  const bool frame_is_time = a.frame && a.cam.turntable.empty();  // a turntable's frame turns the camera
  e["scene.time"] = a.time
                        ? exact(*a.time)
                        : (frame_is_time ? "frame " + *a.frame + " at " + exact(a.fps) + " fps" : "static");
  e["camera"] = a.camera.empty() ? "default '" + camera.name + "'" : a.camera;
  // The camera as rendered, whichever flags or file placed it.
  const auto vec = [](Vec3f v) { return exact(v.x) + "," + exact(v.y) + "," + exact(v.z); };
  e["camera.frame"] = vec(camera.eye) + " u " + vec(camera.u) + " v " + vec(camera.v) + " w " + vec(camera.w);
  e["camera.lens"] =
      (camera.projection == Projection::Orthographic ? "orthographic ymag " + exact(camera.ymag)
                                                     : "perspective yfov " + exact(camera.yfov)) +
      " near " + exact(camera.znear) + " far " + exact(camera.zfar);
  e["image"] = std::to_string(cfg.width) + "x" + std::to_string(cfg.height);
  e["integrator"] = a.integrator;
  e["seed"] = std::to_string(cfg.seed);
  e["filter"] = std::string(filter_name(cfg.filter.type)) + " " + exact(cfg.filter.width);
  e["accel"] = a.accel;
  for (const auto& p : a.accel_params) e["accel." + p.substr(0, p.find('='))] = p.substr(p.find('=') + 1);
  if (a.integrator == "path") {
    const auto& p = cfg.path;
    e["path.sampler"] = a.sampler;
    e["path.max_depth"] = std::to_string(p.max_depth);
    e["path.rr_depth"] = std::to_string(p.rr_depth);
    e["path.clamp_indirect"] = exact(p.clamp_indirect);
    e["path.light_sampling"] = a.light_sampling;
    e["path.adaptive"] = exact(cfg.adaptive_threshold) + " min " + std::to_string(cfg.adaptive_min_spp);
    e["path.light_groups"] = cfg.light_groups ? "1" : "0";
    e["env"] = a.env.empty() ? "none" : a.env;
    if (!env_sha256.empty()) e["env.sha256"] = env_sha256;
    e["env.intensity"] = exact(a.env_intensity);
    e["env.rotation"] = exact(a.env_rotation);
  } else {
    const auto& w = cfg.whitted;
    if (a.integrator == "raster") {
      e["raster.shadows"] = a.raster_shadows;
      if (a.raster_shadows == "map") e["raster.shadow_map_size"] = std::to_string(cfg.raster.shadow_map_size);
    } else {
      e["whitted.max_depth"] = std::to_string(w.max_depth);
    }
    e["whitted.background"] =
        exact(w.background.x) + "," + exact(w.background.y) + "," + exact(w.background.z);
    e["whitted.ambient"] = exact(w.ambient.x) + "," + exact(w.ambient.y) + "," + exact(w.ambient.z);
  }
  return {e};
}

}  // namespace penumbra::cli
