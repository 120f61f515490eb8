// Ray, the Hit record, and analytic intersection routines (ray-sphere, ray-triangle by Cramer's
// rule). These are reference kernels for shading and tests; the accelerators use the
// watertight test in accel/triangle.h.
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// A ray p(t) = org + t dir, valid for t in [tnear, tfar]. dir need not be unit length.
struct Ray {
  Vec3f org;
  float tnear = 0;
  Vec3f dir;
  float tfar = kInfinity;
  float time = 0.5f;  ///< when within the shutter, 0 (open) to 1 (close); moving geometry is
                      ///< where it is then. Rays spawned from a hit keep their parent's time.
};

/// Closest-hit record shared by every accelerator. On a miss geom_id == kInvalidId and the
/// other fields are unspecified.
struct Hit {
  static constexpr uint32_t kInvalidId = 0xffffffffu;
  float t = kInfinity;
  float u = 0, v = 0;  ///< barycentrics: p = (1-u-v) a + u b + v c
  uint32_t geom_id = kInvalidId;
  uint32_t prim_id = kInvalidId;
  bool valid() const { return geom_id != kInvalidId; }
};

/// Ray-sphere: solves a t^2 + b t + c = 0 and returns the nearest root in [tnear, tfar]
/// through t_out. Returns false on a miss (discriminant < 0 or both roots outside the range).
bool intersect_sphere(const Ray& ray, Vec3f center, float radius, float& t_out);

/// Ray-triangle by Cramer's rule on e + t d = a + u (b - a) + v (c - a).
/// Hit iff t in [tnear, tfar], u >= 0, v >= 0, u + v <= 1. Not watertight: reference only.
bool intersect_triangle_cramer(const Ray& ray, Vec3f a, Vec3f b, Vec3f c, float& t, float& u, float& v);

/// Unit geometric normal (b - a) x (c - a) / |(b - a) x (c - a)|; zero for degenerate triangles.
inline Vec3f triangle_normal(Vec3f a, Vec3f b, Vec3f c) {
  return normalize(cross(b - a, c - a));
}

/// Offsets a surface point along its geometric normal so a ray leaving it in direction `dir`
/// does not re-hit the same surface, scaled to the float precision of p.
/// After Waechter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection",
/// Ray Tracing Gems (2019), ch. 6.
Vec3f offset_ray_origin(Vec3f p, Vec3f ng, Vec3f dir);

}  // namespace penumbra
