// Homogeneous clipping of triangles in clip space (Sutherland and Hodgman, "Reentrant Polygon
// Clipping", CACM 1974; Blinn and Newell, "Clipping Using Homogeneous Coordinates", SIGGRAPH
// 1978): against the near plane, a finite far plane and a guard band around the viewport, so
// that every vertex that reaches the rasteriser has w > 0 and a bounded raster position.
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// A clip-space vertex with its barycentric coordinates in the source triangle (b[k] weighs
/// source vertex k; they sum to 1) and its camera-space depth, both interpolated along the
/// clipped edges exactly as the position is.
struct ClipVertex {
  Vec4f p;                 ///< clip-space position (x, y, z, w)
  float b[3] = {0, 0, 0};  ///< barycentrics in the source triangle
  float depth = 0;         ///< camera-space depth (distance along the view axis)
};

/// Each plane adds at most one vertex to a convex polygon: a triangle clipped by the six
/// planes below has at most 9.
inline constexpr int kMaxClipVertices = 9;

/// The planes clip_triangle() uses.
struct ClipPlanes {
  bool far = true;     ///< also clip at z <= w (false for an infinite far plane)
  float guard = 2.0f;  ///< x and y are clipped at +-guard w (>= 1): the guard band, in units of
                       ///< the viewport's half-extent, so few triangles need clipping at the
                       ///< sides and no clipped edge runs through the viewport
};

/// Which planes p lies outside of, as a bit mask (bit 0 near, 1 far, 2..5 the guard band's
/// left, right, bottom, top). When the three vertices of a triangle share a bit, it is
/// invisible; when none is set, it needs no clipping. NaN coordinates are outside every plane.
inline unsigned clip_outcode(const Vec4f& p, const ClipPlanes& planes) {
  const float g = planes.guard * p.w;
  return unsigned(!(p.z + p.w >= 0)) | unsigned(planes.far && !(p.w - p.z >= 0)) << 1 |
         unsigned(!(g + p.x >= 0)) << 2 | unsigned(!(g - p.x >= 0)) << 3 | unsigned(!(g + p.y >= 0)) << 4 |
         unsigned(!(g - p.y >= 0)) << 5;
}

/// Clips triangle `in` against the planes (near: z + w >= 0; far: w - z >= 0; guard band:
/// guard w -+ x >= 0 and likewise for y) and writes the convex polygon that remains to `out`
/// (a triangle fan from out[0]); returns its vertex count, 0 if nothing remains. An edge's
/// intersection point is computed from its endpoints in one canonical order, so the two
/// triangles sharing an edge get bit-identical new vertices on it (no cracks). Never
/// allocates.
int clip_triangle(const ClipVertex in[3], const ClipPlanes& planes, ClipVertex out[kMaxClipVertices]);

}  // namespace penumbra
