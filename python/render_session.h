// The C++ side of the Python module, with no Python in it: a loaded scene with the lock its
// readers and renders share and the acceleration structure kept between renders, the render
// settings as the Python API names them (the CLI's defaults), one render (beauty, data AOVs,
// the path tracer's layers) and the EXR and display image of a render.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf/loader.h"
#include "io/image/image_output.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/render.h"
#include "renderer/lights/area.h"

namespace penumbra::python {

/// Half the machine's RAM (8 GiB if it cannot be read): the loader budget `penumbra` uses
/// without --max-memory.
uint64_t default_memory_budget();

/// A loaded glTF scene as a Python Scene holds it. Every access holds `mutex`: a render adds the
/// default key light to scene.lights for its duration, pose() moves instances, cameras and
/// lights, and the kept accelerator is built and replaced under it.
struct SceneSession {
  std::string file;  ///< as given to load (the name InputError messages carry)
  LoadedScene loaded;
  bool loaded_at_time = false;  ///< GltfLoadOptions::time was set
  std::mutex mutex;
  std::unique_ptr<Accelerator> accel;     ///< the last render's structure, or null
  std::string accel_key;                  ///< the name and parameters `accel` was built with
  std::optional<AreaLights> area_lights;  ///< the emissive triangles, once a path render needed them
};

/// load_gltf(file, options) into a new session. Throws what load_gltf throws.
std::shared_ptr<SceneSession> load_session(const std::string& file, const GltfLoadOptions& options);

/// pose_gltf_scene at `time` seconds (call with the session locked). False, with the scene
/// unchanged, when the scene was not loaded with a time and keep_animation or its animation
/// changes more than placements. Keeps the accelerator when only cameras and lights move,
/// moves its instances where the back end can, and drops it otherwise.
bool pose_session(SceneSession& session, double time);

/// The settings of one render, named as the Python API names them, with `penumbra render`'s
/// defaults. Checked by check_settings.
struct RenderSettings {
  int width = 0,
      height = 0;  ///< 0 and 0: 960 wide; one 0: follows the camera's aspect hint (16:9 without one)
  int spp = 0;     ///< 0: 4 (whitted), 64 (path)
  std::string integrator = "whitted";     ///< "whitted", "path" or "raster"
  std::string raster_shadows = "ray";     ///< raster only: "ray", "map" or "none"
  std::string accel = "embree";           ///< an accelerator_names() entry
  std::vector<std::string> accel_params;  ///< "bvh.max_leaf_size=4", ... of `accel` only
  uint64_t seed = 0;
  int threads = 0;  ///< 0: every hardware thread
  int tile_size = 32;
  std::string camera;  ///< index (digits only) or name; empty: the first camera, else framing the bounds
  std::string filter;  ///< box, tent, gaussian, blackman-harris; empty: box (whitted), blackman-harris (path)
  float filter_width = 0;  ///< pixels; 0: the filter's default width
  int max_depth = -1;      ///< -1: 5 mirror bounces (whitted), 12 bounces (path)
  PixelWindow window;      ///< (x0, y0, x1, y1) of the frame; all zero: the whole frame
  // Whitted only (unset: the CLI's defaults, black background and 0.05 ambient).
  std::optional<Vec3f> background, ambient;
  // Path tracer only.
  int rr_depth = 3;
  float clamp_indirect = 0;
  std::string light_sampling = "mis";         ///< mis, bsdf, light
  std::string sampler = "sobol";              ///< sobol, independent
  std::optional<Vec3f> env_color;             ///< constant environment radiance
  std::string env_map;                        ///< equirectangular map file (.exr, .hdr)
  float env_intensity = 1, env_rotation = 0;  ///< the map's multiplier and turn about +Y (degrees)
  double time_limit = 0;                      ///< seconds; 0: none
  float adaptive = 0;                         ///< adaptive sampling threshold; 0: off
  int adaptive_min_spp = 16;
};

/// AOV names a render accepts: the data AOVs (aov.h) and the path tracer's layers.
inline constexpr const char* kDataAovNames[] = {"albedo", "N", "P", "Z", "UV", "id"};
inline constexpr const char* kPathAovNames[] = {"samples", "variance", "light"};

/// Checks the settings and the AOV names ("all": every AOV of the integrator) as `penumbra
/// render` checks its flags, before any work; returns the AOV set. Throws std::invalid_argument
/// naming the setting and, for a name outside a list, the valid names.
std::set<std::string> check_settings(const RenderSettings& settings, const std::vector<std::string>& aovs);

/// One render with everything its outputs need.
struct RenderOutput {
  std::string scene_file;
  RenderSettings settings;  ///< as requested
  RenderConfig config;      ///< as rendered (size, spp, filter and depths resolved)
  std::set<std::string> aovs;
  Camera camera;
  int camera_index = -1;          ///< into the scene's cameras; -1: framed from the bounds
  bool default_light = false;     ///< the scene had no light: the default key light lit it
  Film film;                      ///< premultiplied RGBA of render_window(config)
  DataAovs data;                  ///< filled when a data AOV was asked for
  std::vector<uint32_t> samples;  ///< path: samples per pixel
  std::vector<float> variance;    ///< path: variance of each pixel's mean luminance
  std::vector<float> groups;      ///< path with "light": kLightGroupChannels per pixel
  std::vector<float> samples_f;   ///< `samples` as floats, for the EXR
  std::string id_manifest;        ///< JSON: object id -> node name, material id -> material name
  RenderStats stats;
};

/// Renders `session`'s scene (locking it) as `penumbra render` does: camera by index or
/// name (InputError listing the cameras otherwise), size from the camera's aspect hint, the
/// environment (env_color, env_map, else the file's image-based light), the emissive
/// triangles, the default key light for an unlit scene, the accelerator (kept for the next
/// render with the same name and parameters), then the beauty and the requested AOVs from the
/// same camera samples. Throws std::invalid_argument for settings outside their ranges and
/// InputError for a bad camera or environment map.
RenderOutput render_session(SceneSession& session, const RenderSettings& settings,
                            const std::vector<std::string>& aovs);

/// How write_render_exr stores a render.
struct ExrWriteOptions {
  bool half = true;                                           ///< half RGBA and colour layers; false: float
  std::string compression = "zip";                            ///< any OpenEXR compression OIIO accepts
  bool multipart = false;                                     ///< one part per layer
  std::vector<std::pair<std::string, std::string>> metadata;  ///< extra string attributes
};

/// The EXR `penumbra render` writes for these settings: R, G, B, A, then every AOV the render
/// holds with the command's channel names and types (albedo.RGB, N.XYZ, P.XYZ, Z, UV.UV,
/// object_id.X / material_id.X as whole-number floats with the name manifest, samples.X,
/// variance.X, the light groups' .RGB) and the settings as metadata. Throws as write_exr.
void write_render_exr(const RenderOutput& output, const std::filesystem::path& path,
                      const ExrWriteOptions& options);

}  // namespace penumbra::python
