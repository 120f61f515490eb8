// The PENUMBRA_shapes node extension for the glTF loader: analytic primitives (sphere, plane,
// disk, box, capsule) and implicit CSG shapes, read from the raw JSON and checked against the
// extension's schema (README, "The PENUMBRA_shapes extension"), then placed as the node's mesh
// would be: by its world transform or by each EXT_mesh_gpu_instancing copy. Internal to io/gltf/.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "io/gltf/context.h"
#include "io/gltf/nodes.h"

namespace penumbra::gltf {

/// The extension's name on nodes and in extensionsUsed / extensionsRequired.
inline constexpr const char* kShapesExtension = "PENUMBRA_shapes";

/// Most SdfNodes one implicit shape may hold, the binary nodes operators fold into included.
inline constexpr int kMaxCsgNodes = 4096;

/// One node's shape as its extension describes it, in the node's local frame.
struct NodeShape {
  int node = -1;  ///< index into nodes
  Shape shape;
  int material = -1;  ///< index into materials; -1 = the default material
};

/// Reads nodes[i].extensions.PENUMBRA_shapes of every node of the raw JSON `doc` (whose nodes
/// check_gltf_json has checked to be objects), in node order. Every CSG node and plane is
/// charged to `budget` before it is stored. Throws InputError(file, JSON path of the offending
/// member, reason) for anything outside the schema: unknown keys, keys of another type, wrong
/// JSON types, values out of range, missing or misplaced children, CSG trees deeper than
/// kMaxSdfDepth or larger than kMaxCsgNodes, degenerate transforms, unbounded implicit shapes.
std::vector<NodeShape> read_node_shapes(const nlohmann::json& doc, const std::string& file,
                                        MemoryBudget& budget);

/// Places the shape of every node in `shape_nodes` (the scene's nodes that carry the extension,
/// in visit order) into ctx.out.scene: one SceneShape per node, moved out of `shapes`, and one
/// Instance per placement (the node's world transform, or each EXT_mesh_gpu_instancing copy),
/// charged to the budget first. Singular, non-finite or huge placements are skipped with a
/// warning naming the node (and counted in nodes.moving_skipped for a moving node); a moving
/// node's instances are never marked the identity.
void place_shapes(const GltfContext& ctx, std::vector<NodeShape>& shapes, NodeTransforms& nodes,
                  const std::vector<int>& shape_nodes);

}  // namespace penumbra::gltf
