// Convex polyhedra as collision proxies: the convex hull of a point set, computed by Qhull
// (Barber, Dobkin & Huhdanpaa, "The Quickhull algorithm for convex hulls", ACM TOMS 22(4), 1996;
// Debian's libqhull_r), and the intersection of half-spaces a k-DOP is (Klosowski et al.,
// "Efficient collision detection using bounding volume hierarchies of k-DOPs", IEEE TVCG 4(1),
// 1998). Both are stored alike: vertices, outward triangles and the planes of the merged faces.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/accel/polytope.h"

namespace penumbra {

/// A plane n . p = d with unit n: the inside is n . p <= d.
struct DPlane {
  DVec3 n{};
  double d = 0;
};

/// A bounded convex polyhedron.
struct ConvexPolyhedron {
  std::vector<DVec3> vertices;      ///< every vertex is a corner of some face
  std::vector<uint32_t> triangles;  ///< 3 per triangle, counter-clockwise seen from outside
  std::vector<uint32_t> face_of;    ///< per triangle: its face, an index into planes
  std::vector<DPlane> planes;       ///< one per face (coplanar facets merged)
  double volume = 0;                ///< enclosed volume (divergence theorem over the triangles)
  double area = 0;                  ///< surface area
  double qhull_volume = -1;         ///< Qhull's own volume of the hull (totvol); -1 if not a hull
  bool thickened = false;           ///< the points spanned no volume (see ConvexHullConfig)
};

/// How convex_hull treats its input.
struct ConvexHullConfig {
  /// Points that span no volume (all on a plane, a line or one point) are hulled together with
  /// copies moved by +-thickness x (the points' bounding-box diagonal, or 1 if that is 0) along
  /// each axis, so a flat part gets a slab of that relative thickness instead of no hull.
  double thickness = 1e-6;
};

/// The convex hull of `points` (finite; at least one): Qhull on joggled input ('QJ': robust and
/// fast on many coplanar or cospherical points, where merging facets is quadratic), its
/// triangles over the original points, edge-adjacent triangles in one plane (to 1e-9 of the
/// size) merged into faces, each face's plane offset to its
/// farthest vertex. Joggling moves points by about 1e-11 of the size, so a point may lie that
/// far outside a plane. Points spanning less than `thickness` (volume under thickness x area)
/// count as flat (ConvexHullConfig). Throws std::invalid_argument for an empty
/// or non-finite input and std::runtime_error with Qhull's message if Qhull fails otherwise.
ConvexPolyhedron convex_hull(std::span<const DVec3> points, const ConvexHullConfig& config = {});

/// The convex hull of the points' (x, y) (z ignored), by Qhull in 2-d: the indices of its
/// corners, counter-clockwise. Empty when the points span no area (collinear or coincident)
/// or Qhull fails.
std::vector<uint32_t> convex_hull_2d(std::span<const DVec3> points);

/// The polyhedron bounded by `planes` (unit normals; the inside is n . p <= d), clipped from
/// the box `box` (which must contain it). Empty (no vertices) if the planes enclose nothing.
ConvexPolyhedron polyhedron_from_planes(std::span<const DPlane> planes, const Bounds3f& box);

/// The smallest and largest n . v over the vertices.
void polyhedron_extent(const ConvexPolyhedron& poly, DVec3 n, double& lo, double& hi);

/// True if p lies inside every plane, allowing `tolerance` (world units).
bool polyhedron_contains(const ConvexPolyhedron& poly, DVec3 p, double tolerance);

}  // namespace penumbra
