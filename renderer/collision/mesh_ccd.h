// Continuous collision detection on triangle meshes whose vertices move on straight lines
// between two poses (each vertex from its start to its end position at a constant rate, as
// Provot, "Collision and self-collision handling in cloth model dedicated to design garments",
// Graphics Interface 1997, and Bridson, Fedkiw & Anderson, "Robust treatment of collisions,
// contact and friction for cloth animation", SIGGRAPH 2002): two triangles first touch when a
// vertex of one meets the other's face or an edge of each meet. Either event needs the four
// points involved to be coplanar, a cubic in the fraction u of the interval; its roots in
// [0, 1] are isolated between the roots of its derivative and refined by bisection, and at each
// root, in order, the points are checked to actually meet (within a tolerance). A simultaneous
// descent of two trees over the triangles' swept boxes (the box of each triangle's six
// corners) finds the candidate pairs. Rigid, skinned and morphing meshes alike: only the
// vertices' two positions count, so a turning body's vertices travel on chords, not arcs.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/accel/polytope.h"
#include "renderer/collision/mesh_contact.h"

namespace penumbra {

/// A mesh in two poses: the same triangles over vertices at `start` (u = 0) and `end` (u = 1).
struct MovingMesh {
  std::span<const DVec3> start, end;  ///< the same count
  std::span<const uint32_t> triangles;
};

/// How close points must come to meet.
struct MeshCcdConfig {
  /// At a root of the coplanarity cubic the points meet when their distance is at most this
  /// fraction of the pair's size (the diagonal of the box both swept meshes fill).
  double tolerance = 1e-9;
  /// Triangle pairs tested at most (15 cubics each); past it the pair is undecided
  /// (MeshFirstContact::converged false), so that meshes sweeping through each other's bulk
  /// cannot run for hours.
  uint64_t max_triangle_pairs = 20000000;
};

/// A moving mesh's triangles' swept boxes (each the box of its corners in both poses) as a
/// tree, for mesh_first_contact; made once per mesh and used against many.
struct SweptTree {
  std::vector<DVec3> corners;      ///< per triangle, its swept box's lower and upper corner
  std::vector<uint32_t> segments;  ///< per triangle, (lower, upper, upper): what the tree is built over
  ContactTree tree;                ///< empty when the mesh has no triangles or its poses differ in size
};

/// The swept tree of `m` (empty when start and end differ in size).
SweptTree build_swept_tree(const MovingMesh& m);

/// The first contact of two moving meshes in one interval.
struct MeshFirstContact {
  bool hit = false;
  double u = 1;    ///< the fraction of the interval at first contact (hit), else 1
  DVec3 point{};   ///< hit: where they touch (the vertex, or the midpoint of the two edges' closest points)
  DVec3 normal{};  ///< hit: unit, from a towards b just before contact (zero when touching at u = 0)
  uint32_t triangle_a = 0, triangle_b = 0;  ///< hit: the triangles that touch first
  uint64_t triangle_pairs = 0;              ///< triangle pairs whose swept boxes overlap (tested)
  uint64_t feature_tests = 0;               ///< vertex-face and edge-edge cubics solved
  /// False when max_triangle_pairs ran out: undecided, nothing is known about the interval (the
  /// pairs are not visited in time order); hit is then false.
  bool converged = true;
};

/// The first u in [0, 1] at which the moving meshes touch (u = 0 when they meet at the start
/// within the tolerance at a coplanar feature; meshes already crossing at the start with no
/// feature coplanar then are the static test's to find). A pair of features that stays
/// coplanar through the interval (a vertex sliding in the plane of a face) is not detected by
/// its cubic; its neighbouring features are. `sa` and `sb` are a's and b's swept trees. Meshes
/// whose poses differ in size have no contact. Never throws.
MeshFirstContact mesh_first_contact(const MovingMesh& a, const SweptTree& sa, const MovingMesh& b,
                                    const SweptTree& sb, const MeshCcdConfig& config = {});

/// The same, building both swept trees.
MeshFirstContact mesh_first_contact(const MovingMesh& a, const MovingMesh& b,
                                    const MeshCcdConfig& config = {});

}  // namespace penumbra
