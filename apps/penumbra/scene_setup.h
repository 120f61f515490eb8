// Loading a scene for a subcommand and choosing what renders it: the glTF file with its warnings
// printed, the camera named on the command line, and the acceleration structure's name and
// build parameters, each checked with the valid choices listed.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "io/gltf/loader.h"
#include "render/accel_params.h"
#include "renderer/accel/factory.h"

namespace penumbra::cli {

/// Loads `file` with the loader's options (`keep_animation`: GltfLoadOptions::keep_animation,
/// `variant`: GltfLoadOptions::variant);
/// unless `quiet`, prints up to 20 warnings on stderr (and how many more there were). Throws
/// what load_gltf throws.
LoadedScene load_scene(const std::string& file, int scene, bool allow_external, bool flatten,
                       uint64_t max_memory, bool quiet, std::optional<double> time = {},
                       bool keep_animation = false, const std::string& variant = {});

/// What an acceleration structure is built over, in a few words: "4.65k triangles", "1.20M
/// triangles, 3 shapes".
std::string describe_scene_size(const Scene& scene);

/// The glTF node `spec` (not empty) names: an index below the node count, or a unique node
/// name. Throws UsageError (as an option `--node` error) for an unknown or ambiguous node.
int find_gltf_node(const GltfInfo& info, const std::string& spec, const std::string& file);

/// The camera instance `spec` names: an index as `penumbra info` lists them, or a camera name.
/// Throws InputError listing the cameras if there is no such camera or the name is ambiguous.
int find_camera(const Scene& scene, const std::string& spec, const std::string& file);

/// The accelerator name and "key=value" parameters, checked before any loading: UsageError (or
/// std::invalid_argument from the parameter parser) with the list of valid names or keys; a
/// parameter of another structure than `name` is refused, as it would be silently unused.
AccelConfig parse_accel(const std::string& name, const std::vector<std::string>& params);

/// The help text of --accel-param: every key with its default and meaning.
std::string accel_param_help();

/// Every structure --accel accepts (render/accel_params.h).
using penumbra::accelerator_list;

}  // namespace penumbra::cli
