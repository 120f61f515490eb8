// The render session: the one pipeline every front end renders through (the command line,
// job files, the Python module and the benchmark). Its phases are free functions that take
// what the previous one returned:
//
//   prepare_render   spec + loaded scene  -> PreparedRender (resolved settings, RenderConfig,
//                                            camera, lights, default key light, identity)
//   build_structure  scene + spec         -> Structure (built, reused or refitted)
//   render_image     prepared + structure -> RenderImage (the beauty through one integrator
//                                            signature, with the path tracer's layers)
//   render_layers    prepared + structure -> RenderLayers (data AOVs, Cryptomatte, cost map,
//                                            from the beauty's own camera samples; motion
//                                            vectors from the pixel centres)
//
// render_scene() runs them all on a Session (a loaded scene, its lock and the structure kept
// between renders), as the Python module does. Writing files stays with the front ends.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "io/gltf/loader.h"
#include "render/motion.h"
#include "render/spec.h"
#include "renderer/film/cryptomatte.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/cost_map.h"
#include "renderer/integrators/deep_pass.h"
#include "renderer/integrators/motion_vectors.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/wireframe.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"

namespace penumbra {

/// The camera instance `spec` names: an index as the scene lists its cameras, or a camera name.
/// Throws InputError(file, `element`) listing the cameras if there is none such or the name is
/// ambiguous.
int find_camera(const Scene& scene, const std::string& spec, const std::string& file,
                const std::string& element = "camera");

/// Places the camera once the image size is known: from the scene's camera `index` (-1: none).
/// The default places the scene's camera as it is, or frames the scene's bounds.
using PlaceCamera = std::function<Camera(const Scene& scene, int index, int width, int height)>;

/// A camera placed by the front end that moves from frame to frame of its own accord (a
/// turntable): the camera PlaceCamera gives, `frames` frame intervals after the render's frame
/// (any finite value within 2^20; 0 is the render's own camera).
using TurnCamera = std::function<Camera(const Scene& scene, int index, int width, int height, double frames)>;

/// What prepare_render needs besides the spec and the scene.
struct PrepareOptions {
  std::string scene_file;  ///< names the file in InputError messages
  int camera_index = -2;   ///< -2: from spec.camera (find_camera); else the index to use (-1: none)
  PlaceCamera place;       ///< empty: the scene's camera or framing the bounds
  /// Set when `place` puts the camera where it moves from frame to frame (a turntable, whose
  /// frames show the scene at one time): its motion over the shutter blurs the render and the
  /// vector layer's neighbouring frames are this scene seen from its previous and next
  /// placements. Empty: a placed camera stays still.
  TurnCamera turn;
  uint64_t env_budget = 0;  ///< bytes an environment map may take (unless charge_budget says)
  /// Called with the resolved config before any light is loaded: charges the image's buffers to
  /// a memory budget and returns the bytes left for an environment map; may throw.
  std::function<uint64_t(const RenderConfig&)> charge_budget;
  /// The area lights (emissive triangles and shapes) from an earlier render of the same scene,
  /// reused; null: built.
  std::shared_ptr<const AreaLights> area_lights;
  SceneIdentity identity;  ///< the scene part of the identity (sha256, index, time, ...)
  /// The vector layer: the time the scene was posed at (unset: its static pose), and how to
  /// load it at another time (required when the layer is asked for at a time).
  std::optional<double> time;
  LoadAtTime load_at;
};

/// The vector layer's neighbouring frames: the scene at the render's time -/+ 1/fps, each with
/// the camera placed as the render's own (the same index or placement, at that time).
struct MotionFrames {
  LoadedScene previous, next;  ///< empty when same_scene
  Camera previous_camera, next_camera;
  bool same_scene = false;  ///< the neighbouring frames pose the scene as the render does (a turntable)
  const Scene& previous_scene(const Scene& render) const { return same_scene ? render : previous.scene; }
  const Scene& next_scene(const Scene& render) const { return same_scene ? render : next.scene; }
};

/// The image a render sees and the camera it sees it through: the first step of prepare_render.
struct RenderView {
  RenderSpec spec;  ///< resolved (resolve())
  RenderConfig config;
  Camera camera;          ///< placed (options.place, the scene's camera, or framing the bounds), pinhole
  int camera_index = -1;  ///< into the scene's cameras; -1: none
};

/// validate(spec), the camera (options.camera_index, else spec.camera through find_camera, else
/// the first), the spec resolved for its aspect hint, the RenderConfig, and the camera placed by
/// options.place (or the scene's, or framed on the bounds) and checked by validate_camera. The
/// lens (depth of field), lights and motion are prepare_render's. Throws std::invalid_argument
/// for settings and InputError for the camera, naming options.scene_file.
RenderView render_view(const Scene& scene, const RenderSpec& spec, const PrepareOptions& options);

/// A render ready to run: everything resolved, the scene's lights set up.
struct PreparedRender {
  RenderSpec spec;  ///< resolved (resolve())
  RenderConfig config;
  Camera camera;
  int camera_index = -1;                           ///< into the scene's cameras; -1: framed from the bounds
  std::shared_ptr<const Environment> environment;  ///< never null (black when unlit)
  std::shared_ptr<const AreaLights> area_lights;   ///< path tracer only, else null
  bool default_light = false;  ///< the scene had no light: prepare_render appended the default key light
  RenderSettings identity;     ///< render_identity() of this render
  std::vector<std::string> warnings;  ///< settings the render ignores, for the front end to show
  /// The vector layer's neighbouring frames; null without the layer or for a static render
  /// (whose vectors are all 0).
  std::shared_ptr<const MotionFrames> motion;

  IntegratorType integrator() const;
  PathLights path_lights() const { return {area_lights.get(), environment.get()}; }
};

/// Resolves `spec` (validate() first) for the scene, places the camera (validate_camera) and
/// its thin lens (the f-number or radius, the focus distance or the depth autofocus finds
/// through focus_at's pixel or the centre's, else the bounds' centre; the raster preview keeps
/// a pinhole and says so in `warnings`), loads
/// the environment (spec.env_color, spec.env_map, else the file's image-based light), builds the
/// emissive triangles and shapes for the path tracer, appends the default key light to scene.lights when
/// nothing lights the scene, loads the vector layer's neighbouring frames (load_motion_frames;
/// with options.turn: the scene as it is, seen from the camera's previous and next placements),
/// keys a turning camera (options.turn) over the shutter with motion blur, and derives the
/// identity. Throws std::invalid_argument for settings, InputError for the
/// camera, the environment map or the neighbouring frames.
PreparedRender prepare_render(LoadedScene& loaded, const RenderSpec& spec, const PrepareOptions& options);

/// The scene at `time` -/+ 1/spec.fps through options.load_at, each checked against `scene`
/// (check_motion_frame), with its camera: the file's camera the render uses, as posed at that
/// time (placed by options.place with the same index when given, at the render's size); a
/// camera placed from the command line or framed from the bounds stays prepared.camera. Throws InputError
/// naming the time when a frame does not match the scene, std::invalid_argument when options.load_at is
/// empty.
MotionFrames load_motion_frames(const Scene& scene, const PreparedRender& prepared, double time,
                                const PrepareOptions& options);

/// Removes the default key light prepare_render appended, if it did.
void finish_render(LoadedScene& loaded, const PreparedRender& prepared);

/// Whether the render queries an acceleration structure: every integrator does but the raster
/// one without shadow rays, Cryptomatte, the cost or vector layer or a pixel probe.
bool needs_structure(const RenderSpec& spec, bool probe = false);

/// An acceleration structure with what its reuse policy needs.
struct Structure {
  std::unique_ptr<Accelerator> accel;
  std::string key;       ///< the name and parameters it was built with
  double built_sah = 0;  ///< its SAH cost when last built (the refit policy's base)
  /// How it came to be: "built", "reused", "instances moved", "refitted" or "rebuilt".
  std::string update = "built";
  std::string reason;  ///< refit_or_rebuild's reason or cost growth, for "refitted"/"rebuilt"
};

/// The structure `spec.accel` names over the scene: `previous` as it is when it was built with
/// the same name and parameters and the scene's geometry has not moved (`moved_vertices` false);
/// refitted or rebuilt to moved vertices by refit_or_rebuild_scene's policy; else built anew.
/// `world_apart`: an animated scene at a time (EmbreeConfig::world_apart). Throws
/// std::invalid_argument for bad parameters.
Structure build_structure(const Scene& scene, const RenderSpec& spec, bool world_apart,
                          Structure previous = {}, bool moved_vertices = false);

/// What the integrators report while they run, and how a path render resumes and stops.
struct RenderHooks {
  ProgressFn progress;                      ///< tiles or passes done of total; may be empty
  PathAccumulators* resume = nullptr;       ///< path: state to continue from and update
  PassFn after_pass;                        ///< path: after each pass (checkpoints)
  const std::atomic<bool>* stop = nullptr;  ///< path: ends the render after the current pass
};

/// The beauty and the path tracer's own layers.
struct RenderImage {
  Film film;                      ///< premultiplied RGBA of render_window(config)
  std::vector<uint32_t> samples;  ///< path: samples per pixel
  std::vector<float> variance;    ///< path: variance of each pixel's mean luminance
  std::vector<float> groups;      ///< path with light groups: kLightGroupChannels per pixel
  std::vector<float> halves;      ///< path with "halves": kHalfChannels per pixel (even, odd RGB)
  /// With spec.denoise, after render_scene: the denoised beauty (film stays the noisy one).
  Film denoised;
  RenderStats stats;
  bool complete = true;  ///< every requested sample taken (a path render may stop early)
};

/// Renders the beauty with the prepared render's integrator: one signature for the three.
/// `accel` may be null only when needs_structure() is false.
RenderImage render_image(const Scene& scene, const Accelerator* accel, const PreparedRender& prepared,
                         const RenderHooks& hooks = {});

/// One pixel exactly as render_image computes it: RGBA and the rays it traced.
void render_pixel(const Scene& scene, const Accelerator* accel, const PreparedRender& prepared, int x, int y,
                  float rgba[4], RayCounts& counts);

/// The layers besides the beauty, from the beauty's own camera samples.
struct RenderLayers {
  DataAovs data;                              ///< albedo, N, P, Z, UV, ids (when one of them is asked for)
  CostImage cost;                             ///< traversal cost of the camera rays ("cost")
  CryptoImage crypto;                         ///< ranked ids, one layer per crypto_layers() entry
  std::vector<std::string> crypto_manifests;  ///< each Cryptomatte layer's {"name": "hex"} JSON
  std::string id_manifest;                    ///< JSON names of the id layer's ids ("id")
  std::vector<float> vector;                  ///< kMotionVectorChannels per pixel of the window ("vector")
  std::vector<float> velocity;                ///< kVelocityChannels per pixel of the window ("velocity")
  std::vector<float> wireframe;               ///< spec.wireframe: coverage per pixel of the window
};

/// The wireframe overlay's settings from a resolved spec: width, hidden edges, and the nodes
/// spec.wireframe_nodes names (indices or names as `info` lists them). Throws
/// std::invalid_argument naming wireframe_nodes for a node the file does not have.
WireframeConfig wireframe_config(const RenderSpec& spec, const GltfInfo& info);

/// Composites the wireframe layer (layers.wireframe) in spec.wireframe_color over the beauty;
/// nothing without it.
void overlay_wireframe(RenderImage& image, const RenderLayers& layers, const PreparedRender& prepared);

/// The Cryptomatte layers `aovs` asks for: CryptoObject, CryptoMaterial, CryptoAsset.
std::vector<std::string> crypto_layers(const std::set<std::string>& aovs);

/// Whether `aovs` asks for a data AOV (albedo, N, P, Z, UV or id) or the halves (whose features
/// the data AOVs' pass computes).
bool wants_data_aovs(const std::set<std::string>& aovs);

/// Whether `aovs` asks for a layer traced against the neighbouring frames (vector, velocity).
bool wants_motion_layers(const std::set<std::string>& aovs);

/// The name each scene instance has in Cryptomatte layer `layer` (CryptoObject: its glTF node's
/// name; CryptoMaterial: its material's name, "default" for none; CryptoAsset: its root node's
/// name), one per scene.instances entry, then one per scene.splat_instances entry (named by
/// their nodes likewise; "splats" in CryptoMaterial).
std::vector<std::string> crypto_instance_names(const Scene& scene, const GltfInfo& info,
                                               const std::string& layer);

/// Traces what the requested data, Cryptomatte, cost and vector layers need (the vector layer
/// from prepared.motion; all 0 without it), and the wireframe's coverage with spec.wireframe.
RenderLayers render_layers(const LoadedScene& loaded, const Accelerator* accel,
                           const PreparedRender& prepared);

/// The deep image of a render with spec.deep (Whitted or path): the beauty's own camera samples
/// traced again with their layers recorded (render_deep), each pixel taking the samples `image`
/// took (the path tracer's adaptive counts), merged with spec.deep_merge_tolerance. The deep
/// samples may take `max_bytes` in memory (DeepConfig::max_bytes); the result says when they would
/// not fit.
DeepResult render_deep_image(const LoadedScene& loaded, const Accelerator& accel,
                             const PreparedRender& prepared, const RenderImage& image,
                             uint64_t max_bytes = UINT64_MAX);

/// A loaded scene as a front end keeps it between renders. Every access holds `mutex`.
struct Session {
  std::string file;  ///< as given to load (the name InputError messages carry)
  LoadedScene loaded;
  bool loaded_at_time = false;  ///< loaded with GltfLoadOptions::time
  double time = 0;              ///< the time the scene is posed at (loaded or posed since); 0 for a still
  LoadAtTime load_at;           ///< loads the file at another time (the vector layer); may be empty
  std::mutex mutex;
  Structure structure;                            ///< the last render's, or empty
  std::shared_ptr<const AreaLights> area_lights;  ///< the emissive triangles and shapes, once needed
  std::string area_lights_key;                    ///< the shutter and motion steps area_lights were built for
};

/// Everything one render produced.
struct RenderResult {
  PreparedRender prepared;
  RenderImage image;
  RenderLayers layers;
  DeepResult deep;  ///< with spec.deep: the deep image
};

/// One render of the session's scene (locking it): the scene's motion over the shutter around
/// session.time (set_scene_motion through session.load_at, cleared without motion blur), prepare_render,
/// build_structure (kept for the next render with the same name and parameters), render_image,
/// render_layers, with spec.deep the deep image (render_deep_image within `env_budget`; throws
/// std::invalid_argument when it does not fit), with spec.denoise the denoised beauty
/// (denoise_render), and the default key light removed again however it ends. `env_budget` as in
/// PrepareOptions.
RenderResult render_scene(Session& session, const RenderSpec& spec, uint64_t env_budget);

}  // namespace penumbra
