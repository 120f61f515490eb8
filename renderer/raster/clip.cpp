// Sutherland-Hodgman clipping in homogeneous coordinates.
#include "renderer/raster/clip.h"

#include <tuple>

namespace penumbra {

namespace {

constexpr int kPlanes = 6;

// Signed distance-like value of p to plane k (inside >= 0).
float plane_value(const Vec4f& p, int k, float guard) {
  switch (k) {
    case 0:
      return p.z + p.w;
    case 1:
      return p.w - p.z;
    case 2:
      return guard * p.w + p.x;
    case 3:
      return guard * p.w - p.x;
    case 4:
      return guard * p.w + p.y;
    default:
      return guard * p.w - p.y;
  }
}

bool plane_used(int k, const ClipPlanes& planes) {
  return k != 1 || planes.far;
}

// Lexicographic order of positions: the canonical direction an edge is cut in.
bool before(const ClipVertex& a, const ClipVertex& b) {
  return std::tie(a.p.x, a.p.y, a.p.z, a.p.w) < std::tie(b.p.x, b.p.y, b.p.z, b.p.w);
}

// The point of edge a-b on plane k, computed from the lexicographically smaller endpoint.
ClipVertex intersect(const ClipVertex& a0, const ClipVertex& b0, int k, float guard) {
  const bool swap = before(b0, a0);
  const ClipVertex& a = swap ? b0 : a0;
  const ClipVertex& b = swap ? a0 : b0;
  const float da = plane_value(a.p, k, guard), db = plane_value(b.p, k, guard);
  const float t = da / (da - db);
  auto lerp = [t](float x, float y) { return x + (y - x) * t; };
  ClipVertex r;
  r.p = {lerp(a.p.x, b.p.x), lerp(a.p.y, b.p.y), lerp(a.p.z, b.p.z), lerp(a.p.w, b.p.w)};
  for (int i = 0; i < 3; ++i) r.b[i] = lerp(a.b[i], b.b[i]);
  r.depth = lerp(a.depth, b.depth);
  return r;
}

}  // namespace

int clip_triangle(const ClipVertex in[3], const ClipPlanes& planes, ClipVertex out[kMaxClipVertices]) {
  ClipVertex buf[2][kMaxClipVertices + 1];
  int n = 3;
  for (int i = 0; i < 3; ++i) buf[0][i] = in[i];
  int cur = 0;
  for (int k = 0; k < kPlanes && n > 0; ++k) {
    if (!plane_used(k, planes)) continue;
    const ClipVertex* src = buf[cur];
    ClipVertex* dst = buf[cur ^ 1];
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const ClipVertex& a = src[i];
      const ClipVertex& b = src[(i + 1) % n];
      const bool a_in = plane_value(a.p, k, planes.guard) >= 0, b_in = plane_value(b.p, k, planes.guard) >= 0;
      if (a_in) dst[m++] = a;
      if (a_in != b_in && m < kMaxClipVertices) dst[m++] = intersect(a, b, k, planes.guard);
    }
    n = m;
    cur ^= 1;
  }
  for (int i = 0; i < n; ++i) out[i] = buf[cur][i];
  return n < 3 ? 0 : n;
}

}  // namespace penumbra
