// Continuous (dynamic, a priori) collision detection: the first time two moving bodies touch
// between two poses, so that a body that passes through a thin wall between two sampled frames
// is caught. On meshes, by the exact times of mesh_ccd.h. On proxies, each body is a fitted convex proxy
// (ProxyCores) moved by a rigid motion; the time of first contact comes from conservative advancement
// (Mirtich, "Impulse-based Dynamic Simulation of Rigid Body Systems", PhD thesis, UC Berkeley, 1996): at each
// step the distance d between the bodies, measured by GJK, and a bound mu on how fast any point of one can
// approach the other along the closest direction n give a time d / mu during which they cannot meet; the
// bound is |v . n| + omega_a rho_a + omega_b rho_b for linear velocities v, angular speeds omega and the
// bodies' largest distances rho from their centres of rotation (Zhang, Lee & Kim, "Interactive continuous
// collision detection for non-convex polyhedra", The Visual Computer 22(9), 2006). Between two poses each
// node moves along a straight line of its centre while turning about it at a constant rate (slerp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/collision/gjk.h"
#include "renderer/collision/scene_collide.h"
#include "renderer/core/math.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// A rigid motion over the fraction u in [0, 1] of an interval: a point p (at u = 0) is at
///   center0 + u (center1 - center0) + R(u) (p - center0)
/// where R(u) turns by u x angle about rotation's axis (slerp from the identity).
struct RigidMotion {
  DVec3 center0{}, center1{};
  Quat rotation{};   ///< unit, w >= 0: the whole turn from u = 0 to u = 1
  double angle = 0;  ///< its angle in radians, in [0, pi]
};

/// The motion that carries center0 to center1 while turning by `rotation` (normalised here).
RigidMotion make_rigid_motion(DVec3 center0, DVec3 center1, const Quat& rotation);

/// Where the point p (at u = 0) is at the fraction u of the motion.
DVec3 move_point(const RigidMotion& m, DVec3 p, double u);

/// Convex cores that follow a rigid motion: copies of a proxy's cores (at u = 0), posed at any u.
struct MovingCores {
  explicit MovingCores(const ProxyCores& rest);
  MovingCores(const MovingCores&) = delete;
  MovingCores& operator=(const MovingCores&) = delete;
  /// Moves the cores to the fraction u of `motion`.
  void pose(const RigidMotion& motion, double u);
  std::vector<std::vector<DVec3>> rest;   ///< per core, its points at u = 0
  std::vector<std::vector<DVec3>> posed;  ///< per core, its points at the last pose
  std::vector<ConvexCore> cores;          ///< views of `posed`, with the cores' radii
};

/// How conservative advancement ends.
struct AdvancementConfig {
  /// The bodies touch when their distance falls below this fraction of the pair's size (the
  /// sum of the largest distances of their cores' points from their centres, and the distance
  /// the centres travel).
  double tolerance = 1e-9;
  int max_steps = 10000;  ///< steps before giving up, undecided, with a lower bound on the time of contact
  /// GJK distances (steps x pairs of cores) before giving up, undecided, likewise.
  uint64_t max_distances = 20000000;
};

/// The first contact of two moving bodies within one interval.
struct FirstContact {
  bool hit = false;       ///< they touch at some u in [0, 1]
  double u = 1;           ///< the fraction of the interval at first contact (hit), else 1
  DVec3 point{};          ///< hit: the midpoint of the closest points at contact
  DVec3 normal{};         ///< hit: unit, from a towards b just before contact (0 when they meet at u = 0)
  int steps = 0;          ///< advancement steps (each a GJK distance per pair of cores)
  bool converged = true;  ///< false: max_steps ran out; u is then a lower bound on the time of contact
};

/// The first u in [0, 1] at which `a` moving by `ma` and `b` moving by `mb` touch, by
/// conservative advancement; they touch at u = 0 if they meet there. Both must hold at least
/// one core. Bodies that turn while staying close without touching may need many steps: past
/// the budget the answer is undecided (converged false).
FirstContact first_contact(MovingCores& a, const RigidMotion& ma, MovingCores& b, const RigidMotion& mb,
                           const AdvancementConfig& config = {});

/// Two nodes' first contact between the two poses.
struct SweptContact {
  int a = -1, b = -1;     ///< glTF nodes, a < b
  double u = 0;           ///< the fraction of the interval at first contact
  DVec3 point{};          ///< where they touch
  DVec3 normal{};         ///< unit, from a towards b just before contact (0 when touching at the start)
  bool converged = true;  ///< false: undecided (in ContinuousReport::undecided): no contact before u
};

/// What collide_continuous found, with the work of each phase.
struct ContinuousReport {
  std::vector<SweptContact> contacts;   ///< sorted by (a, b)
  std::vector<SweptContact> undecided;  ///< pairs whose advancement ran out of budget, sorted by (a, b)
  uint64_t nodes = 0;                   ///< nodes with geometry in both poses
  uint64_t moving_nodes = 0;            ///< of those, nodes whose points move between the poses
  std::vector<int> nonrigid_nodes;      ///< nodes left out: not rigid (proxies), changing triangles (meshes)
  uint64_t broad_pairs = 0;             ///< node pairs whose swept boxes overlap
  uint64_t family_pairs = 0;            ///< of those, pairs the hierarchy or a skin joins, left out
  uint64_t narrow_tests = 0;            ///< node pairs advanced
  uint64_t steps = 0;                   ///< advancement steps over every pair (meshes: swept triangle pairs)
};

/// The first contacts between the poses `start` (u = 0) and `end` (u = 1) of the same scene
/// (the same instances in the same order, posed at two times).
/// Proxies (!config.mesh): proxies of `config.kind` are fitted to each rigid node's geometry at
/// the start, each node moves rigidly as described in the banner, and a broad phase over the
/// boxes each proxy sweeps comes before conservative advancement on the pairs. Nodes whose
/// vertices do not follow one rigid motion (skinning, morphing, changing scale) are listed in
/// nonrigid_nodes and left out.
/// Meshes (config.mesh): every vertex moves on a straight line between its two positions (any
/// motion: rigid, skinned, morphed); a broad phase over the boxes of both poses, then pairs that
/// meet at the start (mesh_contacts) touch at u = 0, the others' first contact comes from
/// mesh_first_contact (exact vertex-face and edge-edge times); nodes whose triangles differ
/// between the poses are listed in nonrigid_nodes and left out; `steps` counts the triangle
/// pairs whose swept boxes overlap; a pair past MeshCcdConfig's budget is undecided at u = 0.
/// Throws std::invalid_argument naming the node if its geometry cannot be fitted.
ContinuousReport collide_continuous(const Scene& start, const Scene& end, const NodeLinks& links,
                                    const CollideConfig& config, const AdvancementConfig& advance = {});

}  // namespace penumbra
