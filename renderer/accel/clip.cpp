// Clipping a primitive to a box (Sutherland & Hodgman, "Reentrant polygon clipping", CACM 1974).
#include "renderer/accel/clip.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

Bounds3f clip_primitive_bounds(const PrimitiveRecord& t, const Bounds3f& box) {
  if (is_shape(t)) {
    const Bounds3f o{max(t.a, box.lo), min(t.b, box.hi)};
    return o.empty() ? Bounds3f{} : o;
  }
  struct P {
    double v[3];
  };
  P poly[16], tmp[16];
  int n = 3;
  for (int k = 0; k < 3; ++k) {
    poly[0].v[k] = t.a[k];
    poly[1].v[k] = t.b[k];
    poly[2].v[k] = t.c[k];
  }
  for (int k = 0; k < 3 && n > 0; ++k) {
    for (int side = 0; side < 2 && n > 0; ++side) {
      // Keep points with s * (x - plane) >= 0: s = +1 for the lower face, -1 for the upper.
      const double plane = side == 0 ? box.lo[k] : box.hi[k];
      const double s = side == 0 ? 1.0 : -1.0;
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const P& a = poly[i];
        const P& b = poly[(i + 1) % n];
        const double da = s * (a.v[k] - plane), db = s * (b.v[k] - plane);
        if (da >= 0) tmp[m++] = a;
        if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
          const double f = da / (da - db);
          P c;
          for (int j = 0; j < 3; ++j) c.v[j] = a.v[j] + f * (b.v[j] - a.v[j]);
          c.v[k] = plane;
          tmp[m++] = c;
        }
      }
      n = m;
      std::copy(tmp, tmp + m, poly);
    }
  }
  Bounds3f out;
  if (n == 0) return out;
  double lo[3] = {poly[0].v[0], poly[0].v[1], poly[0].v[2]}, hi[3] = {lo[0], lo[1], lo[2]};
  for (int i = 1; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], poly[i].v[k]);
      hi[k] = std::max(hi[k], poly[i].v[k]);
    }
  for (int k = 0; k < 3; ++k) {
    float l = float(lo[k]), h = float(hi[k]);
    if (double(l) > lo[k]) l = std::nextafter(l, -kInfinity);
    if (double(h) < hi[k]) h = std::nextafter(h, kInfinity);
    out.lo[k] = std::max(l, box.lo[k]);
    out.hi[k] = std::min(h, box.hi[k]);
    if (out.lo[k] > out.hi[k]) return Bounds3f{};
  }
  return out;
}

}  // namespace penumbra
