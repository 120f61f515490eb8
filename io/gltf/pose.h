// Posing a loaded glTF scene at another time (pose_gltf_scene, loader.h): the GltfAnimation the
// loader keeps beside a scene loaded at a time, and how the loader makes it. Internal to
// io/gltf/.
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/gltf/context.h"
#include "io/gltf/nodes.h"

namespace penumbra {

struct GltfAnimation {
  tinygltf::Model model;  ///< the parsed file: channels, samplers, node TRS, instancing attributes
  std::string file;       ///< as named in every InputError
  GltfLoadOptions options;
  std::vector<int> parent;      ///< NodeTransforms::parent
  std::vector<uint8_t> moving;  ///< NodeTransforms::moving
  std::vector<int> cameras;     ///< NodeUses::cameras: the node of each Scene::cameras entry
  std::vector<int> lights;      ///< NodeUses::lights: the node of each Scene::lights entry
  /// Only placements move: no morph-weight channel, no skinned mesh, no flattened mesh on a
  /// moving node and no moving placement left out at the load.
  bool rigid = false;
};

}  // namespace penumbra

namespace penumbra::gltf {

/// The GltfAnimation of the conversion `ctx` (at ctx.options.time, after every node was
/// placed), without the model, which the caller moves in once the conversion is done.
std::shared_ptr<GltfAnimation> describe_animation(const GltfContext& ctx, const NodeTransforms& nodes,
                                                  const NodeUses& uses);

}  // namespace penumbra::gltf
