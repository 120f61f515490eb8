// Edge functions in fixed point: the rasteriser's inside test and its barycentrics as area
// ratios (Pineda, "A Parallel Algorithm for Polygon Rasterization", SIGGRAPH 1988), with the
// top-left fill rule of Direct3D and OpenGL, so that a sample on an edge shared by two
// triangles belongs to exactly one of them. Integer arithmetic only: the test is exact.
#pragma once

#include <cmath>
#include <cstdint>

namespace penumbra {

/// Sub-pixel precision: raster positions (vertices and sample positions) are snapped to
/// 1/4096 pixel.
inline constexpr int kSubpixelBits = 12;
inline constexpr double kSubpixelScale = double(1 << kSubpixelBits);
/// Largest |coordinate| in pixels a snapped position may have: coordinate differences stay
/// below 2^29 units and edge-function values below 2^60, inside int64.
inline constexpr double kMaxRasterCoordinate = double(1 << 16);

/// A raster position (x right, y down, pixel corners at integers) in 1/4096 pixel units.
struct FixedPoint {
  int64_t x = 0, y = 0;
};

/// Rounds to the nearest integer, halves away from zero (as std::llround, inline). Requires
/// finite |v| < 2^62.
inline int64_t round_to_int64(double v) {
  return int64_t(v + (v >= 0 ? 0.5 : -0.5));
}

/// Snaps a raster position to the fixed-point grid (round to nearest). Requires finite
/// |x|, |y| <= kMaxRasterCoordinate (clipping guarantees it for triangle vertices).
inline FixedPoint to_fixed(double x, double y) {
  return {round_to_int64(x * kSubpixelScale), round_to_int64(y * kSubpixelScale)};
}

/// Twice the signed area of (a, b, p): cross(b - a, p - a), exact. With raster y pointing
/// down it is positive when a, b, p turn clockwise on screen.
inline int64_t edge_function(FixedPoint a, FixedPoint b, FixedPoint p) {
  return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

/// Whether edge a -> b of a triangle whose edge functions are positive inside is a top or a
/// left edge (raster y down): a top edge is horizontal with the interior below it (dy == 0,
/// dx > 0), a left edge has the interior to its right (dy < 0). Samples exactly on such an
/// edge are inside; on the other edges they are outside.
inline bool is_top_left(FixedPoint a, FixedPoint b) {
  const int64_t dx = b.x - a.x, dy = b.y - a.y;
  return dy < 0 || (dy == 0 && dx > 0);
}

/// One edge as a line equation e(p) = a p.x + b p.y + c (= edge_function(from, to, p)) and
/// the fill rule's threshold: p is on the inner side iff e(p) >= threshold.
struct EdgeEquation {
  int64_t a = 0, b = 0, c = 0;
  int64_t threshold = 0;  ///< 0 for a top or left edge, 1 otherwise
  int64_t operator()(FixedPoint p) const { return a * p.x + b * p.y + c; }
};

/// A triangle ready for inside tests: its three edges, edge k opposite vertex k, so that
/// edge k's value at p is vertex k's barycentric coordinate times area2.
struct EdgeTriangle {
  EdgeEquation edge[3];
  int64_t area2 = 0;  ///< twice the area, > 0
};

/// The equation of edge from -> to.
inline EdgeEquation make_edge(FixedPoint from, FixedPoint to) {
  EdgeEquation e;
  e.a = from.y - to.y;
  e.b = to.x - from.x;
  e.c = from.x * to.y - from.y * to.x;
  e.threshold = is_top_left(from, to) ? 0 : 1;
  return e;
}

/// Sets up triangle (v0, v1, v2), which must have edge_function(v0, v1, v2) > 0 (callers
/// swap two vertices of a triangle of negative area; zero area covers no sample).
inline EdgeTriangle make_edge_triangle(FixedPoint v0, FixedPoint v1, FixedPoint v2) {
  EdgeTriangle t;
  t.edge[0] = make_edge(v1, v2);
  t.edge[1] = make_edge(v2, v0);
  t.edge[2] = make_edge(v0, v1);
  t.area2 = edge_function(v0, v1, v2);
  return t;
}

/// The three edge values at p (e[k] = barycentric weight of vertex k times area2) and
/// whether p is covered under the top-left rule.
inline bool edge_inside(const EdgeTriangle& t, FixedPoint p, int64_t e[3]) {
  e[0] = t.edge[0](p);
  e[1] = t.edge[1](p);
  e[2] = t.edge[2](p);
  return e[0] >= t.edge[0].threshold && e[1] >= t.edge[1].threshold && e[2] >= t.edge[2].threshold;
}

/// Screen-space (linear) barycentrics of a point as area ratios e[k] / area2 (they sum to 1).
inline void edge_barycentrics(const EdgeTriangle& t, const int64_t e[3], double out[3]) {
  const double inv = 1.0 / double(t.area2);
  out[0] = double(e[0]) * inv;
  out[1] = double(e[1]) * inv;
  out[2] = double(e[2]) * inv;
}

}  // namespace penumbra
