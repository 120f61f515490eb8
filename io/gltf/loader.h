// glTF 2.0 loading (.gltf with external or data-URI buffers, .glb) into a renderer Scene.
// tinygltf parses; this module validates everything tinygltf does not (indices, accessor
// ranges with overflow-safe arithmetic, node cycles, NaN data, URI escapes, JSON depth,
// camera and light parameters) and flattens the node hierarchy into world-space meshes and
// instances; the PENUMBRA_shapes node extension adds analytic and implicit shapes. Images
// (PNG, JPEG from files, data URIs or bufferViews) are decoded through OpenImageIO into
// MIP-mapped textures. A scene loaded at an animation time can be posed at another time without
// loading it again (pose_gltf_scene) when its animations move only nodes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "renderer/lights/environment.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// Loader limits and choices, with their defaults.
struct GltfLoadOptions {
  int scene = -1;                          ///< glTF scene index; -1 = the file's default (or 0)
  bool allow_external_uris = false;        ///< allow URIs that resolve outside the file's folder
  uint64_t max_file_bytes = 2ull << 30;    ///< per file read (glTF, GLB, .bin)
  uint64_t max_memory_bytes = 8ull << 30;  ///< budget for decoded geometry
  int max_json_depth = 64;                 ///< deeper JSON nesting is rejected before parsing
  /// Animation time in seconds: every animation's channels (node TRS, morph weights; skins
  /// follow their joints) are evaluated at this time before the scene is built. Unset: the
  /// file's static pose (no channel applied).
  std::optional<double> time;
  /// true: every placement of a mesh gets its own world-space copy (no instancing). false: a
  /// mesh placed more than once (by several nodes or EXT_mesh_gpu_instancing) is stored once
  /// and instanced; a mesh placed once is put in world space, unless a time is asked for and
  /// its node's world transform is animated (see pose_gltf_scene).
  bool flatten = false;
  /// With a time and a file with animations: keep what pose_gltf_scene needs, the parsed file
  /// with its buffers included, in LoadedScene::animation (memory held as long as the scene).
  bool keep_animation = false;
  /// KHR_materials_variants: the variant whose materials the primitives use (empty: each
  /// primitive's own material). A name the file does not define is an error listing its variants.
  std::string variant;
};

/// One glTF mesh as `penumbra info` lists it.
struct GltfMeshInfo {
  std::string name;        ///< its name, or "meshes[i]" if unnamed
  int primitives = 0;      ///< primitives in the file, usable or not
  uint64_t triangles = 0;  ///< triangles of its usable primitives, once (not per placement)
};

/// Descriptive facts about the file, for `penumbra info`.
struct GltfInfo {
  std::string generator, version;
  int scene_count = 0, scene_index = -1;
  std::vector<std::string> scene_names;
  int node_count = 0, mesh_count = 0, primitive_count = 0;
  std::vector<GltfMeshInfo> meshes;  ///< every glTF mesh, in file order
  int gltf_camera_count = 0, gltf_light_count = 0, image_count = 0, animation_count = 0;
  std::vector<std::string> extensions_used, extensions_required;
  std::vector<std::string> variants;                ///< KHR_materials_variants names, in file order
  int variant = -1;                                 ///< the variant used (index into variants), -1: none
  std::string image_light;                          ///< the EXT_lights_image_based light used, empty: none
  std::vector<std::string> camera_instances;        ///< "name (perspective, node 3)" in scene order
  std::vector<std::string> node_names;              ///< each node's name, or "nodes[i]" if unnamed
  std::vector<int> node_parents;                    ///< each node's parent node, -1 for a root
  std::vector<std::vector<int>> node_skin_joints;   ///< per node, the joints of its skin (empty: none)
  std::vector<std::filesystem::path> source_files;  ///< every file read: the glTF/GLB first, then each
                                                    ///< external buffer and image file, in load order
  /// The SHA-256 of each source_files entry's bytes as the loader read them (same order).
  std::vector<std::string> source_sha256;
};

/// What pose_gltf_scene needs to pose a loaded scene at another time: the parsed file (its
/// buffers included), the node links, which nodes move, and the node of each camera and light.
/// Opaque outside io/gltf/.
struct GltfAnimation;

struct LoadedScene {
  Scene scene;
  GltfInfo info;
  /// The scene's EXT_lights_image_based light as the path tracer's environment; null if none.
  std::shared_ptr<const Environment> environment;
  std::vector<std::string> warnings;  ///< each names the element it concerns
  /// Set when a time and keep_animation were asked for and the file has animations that only
  /// move placements (see pose_gltf_scene):
  /// pose_gltf_scene() moves this scene's instances, cameras and lights to another time. Null
  /// otherwise.
  std::shared_ptr<const GltfAnimation> animation;
  uint64_t animation_bytes = 0;  ///< what `animation` holds of the file (buffers, images), for budgets
};

/// Loads `file`. A file in another 3D format (OBJ, FBX, USD, PLY, ...: check_gltf_file_format)
/// is refused naming the format before it is parsed. Throws InputError (file + JSON path +
/// reason) for anything malformed or hostile; degenerate but harmless content (lines primitives, NaN
/// vertices, missing images) produces a warning instead and is skipped.
LoadedScene load_gltf(const std::filesystem::path& file, const GltfLoadOptions& options = {});

/// Poses `scene`, loaded by load_gltf with a time and `animation` (LoadedScene::animation, the
/// scene as loaded: no instance, camera or light added or removed), at `time` seconds: the
/// instances of moving nodes (to_world, to_object, mirrored; never marked the identity), every
/// camera's eye and frame and every punctual light's position and direction become those a
/// fresh load_gltf at `time` gives; meshes, shapes and materials are untouched. Returns false,
/// with the scene unchanged, when the animation changes more than placements: morph-weight
/// channels, skinned meshes, a flattened moving mesh, Gaussian splats placed by a moving node, a
/// placement left out as singular or huge (at the load or at `time`), another count of cameras
/// or lights; the caller then loads the
/// file again. Throws InputError naming the node or the animation element as load_gltf does
/// (non-finite or singular transforms, malformed channels), leaving the scene unchanged. When
/// posed, `*moved_instances` (if given) is set to the number of instances of moving nodes, whose
/// maps were set again (0: only cameras and lights move, the instances are as they were).
bool pose_gltf_scene(const GltfAnimation& animation, double time, Scene& scene,
                     uint64_t* moved_instances = nullptr);

/// Maximum nesting depth of arrays/objects in a JSON text (strings are skipped correctly).
/// Stops counting once `limit` is exceeded and returns limit + 1.
int json_nesting_depth(std::string_view json, int limit);

/// The extensions this loader implements (an extensionsRequired entry outside it is an error).
std::vector<std::string> supported_gltf_extensions();
/// The subset of supported_gltf_extensions() implemented in part, each with what is missing
/// (e.g. KHR_texture_basisu: fallback images only).
std::vector<std::pair<std::string, std::string>> partial_gltf_extensions();

}  // namespace penumbra
