// The watertight ray-triangle test shared by Penumbra's own acceleration structures, so that a
// disagreement between two structures is structural, never numerical.
// Woop, Benthin & Wald, "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013.
#pragma once

// The hit/miss decision is Woop's, in float (watertight). Once a ray is known to pass through
// the triangle, t, u and v are recomputed with the same formulas in double: in float they lose
// up to 1e-3 relative on long thin triangles far from the hit (the edge functions cancel), as
// in the benchmark's "slivers" scene checked against Embree and a double-precision reference.

#include <algorithm>
#include <cmath>
#include <cstring>

#include "renderer/core/geometry.h"

namespace penumbra {

/// Per-ray precomputation of the shear transform (axis permutation kx, ky, kz and shear).
struct WatertightRay {
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;
  double dsx = 0, dsy = 0, dsz = 1;  ///< the shear in double, for the hit's t, u, v
  float tnear = 0;                   ///< max(ray.tnear, 0): every back end treats t < 0 as behind the origin
  bool valid = false;                ///< false for NaN/Inf/zero directions or tnear > tfar: such rays miss
};

[[gnu::always_inline]] inline WatertightRay prepare_watertight(const Ray& ray) {
  WatertightRay w;
  const Vec3f d = ray.dir;
  if (!is_finite(d) || !is_finite(ray.org) || std::isnan(ray.tnear) || std::isnan(ray.tfar)) return w;
  w.tnear = std::max(ray.tnear, 0.0f);
  if (w.tnear > ray.tfar) return w;
  const Vec3f ad = abs(d);
  w.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  float dv[3];
  std::memcpy(dv, &d, sizeof dv);
  const float dz = dv[w.kz];
  if (dz == 0) return w;
  w.kx = w.kz == 2 ? 0 : w.kz + 1;
  w.ky = w.kx == 2 ? 0 : w.kx + 1;
  if (dz < 0) std::swap(w.kx, w.ky);  // preserve winding
  w.sx = dv[w.kx] / dz;
  w.sy = dv[w.ky] / dz;
  w.sz = 1.0f / dz;
  w.dsz = 1.0 / dz;
  w.dsx = dv[w.kx] * w.dsz;
  w.dsy = dv[w.ky] * w.dsz;
  w.valid = true;
  return w;
}

/// Component i of v as an indexed load (Vec3f::operator[] is a chain of selects, slow with a
/// per-ray permutation index in the innermost loop).
inline float component(const Vec3f& v, int i) {
  float f[3];
  std::memcpy(f, &v, sizeof f);
  return f[i];
}

/// Tests triangle (a, b, c) against the ray; on a hit with t in [tnear, tfar] writes t, u, v
/// (p = (1-u-v) a + u b + v c) and returns true. Degenerate triangles never hit.
inline bool intersect_triangle_watertight(const Ray& ray, const WatertightRay& w, Vec3f a, Vec3f b, Vec3f c,
                                          float tfar, float& t_out, float& u_out, float& v_out) {
  // Translate to the ray origin, then shear so the ray is the +z axis.
  const Vec3f A = a - ray.org, B = b - ray.org, C = c - ray.org;
  const float Az0 = component(A, w.kz), Bz0 = component(B, w.kz), Cz0 = component(C, w.kz);
  const float Ax = component(A, w.kx) - w.sx * Az0, Ay = component(A, w.ky) - w.sy * Az0;
  const float Bx = component(B, w.kx) - w.sx * Bz0, By = component(B, w.ky) - w.sy * Bz0;
  const float Cx = component(C, w.kx) - w.sx * Cz0, Cy = component(C, w.ky) - w.sy * Cz0;
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
  const float fdet = U + V + W;
  if (fdet == 0.0f) return false;
  // Early out in float when the triangle is certainly behind tnear or beyond tfar, so only
  // near-range cases pay for the double computation below. Error bound: the sheared coordinates
  // carry an absolute error of ~2 eps M (M the largest translated coordinate, |sx|, |sy| <= 1),
  // so U, V, W of ~4 eps M S (S the largest sheared coordinate) and T of ~12 eps M S Z (Z the
  // largest |Az|, |Bz|, |Cz|); 1e-4 M S Z is about 70x that.
  {
    const float Az = w.sz * Az0, Bz = w.sz * Bz0, Cz = w.sz * Cz0;
    const float T = U * Az + V * Bz + W * Cz;
    const float M = std::max({max_component(abs(A)), max_component(abs(B)), max_component(abs(C))});
    const float S =
        std::max({std::fabs(Ax), std::fabs(Ay), std::fabs(Bx), std::fabs(By), std::fabs(Cx), std::fabs(Cy)});
    const float Z = std::max({std::fabs(Az), std::fabs(Bz), std::fabs(Cz)});
    const float err = 1e-4f * M * S * Z;
    const float lo = (T - err) / fdet, hi = (T + err) / fdet;  // fdet may be negative: order them
    if (std::max(lo, hi) < w.tnear || std::min(lo, hi) > tfar) return false;  // NaN: no early out
  }
  // The ray passes through the triangle: its distance and barycentrics in double.
  // Vertex minus origin in double: exact unless their magnitudes differ by more than 2^29.
  const auto rel = [&](Vec3f p, int k) { return double(component(p, k)) - double(component(ray.org, k)); };
  const double ax = rel(a, w.kx), ay = rel(a, w.ky), az = rel(a, w.kz);
  const double bx = rel(b, w.kx), by = rel(b, w.ky), bz = rel(b, w.kz);
  const double cx = rel(c, w.kx), cy = rel(c, w.ky), cz = rel(c, w.kz);
  const double dAx = ax - w.dsx * az, dAy = ay - w.dsy * az;
  const double dBx = bx - w.dsx * bz, dBy = by - w.dsy * bz;
  const double dCx = cx - w.dsx * cz, dCy = cy - w.dsy * cz;
  double dU = dCx * dBy - dCy * dBx, dV = dAx * dCy - dAy * dCx, dW = dBx * dAy - dBy * dAx;
  // Keep the float decision: a weight whose sign flipped in double is on the edge, so 0.
  if (U >= 0 && V >= 0 && W >= 0) {
    dU = std::max(dU, 0.0), dV = std::max(dV, 0.0), dW = std::max(dW, 0.0);
  } else {
    dU = std::min(dU, 0.0), dV = std::min(dV, 0.0), dW = std::min(dW, 0.0);
  }
  const double det = dU + dV + dW;
  if (det == 0.0) return false;
  const double T = w.dsz * (dU * az + dV * bz + dW * cz);
  const double t = T / det;
  if (!(t >= w.tnear && t <= tfar)) return false;
  t_out = float(t);
  if (!(t_out >= w.tnear && t_out <= tfar)) return false;  // rounding to float at the ends
  u_out = float(dV / det);                                 // weight of b
  v_out = float(dW / det);                                 // weight of c
  return true;
}

}  // namespace penumbra
