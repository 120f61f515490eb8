// `penumbra mesh`: the implicit shapes a glTF scene places (or one node's), extracted by marching
// cubes at a resolution, moved into the world with their materials, written as .gltf + .bin or
// as one .glb (see renderer/scene/shape_mesh.h).
#pragma once

#include <optional>
#include <string>

namespace penumbra::cli {

struct MeshArgs {
  std::string scene_file;
  std::string output;               ///< .glb or .gltf (with OUT.bin beside it)
  std::optional<std::string> node;  ///< a glTF node index or name (not empty); none = every implicit shape
  int resolution = 0;               ///< cells along each shape's longest axis, [1, 4096]
  int scene = -1;                   ///< glTF scene index; -1 = the file's default
  std::string max_memory;           ///< budget for the scene, grids and meshes; empty = half the RAM
  bool allow_external = false;
  bool quiet = false;
};

/// Checks the output (.glb or .gltf, not a file the run reads) and the resolution before
/// loading, resolves the node, meshes and writes atomically, and prints the output path.
/// Returns the exit code; throws UsageError or InputError for bad input (an empty or unknown
/// node, a node without an implicit shape, a resolution over the budget), std::runtime_error when a
/// write fails.
int run_mesh(const MeshArgs& args);

}  // namespace penumbra::cli
