// Bounded convex polyhedra in double precision, for builders whose nodes are regions cut by
// arbitrary planes (the BSP tree of accel/bsp.h): a box, clipping by a half-space, the exact
// surface area and volume, and the areas of both parts of a cut without building them (the
// SAH's inputs). Build-time only: nothing here is used by traversal, so rounding here can only
// change a tree's quality, never an answer.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "renderer/core/dvec3.h"
#include "renderer/core/math.h"

namespace penumbra {

/// The nearest point of triangle abc to p, by the Voronoi region of p (Ericson, "Real-Time
/// Collision Detection", 2005, 5.1.5); finite for triangles without area (repeated corners).
DVec3 closest_on_triangle(DVec3 p, DVec3 a, DVec3 b, DVec3 c);
/// A closed convex polyhedron stored as its faces: convex polygons over a shared vertex list,
/// each counter-clockwise seen from outside, with its outward unit normal and area. The default
/// polytope is empty. Planes are (n, k) with n of any non-zero length: dot(n, p) - k >= 0 is the
/// positive side. Points within a relative 1e-13 of a cutting plane count as on it, so no cut
/// leaves slivers of rounding size.
class Polytope {
 public:
  Polytope() = default;
  /// The box `b`; empty if `b` has a zero, negative or non-finite extent on some axis.
  explicit Polytope(const Bounds3f& b);

  bool empty() const { return m_faces.empty(); }
  size_t face_count() const { return m_faces.size(); }
  std::span<const DVec3> vertices() const { return m_vertices; }
  /// Sum of the faces' areas; 0 when empty.
  double area() const;
  /// Enclosed volume (divergence theorem over the faces); 0 when empty.
  double volume() const;
  /// The range [lo, hi] of dot(n, p) over the polytope; lo > hi when empty.
  void extent(DVec3 n, double& lo, double& hi) const;
  /// The part on the positive side of plane (n, k) (`positive`) or on its negative side, with
  /// the cut closed by a cap face in the plane. Empty when that side holds no volume; a copy
  /// when the plane does not cut.
  Polytope clip(DVec3 n, double k, bool positive) const;
  /// For each k = positions[i], the surface areas of clip(n, k, false) and clip(n, k, true)
  /// (their caps included), written to negative[i] and positive[i] (spans of the same size),
  /// without building them: the cap's area follows from the clipped faces, whose area vectors
  /// sum to zero with it.
  void split_areas(DVec3 n, std::span<const double> positions, std::span<double> negative,
                   std::span<double> positive) const;
  /// The faces as fans of triangles, counter-clockwise seen from outside: 3 indices into
  /// vertices() per triangle appended to `indices` (vertices no face uses stay unreferenced).
  void triangles(std::vector<uint32_t>& indices) const;

 private:
  friend class PolytopeSlicer;

  struct Face {
    uint32_t begin = 0, count = 0;  ///< the face's vertex indices: m_loops[begin, begin + count)
    DVec3 normal{};                 ///< outward, unit
    double area = 0;
  };

  /// Adds the polygon m_loops[begin, end) as a face with outward unit normal `normal`, or drops
  /// it (and its indices) if its area is not positive.
  void add_face(uint32_t begin, DVec3 normal);

  std::vector<DVec3> m_vertices;
  std::vector<uint32_t> m_loops;   ///< every face's vertex indices, face after face
  std::vector<double> m_fan_area;  ///< per m_loops entry j >= 1 but the face's last: the area of
                                   ///< the triangle (its face's first entry, j, j + 1)
  std::vector<Face> m_faces;
};

/// Cuts of one polytope by parallel planes dot(n, p) = k: the vertices' projections on n and
/// the faces' ranges of them are computed once (reset()), then each position costs O(faces),
/// plus a closed form per triangle of the crossed faces' fans for the exact areas. Reusable:
/// reset() keeps the memory. Polytope::split_areas() is this over a list of positions.
class PolytopeSlicer {
 public:
  /// Prepares cuts of `p` by planes with normal n (any non-zero length). `p` must outlive the
  /// calls until the next reset().
  void reset(const Polytope& p, DVec3 n);
  /// The surface areas of the parts on the negative and positive sides of dot(n, p) = k,
  /// caps included (what Polytope::split_areas() reports).
  void areas(double k, double& negative, double& positive);

 private:
  /// A triangle of a face's fan: its vertices' heights along n sorted (a <= b <= c), its area
  /// and the factors of the part below a height between them.
  struct FanTriangle {
    double a, b, c, area, lower, upper;
  };

  const Polytope* m_poly = nullptr;
  double m_scale = 0, m_total = 0;
  std::vector<double> m_proj;      ///< per vertex: dot(n, v)
  std::vector<double> m_face_lo;   ///< per face: the smallest projection of its vertices
  std::vector<double> m_face_hi;   ///< per face: the largest
  std::vector<double> m_face_cos;  ///< per face: cosine of its normal with n
  std::vector<FanTriangle> m_fan;  ///< per m_loops entry as Polytope::m_fan_area, filled for a face
                                   ///< the first time a plane crosses it
  std::vector<uint8_t> m_ready;    ///< per face: its m_fan entries filled
};

}  // namespace penumbra
