// Shapes as triangles, for the queries that take triangle meshes (proxy fitting, collisions):
// boxes exactly; spheres as a subdivided icosahedron with its corners on the sphere; capsules
// as that icosphere's two halves moved apart along the axis (its equatorial band becomes the
// cylinder); planes as two triangles; disks as a fan; implicit shapes by marching cubes over
// their bounds. Each comes with a bound on how far the triangles and the true surface lie apart.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/shapes/shape.h"

namespace penumbra {

/// How finely shape_triangles divides curved shapes.
///
/// | field               | default | meaning                                                   |
/// |---------------------|---------|-----------------------------------------------------------|
/// | subdivisions        | 3       | icosahedron subdivisions of spheres and capsules, [0, 6]:  |
/// |                     |         | 20 x 4^n triangles (3: 1280; error 0.3 % of a sphere's     |
/// |                     |         | radius, 1.3 % of a capsule's)                              |
/// | disk_segments       | 64      | triangles of a disk's fan, [3, 65536]                      |
/// | implicit_resolution | 64      | marching cubes cells along an implicit shape's longest     |
/// |                     |         | bound, [1, 1024]                                           |
struct ShapeTrianglesConfig {
  int subdivisions = 3;
  int disk_segments = 64;
  int implicit_resolution = 64;
};

/// A shape's surface as triangles in its object space, wound counter-clockwise seen from
/// outside (flat shapes: from their front, +Y).
struct ShapeTriangles {
  std::vector<Vec3f> positions;
  std::vector<uint32_t> indices;  ///< 3 per triangle
  bool closed = true;             ///< false for planes and disks
  /// Every point of the true surface lies within `error` of the triangles and every point of
  /// the triangles within `error` of the true surface (in object space; 0 for boxes and planes).
  /// Spheres, capsules and disks: exact bounds (the triangles are inscribed, so this is the
  /// radius less the least distance from the axis or centre to a triangle). Implicit shapes:
  /// the diagonal of a grid cell, for features larger than a cell (marching cubes can miss
  /// thinner ones).
  double error = 0;
};

/// The triangles of `shape`. Throws std::invalid_argument for a config value out of range or an
/// implicit shape without bounds (its inside is not bounded), and what extract_isosurface
/// throws.
ShapeTriangles shape_triangles(const Shape& shape, const ShapeTrianglesConfig& config = {});

/// What shape_triangles makes, for memory budgets: exact counts, except for implicit shapes,
/// estimated from marching_cubes_bytes's mesh estimate (48 bytes per vertex with its two
/// triangles). Throws as shape_triangles for a bad config; an unbounded implicit shape counts 0.
struct ShapeTrianglesCount {
  uint64_t vertices = 0, triangles = 0;
};
ShapeTrianglesCount shape_triangles_count(const Shape& shape, const ShapeTrianglesConfig& config = {});

}  // namespace penumbra
