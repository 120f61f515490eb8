// The watertight ray-triangle test shared by Penumbra's own acceleration structures, so that a
// disagreement between two structures is structural, never numerical.
// Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013.
#pragma once

#include <algorithm>
#include <cmath>

#include "renderer/geometry.h"

namespace penumbra {

/// Per-ray precomputation of the shear transform (axis permutation kx, ky, kz and shear).
struct WatertightRay {
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;
  float tnear = 0;     ///< max(ray.tnear, 0): every back end treats t < 0 as behind the origin
  bool valid = false;  ///< false for NaN/Inf/zero directions or tnear > tfar: such rays miss
};

inline WatertightRay prepare_watertight(const Ray& ray) {
  WatertightRay w;
  const Vec3f d = ray.dir;
  if (!is_finite(d) || !is_finite(ray.org) || std::isnan(ray.tnear) || std::isnan(ray.tfar))
    return w;
  w.tnear = std::max(ray.tnear, 0.0f);
  if (w.tnear > ray.tfar) return w;
  const Vec3f ad = abs(d);
  w.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  if (d[w.kz] == 0) return w;
  w.kx = (w.kz + 1) % 3;
  w.ky = (w.kx + 1) % 3;
  if (d[w.kz] < 0) std::swap(w.kx, w.ky);  // preserve winding
  w.sx = d[w.kx] / d[w.kz];
  w.sy = d[w.ky] / d[w.kz];
  w.sz = 1.0f / d[w.kz];
  w.valid = true;
  return w;
}

/// Tests triangle (a, b, c) against the ray; on a hit with t in [tnear, tfar] writes t, u, v
/// (p = (1-u-v) a + u b + v c) and returns true. Degenerate triangles never hit.
inline bool intersect_triangle_watertight(const Ray& ray, const WatertightRay& w, Vec3f a,
                                          Vec3f b, Vec3f c, float tfar, float& t_out,
                                          float& u_out, float& v_out) {
  // Translate to the ray origin, then shear so the ray is the +z axis.
  const Vec3f A = a - ray.org, B = b - ray.org, C = c - ray.org;
  const float Ax = A[w.kx] - w.sx * A[w.kz], Ay = A[w.ky] - w.sy * A[w.kz];
  const float Bx = B[w.kx] - w.sx * B[w.kz], By = B[w.ky] - w.sy * B[w.kz];
  const float Cx = C[w.kx] - w.sx * C[w.kz], Cy = C[w.ky] - w.sy * C[w.kz];
  // Scaled barycentrics (edge functions).
  float U = Cx * By - Cy * Bx;
  float V = Ax * Cy - Ay * Cx;
  float W = Bx * Ay - By * Ax;
  if (U == 0.0f || V == 0.0f || W == 0.0f) {  // fall back to double on edges
    U = float(double(Cx) * By - double(Cy) * Bx);
    V = float(double(Ax) * Cy - double(Ay) * Cx);
    W = float(double(Bx) * Ay - double(By) * Ax);
  }
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;
  // Scaled hit distance and range test without division.
  const float Az = w.sz * A[w.kz], Bz = w.sz * B[w.kz], Cz = w.sz * C[w.kz];
  const float T = U * Az + V * Bz + W * Cz;
  const float inv = 1.0f / det;
  const float t = T * inv;
  if (!(t >= w.tnear && t <= tfar)) return false;
  t_out = t;
  u_out = V * inv;  // weight of b
  v_out = W * inv;  // weight of c
  return true;
}

}  // namespace penumbra
