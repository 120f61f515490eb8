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
#include "render/session.h"
#include "render/spec.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/render.h"
#include "renderer/lights/area.h"

namespace penumbra::python {

/// Half the machine's RAM (8 GiB if it cannot be read): the loader budget `penumbra` uses
/// without --max-memory.
uint64_t default_memory_budget();

/// A loaded glTF scene as a Python Scene holds it: the render session's (render/session.h).
/// Every access holds `mutex`: a render adds the default key light to scene.lights for its
/// duration, pose() moves instances, cameras and lights, and the kept structure is built and
/// replaced under it.
using SceneSession = Session;

/// load_gltf(file, options) into a new session. Throws what load_gltf throws.
std::shared_ptr<SceneSession> load_session(const std::string& file, const GltfLoadOptions& options);

/// pose_gltf_scene at `time` seconds (call with the session locked). False, with the scene
/// unchanged, when the scene was not loaded with a time and keep_animation or its animation
/// changes more than placements. Keeps the structure when only cameras and lights move,
/// moves its instances where the back end can, and drops it otherwise.
bool pose_session(SceneSession& session, double time);

/// The settings of one render: the library's spec (render/spec.h), whose fields the Python API
/// names as they are; `aovs` is passed to render_session separately.
using RenderSettings = RenderSpec;

/// AOV names a render accepts from Python: the data AOVs (aov.h) and the path tracer's layers.
const std::vector<std::string>& python_aov_names();

/// One render with everything its outputs need.
struct RenderOutput {
  std::string scene_file;
  RenderSettings settings;  ///< as requested
  RenderConfig config;      ///< as rendered (size, spp, filter and depths resolved)
  std::set<std::string> aovs;
  Camera camera;
  int camera_index = -1;              ///< into the scene's cameras; -1: framed from the bounds
  bool default_light = false;         ///< the scene had no light: the default key light lit it
  std::vector<std::string> warnings;  ///< settings the render ignored (PreparedRender::warnings)
  Film film;                          ///< premultiplied RGBA of render_window(config): the main beauty
  /// With denoise: the other beauty (the noisy one, or the denoised one when denoise_main is
  /// "noisy"); else empty.
  Film second;
  std::vector<float> halves;      ///< with "halves" or denoise: kHalfChannels per pixel
  DataAovs data;                  ///< filled when a data AOV was asked for
  std::vector<uint32_t> samples;  ///< path: samples per pixel
  std::vector<float> variance;    ///< path: variance of each pixel's mean luminance
  std::vector<float> groups;      ///< path with "light": kLightGroupChannels per pixel
  std::vector<float> vector;      ///< with "vector": kMotionVectorChannels per pixel
  std::vector<float> velocity;    ///< with "velocity": kVelocityChannels per pixel
  std::vector<float> wireframe;   ///< with the wireframe setting: its coverage per pixel
  std::vector<float> samples_f;   ///< `samples` as floats, for the EXR
  std::string id_manifest;        ///< JSON: object id -> node name, material id -> material name
  DeepImage deep;                 ///< with settings.deep: the deep image (render_deep_image)
  RenderStats stats;
};

/// Renders `session`'s scene through the render session (render_scene) with `settings` and the
/// layers `aovs` names ("all": every layer of python_aov_names() the integrator has). Throws
/// std::invalid_argument for settings outside their ranges and InputError for a bad camera or
/// environment map.
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
/// variance.X, the light groups' .RGB, vector.XYZW) and the settings as metadata. Throws as write_exr.
void write_render_exr(const RenderOutput& output, const std::filesystem::path& path,
                      const ExrWriteOptions& options);

/// The deep EXR `penumbra render --deep` writes for these settings (write_deep_exr) with the same
/// metadata as write_render_exr. Requires a render with settings.deep.
void write_render_deep_exr(const RenderOutput& output, const std::filesystem::path& path,
                           const ExrWriteOptions& options);

}  // namespace penumbra::python
