// The PENUMBRA_shapes node extension for the glTF loader: analytic primitives (sphere, plane,
// disk, box, capsule) and implicit CSG shapes, read from the raw JSON and checked against the
// extension's schema (README, "The PENUMBRA_shapes extension"); the solids of their polyhedron
// nodes built from glTF meshes once the buffers are read; then placed as the node's mesh would
// be: by its world transform or by each EXT_mesh_gpu_instancing copy. Internal to io/gltf/.
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

/// Most triangles the mesh of one "polyhedron" CSG node may have.
inline constexpr uint64_t kMaxPolyhedronTriangles = 65536;

/// Most polygon-plane tests building one polyhedron's solid BSP may take
/// (SolidBspConfig::max_classifications): a few seconds; a convex part of n triangles needs about
/// n^2 / 2, so convex meshes of more than about 30000 triangles are refused.
inline constexpr uint64_t kMaxPolyhedronClassifications = uint64_t(1) << 29;

/// A "polyhedron" CSG node read from the JSON whose solid is built once the buffers are read:
/// its index in the tree's polyhedra, the glTF mesh, and the JSON path of its "mesh" member.
struct PendingPolyhedron {
  int index = -1;
  int mesh = -1;
  std::string where;
};

/// One node's shape as its extension describes it, in the node's local frame.
struct NodeShape {
  int node = -1;  ///< index into nodes
  Shape shape;
  int material = -1;  ///< index into materials; -1 = the default material
  /// The polyhedron nodes of an implicit shape, not built yet (their SdfTree::polyhedra entries
  /// are empty, and the shape's Lipschitz bound and bounds not computed): place_shapes builds them.
  std::vector<PendingPolyhedron> polyhedra;
  std::string csg;  ///< JSON path of the implicit shape's csg member when polyhedra is not empty
};

/// Reads nodes[i].extensions.PENUMBRA_shapes of every node of the raw JSON `doc` (whose nodes
/// check_gltf_json has checked to be objects), in node order. Every CSG node and plane is
/// charged to `budget` before it is stored. Throws InputError(file, JSON path of the offending
/// member, reason) for anything outside the schema: unknown keys, keys of another type, wrong
/// JSON types, values out of range, missing or misplaced children, CSG trees deeper than
/// kMaxSdfDepth or larger than kMaxCsgNodes, degenerate transforms, unbounded implicit shapes,
/// polyhedron nodes without a mesh index or with one out of range. Shapes with polyhedron nodes
/// are checked for bounds when place_shapes builds their solids.
std::vector<NodeShape> read_node_shapes(const nlohmann::json& doc, const std::string& file,
                                        MemoryBudget& budget);

/// First builds the solid of every polyhedron CSG node of every shape in `shapes` (the union of
/// its glTF mesh's TRIANGLES primitives, their POSITION and indices, vertices numbered across the
/// primitives in order; morph targets and skins are ignored) with build_solid_mesh: a mesh used
/// by several nodes is built once and copied; each solid is charged to the budget; a mesh wound
/// inwards is reversed with a warning. Throws InputError naming the node's "mesh" member for a
/// primitive of another mode or without POSITION, more than kMaxPolyhedronTriangles triangles, a
/// mesh build_solid_mesh refuses ("mesh 3 is not closed: edge (12, 40) is used by 1 triangle"),
/// or a build beyond the budget or kMaxPolyhedronClassifications; then the unbounded and empty
/// checks of read_node_shapes.
///
/// Then places the shape of every node in `shape_nodes` (the scene's nodes that carry the
/// extension, in visit order) into ctx.out.scene: one SceneShape per node, moved out of `shapes`,
/// and one Instance per placement (the node's world transform, or each EXT_mesh_gpu_instancing
/// copy), charged to the budget first. Singular, non-finite or huge placements are skipped with a
/// warning naming the node (and counted in nodes.moving_skipped for a moving node); a moving
/// node's instances are never marked the identity.
void place_shapes(const GltfContext& ctx, std::vector<NodeShape>& shapes, NodeTransforms& nodes,
                  const std::vector<int>& shape_nodes);

}  // namespace penumbra::gltf
