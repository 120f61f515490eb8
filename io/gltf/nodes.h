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
  /// Per node: its world transform is animated (the node or an ancestor is the target of a
  /// translation, rotation or scale channel); empty without a time.
  std::vector<uint8_t> moving;
  /// Placements of moving nodes left out as singular, non-finite or huge (the loader counts
  /// them: such a scene is not posed at another time without loading it again).
  uint64_t moving_skipped = 0;
};

/// True if `node`'s world transform is animated (NodeTransforms::moving).
inline bool is_moving(const NodeTransforms& nodes, int node) {
  return node >= 0 && size_t(node) < nodes.moving.size() && nodes.moving[size_t(node)];
}

/// A node with a mesh, in traversal order.
struct MeshUse {
  int mesh, node;
};

/// What the scene's walk found to place besides cameras and lights, in visit order.
struct NodeUses {
  std::vector<MeshUse> meshes;  ///< nodes with a mesh
  std::vector<int> shapes;      ///< nodes with the PENUMBRA_shapes extension
  std::vector<int> cameras;     ///< the node of each camera placed (Scene::cameras order)
  std::vector<int> lights;      ///< the node of each light placed (Scene::lights order)
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

/// Marks NodeTransforms::moving from every animation's translation, rotation and scale
/// channels (whose target nodes evaluate_animations has checked) and the parent links.
void mark_moving_nodes(const GltfContext& ctx, NodeTransforms& nodes);

/// Sets the eye and frame of `cam` from its node's world transform (scale removed). Throws
/// InputError naming the node if the transform is singular.
void place_camera(const GltfContext& ctx, int node, const Transform& world, Camera& cam);

/// Sets the position and direction of `light` from its node's world transform. Throws
/// InputError naming the node if a spot or directional light's transform is singular.
void place_light(const GltfContext& ctx, int node, const Transform& world, Light& light);

/// Walks the scene depth-first from `roots` (checked: in range, parentless, listed once),
/// placing cameras and lights into ctx.out.scene; returns the nodes with meshes and with shapes.
NodeUses place_nodes(const GltfContext& ctx, NodeTransforms& nodes, const std::vector<int>& roots);

}  // namespace penumbra::gltf
