// The node hierarchy for the glTF loader: parent links checked for cycles and shared children,
// world transforms (each computed once, on first use), the scene's roots, cameras and
// KHR_lights_punctual lights placed by their nodes (glTF 2.0 spec 3.5, 3.10).
#pragma once

#include <cstdint>
#include <vector>

#include "io/gltf/animation.h"
#include "io/gltf/context.h"

namespace penumbra::gltf {

/// Parent links and the world transforms computed so far.
struct NodeTransforms {
  std::vector<int> parent;       ///< per node, -1 for a root
  std::vector<Transform> world;  ///< per node, valid where `known`
  std::vector<uint8_t> known;
  const std::vector<NodePose>* poses = nullptr;  ///< animated TRS overrides (may be empty)
};

/// A node with a mesh, in traversal order.
struct MeshUse {
  int mesh, node;
};

/// What the scene's walk found to place besides cameras and lights, in visit order.
struct NodeUses {
  std::vector<MeshUse> meshes;  ///< nodes with a mesh
  std::vector<int> shapes;      ///< nodes with the PENUMBRA_shapes extension
};

/// Checks every camera's and light's parameters. Throws InputError naming them.
void validate_cameras(const GltfContext& ctx);
void validate_lights(const GltfContext& ctx);

/// The root nodes of the scene chosen by options.scene, else the file's default, else scenes[0],
/// else every parentless node (with a warning). Sets out.info.scene_index to the scene, -1 if none.
std::vector<int> scene_roots(const GltfContext& ctx);

/// Parent links after checking child indices, single parents and acyclicity (iteratively).
NodeTransforms link_nodes(const GltfContext& ctx, const std::vector<NodePose>& poses);

/// The world transform of `node`: its parent's world x its local transform (TRS or matrix,
/// animated if posed), computed once per node. Throws InputError if it is not finite.
const Transform& world_transform(const GltfContext& ctx, NodeTransforms& nodes, int node);

/// Walks the scene depth-first from `roots` (checked: in range, parentless, listed once),
/// placing cameras and lights into ctx.out.scene; returns the nodes with meshes and with shapes.
NodeUses place_nodes(const GltfContext& ctx, NodeTransforms& nodes, const std::vector<int>& roots);

}  // namespace penumbra::gltf
