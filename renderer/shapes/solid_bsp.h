// Solid (leaf-labelled) BSP trees of closed triangle meshes for point-in-polyhedron tests: an
// autopartition by the triangles' own planes (H. Fuchs, Z. Kedem, B. Naylor, "On Visible Surface
// Generation by A Priori Tree Structures", SIGGRAPH 1980) whose leaves are labelled IN or OUT
// (W. Thibault, B. Naylor, "Set Operations on Polyhedra Using Binary Space Partitioning Trees",
// SIGGRAPH 1987), and SolidMesh, the tree with a small BVH over the triangles for exact signed
// distances (the SDF primitive SdfKind::Polyhedron). Not a general CSG-on-meshes library: no
// tree merging, no boundary output. Plain data and free functions; queries never allocate or throw.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

/// How build_solid_bsp partitions. Validated by the builders (std::invalid_argument naming the
/// field and the value).
///
/// | field               | default | range         | meaning                                       |
/// |---------------------|---------|---------------|-----------------------------------------------|
/// | candidates          | 12      | [1, 4096]     | splitters tried per node: polygons evenly     |
/// |                     |         |               | spaced in its list (deterministic)            |
/// | score_sample        | 256     | [1, 2^20]     | polygons, evenly spaced, each candidate is    |
/// |                     |         |               | scored on                                     |
/// | split_weight        | 4       | [0, 1e6]      | score = split_weight x splits                 |
/// |                     |         |               |         + abs(front - back)                   |
/// | relative_epsilon    | 1e-7    | [1e-12, 1e-2] | a vertex within relative_epsilon x the        |
/// |                     |         |               | bounding box's diagonal of a plane is on it   |
/// | max_nodes           | 0       | >= 0          | budget of nodes and of polygon fragments      |
/// |                     |         |               | (triangles + splits); 0: 8 x triangles + 1024 |
/// |                     |         |               | (at most 2^27)                                |
/// | max_classifications | 0       | >= 0          | budget of polygon-plane tests, the build's    |
/// |                     |         |               | time (a convex part of n triangles needs      |
/// |                     |         |               | about n^2 / 2); 0: unlimited                  |
struct SolidBspConfig {
  int candidates = 12;
  int score_sample = 256;
  double split_weight = 4;
  double relative_epsilon = 1e-7;
  uint64_t max_nodes = 0;
  uint64_t max_classifications = 0;
};

/// Leaf labels in SolidBspNode::front / back: the region is inside (IN) or outside (OUT) the solid.
inline constexpr int32_t kSolidBspIn = -1;
inline constexpr int32_t kSolidBspOut = -2;

/// One splitting plane. 40 bytes: the plane (32), the two children (8).
struct SolidBspNode {
  double nx = 0, ny = 0, nz = 1;  ///< unit normal, pointing out of the solid (the triangle winding's side)
  double d = 0;                   ///< plane: nx x + ny y + nz z = d
  int32_t front = kSolidBspOut;   ///< where n . p - d > 0: a node index (> this node's), or a leaf label
  int32_t back = kSolidBspIn;     ///< where n . p - d <= 0
};
static_assert(sizeof(SolidBspNode) == 40, "SolidBspNode is 40 bytes");

/// What a build made.
struct SolidBspStats {
  uint64_t triangles = 0;        ///< triangles partitioned (of non-zero area)
  uint64_t degenerate = 0;       ///< triangles skipped: repeated (welded) vertices or zero area
  uint64_t fragments = 0;        ///< polygons partitioned: triangles + splits
  uint64_t splits = 0;           ///< polygons cut in two by a splitting plane
  uint64_t classifications = 0;  ///< polygon-against-plane tests (splitter scores and partitions)
  uint64_t in_leaves = 0, out_leaves = 0;
  int depth = 0;  ///< nodes on the longest root-to-leaf path
};

/// A solid BSP tree. Children always have larger indices than their parent.
struct SolidBsp {
  std::vector<SolidBspNode> nodes;  ///< root at 0; no nodes: every point is outside
  bool flipped = false;  ///< the mesh wound inwards (negative signed volume): its winding was reversed
  double volume = 0;     ///< the enclosed volume (> 0), from the (reversed if flipped) winding
  double tolerance = 0;  ///< the absolute on-plane tolerance used: relative_epsilon x diagonal
  Bounds3f bounds;       ///< of the mesh's vertices: every point outside is outside the solid
  SolidBspStats stats;
};

/// What the builders throw for a mesh they refuse (std::invalid_argument). what() is
/// "build_solid_bsp: the mesh " + reason(); reason() reads after a mesh's name, e.g.
/// "is not closed: edge (12, 40) is used by 1 triangle".
class SolidMeshError : public std::invalid_argument {
 public:
  SolidMeshError(const std::string& reason, bool over_budget);
  const std::string& reason() const { return m_reason; }
  /// True when the build needed more than SolidBspConfig::max_nodes nodes or fragments, or
  /// more than max_classifications polygon tests.
  bool over_budget() const { return m_over_budget; }

 private:
  std::string m_reason;
  bool m_over_budget;
};

/// Builds the solid BSP tree of the closed mesh (positions, indices: 3 per triangle). Vertices
/// at exactly equal positions are welded first (glTF meshes split vertices along seams), and
/// vertex indices in messages are the first original index of each welded group. Checks, in
/// order, each a SolidMeshError: an index count not a multiple of 3, no triangles, an index out
/// of range, a non-finite vertex used by a triangle, then, over the triangles whose three
/// (welded) vertices differ, that every edge is used by exactly one triangle in each direction
/// ("is not closed: edge (a, b) is used by 1 triangle", "is not consistently oriented: ..."),
/// then that some triangle has non-zero area and that the mesh encloses a volume. Triangles of
/// zero area (or with repeated vertices) are skipped. A mesh whose signed volume is negative
/// (wound inwards) is flipped, not refused: SolidBsp::flipped records it. Orientation is judged
/// over the whole mesh: a component wound against the rest (other than a cavity) is not found.
/// Splitting runs in double; a build needing more nodes or fragments than config.max_nodes, or
/// more than config.max_classifications polygon tests, throws SolidMeshError with
/// over_budget(). Deterministic. Time grows with the square of the triangles of a convex part
/// (an autopartition of a convex solid is a chain), and so does the depth of the tree, which is
/// what a query costs.
SolidBsp build_solid_bsp(std::span<const Vec3f> positions, std::span<const uint32_t> indices,
                         const SolidBspConfig& config = {});

/// True if p lies inside the solid. Points within about SolidBsp::tolerance of the surface may
/// answer either way. Cost: a box test, then one plane test per level. Never allocates or throws.
bool solid_bsp_inside(const SolidBsp& bsp, Vec3f p);

/// A node of SolidMesh's distance BVH. 32 bytes: the box (24), first (4), count (4).
struct SolidMeshBvhNode {
  Vec3f lo, hi;  ///< bounds of the node's triangles
  /// Leaf: the first triangle; inner: the second child's index (the first child follows the node).
  uint32_t first = 0;
  uint32_t count = 0;  ///< leaf: number of triangles (> 0); inner: 0
};
static_assert(sizeof(SolidMeshBvhNode) == 32, "SolidMeshBvhNode is 32 bytes");

/// A closed mesh as a solid with exact distances: the welded, outward-wound triangles, a BVH
/// over those of non-zero area (median splits, up to 4 per leaf) and the solid BSP.
struct SolidMesh {
  std::vector<Vec3f> positions;   ///< the welded vertices
  std::vector<uint32_t> indices;  ///< 3 per triangle, outward winding: the first bvh_triangles in BVH leaf
                                  ///< order, then the zero-area ones (kept so the mesh stays closed)
  uint32_t bvh_triangles = 0;
  std::vector<SolidMeshBvhNode> bvh;  ///< root at 0; empty only for a default-constructed SolidMesh
  SolidBsp bsp;
  Bounds3f bounds;             ///< of the positions
  float surface_distance = 0;  ///< below this distance the gradient is the nearest triangle's normal
};

/// The mesh's solid (build_solid_bsp's checks and errors) with its distance BVH.
SolidMesh build_solid_mesh(std::span<const Vec3f> positions, std::span<const uint32_t> indices,
                           const SolidBspConfig& config = {});

/// The nearest point of the mesh's surface to p.
struct SolidMeshClosest {
  float distance = kInfinity;  ///< Euclidean distance to `point`
  Vec3f point;                 ///< closest point (exact point-triangle distance, in double)
  uint32_t triangle = 0;       ///< triangle index (into indices / 3) it lies on
};

/// The closest surface point to p: a BVH walk with a fixed stack, nearer child first, boxes
/// farther than the best distance pruned. distance = kInfinity for an empty mesh. Never
/// allocates or throws.
SolidMeshClosest solid_mesh_closest(const SolidMesh& mesh, Vec3f p);

/// -distance inside the solid (solid_bsp_inside), +distance outside: Lipschitz 1 away from the
/// surface's tolerance band. Never allocates or throws.
float solid_mesh_signed_distance(const SolidMesh& mesh, Vec3f p);

/// The unit gradient of solid_mesh_signed_distance at p: +-(p - closest) / distance, or the
/// closest triangle's outward normal within surface_distance of the surface. Never allocates
/// or throws.
Vec3f solid_mesh_gradient(const SolidMesh& mesh, Vec3f p);

/// Bytes the mesh's vectors hold (positions, indices, BVH, BSP nodes).
uint64_t solid_mesh_bytes(const SolidMesh& mesh);

}  // namespace penumbra
