// Static (discrete, a posteriori) collision detection over a scene's nodes at one pose: the
// world-space geometry of each node that places a mesh, a broad phase by sweep and prune over
// their boxes (Cohen, Lin, Manocha & Ponamgi, "I-COLLIDE", I3D 1995), pairs that the node
// hierarchy or a skin joins (nodes_joined) left out unless asked, and a narrow phase on the
// triangles (mesh_contact: exact; closed meshes also as solids, for a solid inside another
// and the depth of the deepest surface point inside the other) or on fitted proxies (gjk:
// distance and penetration depth), and optionally the volume of each interpenetration
// (shared_volume.h).
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "renderer/collision/mesh_contact.h"
#include "renderer/collision/proxy.h"
#include "renderer/collision/scene_proxies.h"
#include "renderer/collision/shared_volume.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// What collide_scene tests.
struct CollideConfig {
  bool mesh = true;                  ///< narrow phase on the triangles; false: on proxies of `kind`
  ProxyKind kind = ProxyKind::Hull;  ///< the proxies' kind when !mesh
  ProxyConfig fit;                   ///< their fitting
  bool include_children = false;     ///< also test pairs the hierarchy or a skin joins (nodes_joined)
  bool volumes = false;              ///< measure each contact's interpenetration volume
  SharedVolumeConfig volume;         ///< how (meshes, and proxies without a closed form)
  /// Meshes' solids for volumes (each node's mesh must be closed); the partition's quadratic
  /// time on convex parts is capped at 10^9 polygon tests.
  SolidBspConfig solid{.max_classifications = 1000000000};
  /// Meshes' penetration depth: surface samples per node pair at most (the spacing, and so
  /// NodeContact::depth_error, grows until they fit; when the corners of the triangles inside
  /// the pair's common box alone exceed it, those are the samples); 0: no depth.
  uint64_t depth_samples = uint64_t(1) << 18;
  ShapeTrianglesConfig shapes;  ///< how nodes' shapes become triangles
};

/// Two nodes that touch or interpenetrate.
struct NodeContact {
  int a = -1, b = -1;  ///< glTF nodes, a < b
  /// Proxies: the penetration depth (0 when touching). Closed meshes: the depth of the deepest
  /// point of either surface inside the other solid, sampled (a lower bound on the distance
  /// either must move to come apart; exact when a vertex goes deepest, as in a box sunk into a
  /// floor); NaN when a mesh is open.
  double depth = NAN;
  /// Meshes: the true deepest point lies at most this much deeper than `depth` (the samples'
  /// spacing: every surface point lies within it of a sample); 0 for proxies.
  double depth_error = 0;
  /// Unit, moving b by depth along it separates them (proxies), or moves the deepest point out
  /// (meshes; zero when no sample lies inside).
  DVec3 direction{};
  /// A point where they meet (meshes: where two triangles meet; when one solid holds the other
  /// without their surfaces meeting, the deepest sample, or a vertex inside with no depth).
  DVec3 point{};
  /// Nodes placing shapes: the points and depth are those of the shapes' triangles, which lie
  /// within this distance of the true surfaces (NodeGeometry::shape_error, the larger of the
  /// two); 0 for meshes.
  double shape_error = 0;
  uint64_t triangle_pairs = 0;  ///< meshes: the pairs of triangles that meet
  VolumeEstimate volume;        ///< with CollideConfig::volumes: the volume they share
};

/// What collide_scene found, with the work of each phase.
struct CollideReport {
  std::vector<NodeContact> contacts;  ///< sorted by (a, b)
  uint64_t nodes = 0;                 ///< nodes with geometry
  uint64_t broad_pairs = 0;           ///< node pairs whose world boxes overlap
  uint64_t family_pairs = 0;          ///< of those, pairs the hierarchy or a skin joins, left out
  uint64_t narrow_tests = 0;          ///< node pairs tested exactly
  uint64_t triangle_tests = 0;        ///< meshes: triangle pairs tested
};

/// The box of `points` in single precision, rounded outward so that it holds them.
Bounds3f points_box(std::span<const DVec3> points);

/// Per triangle of a node's geometry, +1 or -1 so that each placement's meshes (the instances
/// sharing one placement) wind outward: the sign of their signed volume (a mirrored placement or
/// an inward-wound file gives a negative one). For mesh_winding on closed nodes.
std::vector<int8_t> outward_orientation(const NodeGeometry& g);

/// A vertex of `from` inside the solid of the closed node `into` (mesh_winding over its contact
/// tree `into_tree` with `into_orientation`: a positive winding number), or null. Only vertices
/// within into's box are tested.
const DVec3* vertex_inside(const NodeGeometry& from, const NodeGeometry& into, const ContactTree& into_tree,
                           std::span<const int8_t> into_orientation);

/// The pairs of overlapping boxes among `boxes` (i < j), sorted: sweep and prune along x, then
/// the y and z intervals.
std::vector<std::pair<uint32_t, uint32_t>> sweep_and_prune(std::span<const Bounds3f> boxes);

/// Every pair of nodes whose geometry touches or interpenetrates at the scene's pose. Throws
/// std::invalid_argument naming the node if its geometry cannot be fitted (proxies) or, for
/// volumes on meshes, is not a closed mesh (build_solid_mesh's checks) or needs more than the
/// solid's budget.
CollideReport collide_scene(const Scene& scene, const NodeLinks& links, const CollideConfig& config);

}  // namespace penumbra
