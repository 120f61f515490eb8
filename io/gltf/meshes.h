// Meshes for the glTF loader: primitives decoded and validated once in their mesh's local space
// (attributes, indices, topology, morph targets, skinning attributes; glTF 2.0 spec 3.7), then
// placed: morphed, skinned or transformed into world-space copies, or stored once and instanced
// when a mesh is placed more than once (several nodes or EXT_mesh_gpu_instancing).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/gltf/animation.h"
#include "io/gltf/context.h"
#include "io/gltf/nodes.h"

namespace penumbra::gltf {

/// Bytes an accelerator allocates per non-identity instance, measured with the peak RSS of
/// `penumbra info` on 10^5 and 10^6 EXT_mesh_gpu_instancing instances of one triangle: Embree
/// (an instance geometry per placement and the top-level BVH) about 450 bytes, the two-level BVH
/// about 400, beyond the scene's Instance.
constexpr uint64_t kAccelBytesPerInstance = 460;

/// One glTF primitive decoded and validated in its mesh's local space.
struct LocalPrimitive {
  std::vector<Vec3f> positions, normals;  ///< normals empty if absent or unusable
  std::vector<Vec4f> tangents, colors;    ///< empty if absent
  std::vector<Vec2f> uvs, uvs1;
  std::vector<uint32_t> indices;                                     ///< triangle list
  std::vector<std::vector<Vec3f>> target_positions, target_normals;  ///< morph target deltas
  std::vector<std::array<uint16_t, 4>> joints;                       ///< JOINTS_0 (skinning), empty if absent
  std::vector<Vec4f> weights;                                        ///< WEIGHTS_0
  int material = -1;
  bool points = false;       ///< POINTS: one degenerate triangle (i, i, i) per point (Mesh::points)
  bool lines = false;        ///< LINES, LINE_LOOP, LINE_STRIP: one (a, b, b) per segment (Mesh::lines)
  std::vector<float> radii;  ///< points and lines: the file's radii (PENUMBRA_points), else empty
  /// KHR_gaussian_splatting: the primitive's splats, rendered as splats (placed by
  /// add_splat_instances) instead of the POINTS the extension names as fallback.
  std::optional<SplatCloud> splats;
  bool usable = false;  ///< false: skipped with a warning
};

/// The number of placements EXT_mesh_gpu_instancing declares on `node`: the largest count of its
/// attribute accessors, read before any is decoded (placements_of checks that they agree); 1
/// without the extension.
uint64_t declared_placements(const GltfContext& ctx, int node);

/// The placements of what `node` carries: `world` x T_i R_i S_i for each EXT_mesh_gpu_instancing
/// instance i, or {world} without the extension (or, with a warning, without its attributes).
/// Throws InputError naming the attribute for malformed instance data.
std::vector<Transform> placements_of(const GltfContext& ctx, int node, const Transform& world);

/// The primitive extension giving points and lines their size: {"width": w > 0} in the mesh's
/// units (a point's diameter, a line's width), or per vertex in a SCALAR float attribute
/// "_WIDTH" (> 0), which wins.
inline constexpr const char* kPointsExtension = "PENUMBRA_points";

/// Every primitive of every mesh, [mesh][primitive]. POINTS become point sets (Mesh::points),
/// LINES, LINE_LOOP and LINE_STRIP line sets (Mesh::lines), with the file's radii if it gives
/// them. Triangle primitives without POSITION or triangles, and NaN positions are kept unusable
/// with a warning; malformed accessors, modes, materials, attribute counts, widths, a LINES
/// index count that is odd, a strip or loop of one vertex, and points or lines without POSITION
/// throw InputError naming the primitive.
std::vector<std::vector<LocalPrimitive>> decode_meshes(const GltfContext& ctx);

/// Places the mesh of every use (in order) into ctx.out.scene. A mesh placed more than once, or
/// by a moving node (NodeTransforms::moving; its instances never marked the identity), is
/// stored once in object space and instanced unless options.flatten; a mesh placed once by a
/// still node, and a skinned mesh, is put in world space. Every placement is charged to the
/// budget first; placements of moving nodes left out are counted in nodes.moving_skipped.
void place_meshes(const GltfContext& ctx, const std::vector<std::vector<LocalPrimitive>>& decoded,
                  NodeTransforms& nodes, const std::vector<MeshUse>& uses);

}  // namespace penumbra::gltf
