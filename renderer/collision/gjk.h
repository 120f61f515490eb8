// The distance between two convex proxies by the Gilbert-Johnson-Keerthi algorithm (Gilbert,
// Johnson & Keerthi, "A fast procedure for computing the distance between complex objects in
// three-dimensional space", IEEE J. Robotics and Automation 4(2), 1988), in the form of van den
// Bergen ("A fast and robust GJK implementation for collision detection of convex objects",
// JGT 4(2), 1999): the simplex nearest the origin in the Minkowski difference, reduced by the
// closest-point regions of Ericson ("Real-Time Collision Detection", 2005, sec. 5.1 and 9.5).
// Every proxy kind is a convex core (the hull of a few points: a sphere's centre, a capsule's
// segment, a box's corners, a polyhedron's vertices) grown by a radius, so spheres and capsules
// are measured exactly. gjk_distance never allocates, throws or logs.
#pragma once

#include <list>
#include <span>
#include <vector>

#include "renderer/collision/proxy.h"

namespace penumbra {

/// A convex set: the convex hull of `points` (at least one) grown by `radius` (>= 0).
struct ConvexCore {
  std::span<const DVec3> points;
  double radius = 0;
};

/// The result of gjk_distance.
struct ConvexDistance {
  bool intersect = false;  ///< the sets meet (closer than 1e-10 of their Minkowski difference's size counts)
  double distance = 0;     ///< the least distance between them; 0 when they meet
  DVec3 a{}, b{};          ///< closest points on each set (when they do not meet)
  int iterations = 0;
};

/// The distance between two convex cores. Converges when a support step improves the distance
/// by less than a relative 1e-12; at most 128 steps.
ConvexDistance gjk_distance(const ConvexCore& a, const ConvexCore& b);

/// The convex cores of a proxy: one for each kind, one per part of a composite. Holds the
/// points the cores of spheres, boxes and capsules need; hulls' cores view the proxy's parts,
/// which must outlive it.
struct ProxyCores {
  explicit ProxyCores(const Proxy& proxy);
  ProxyCores(const ProxyCores&) = delete;
  ProxyCores& operator=(const ProxyCores&) = delete;
  std::vector<ConvexCore> cores;
  std::vector<size_t> part;  ///< per core: its index in Proxy::parts (0 for the other kinds)
  std::list<std::vector<DVec3>> storage;
};

/// The distance between two proxies: the least over their cores' pairs (a composite meets
/// another proxy when one of its parts does).
ConvexDistance proxy_distance(const Proxy& a, const Proxy& b);

/// How far two meeting proxies interpenetrate: the least translation of `b` that separates
/// them (the penetration depth) and its direction. Each proxy is a convex core grown by a
/// radius, and the Minkowski sum adds radii: depth = depth(cores) + ra + rb when the cores
/// meet, ra + rb - distance(cores) when they do not. The cores' depth is the least overlap of
/// their projections over the candidate axes that hold every facet normal of the cores'
/// Minkowski difference: face normals of each polyhedron or box and cross products of their
/// edges (a capsule's segment counts as an edge); it is exact over these (Cameron & Culley,
/// "Determining the minimum translational distance between two convex polyhedra", ICRA 1986).
/// When the edge pairs times the vertices exceed 5e7 tests only face normals are tried, which
/// bounds the depth from above (`exact` false). A composite reports its deepest part's depth
/// (separating all its parts at once may take more).
struct Penetration {
  bool intersect = false;
  double depth = 0;   ///< 0 when the proxies do not meet
  DVec3 direction{};  ///< unit: moving b by depth x direction separates them
  bool exact = true;
};
Penetration penetration(const Proxy& a, const Proxy& b);

/// The corner points of an oriented box (8).
void box_corners(const OrientedBox& box, DVec3 out[8]);

/// Segment-segment closest points (Ericson 5.1.9): the distance between segments p1q1 and p2q2,
/// with the closest points in c1, c2.
double segment_distance(DVec3 p1, DVec3 q1, DVec3 p2, DVec3 q2, DVec3& c1, DVec3& c2);

}  // namespace penumbra
