// Analytic ray intersections and the robust ray-origin offset.
#include "renderer/core/geometry.h"

#include <bit>
#include <cstring>

namespace penumbra {

bool intersect_sphere(const Ray& ray, Vec3f center, float radius, float& t_out) {
  const Vec3f oc = ray.org - center;
  const double a = dot(ray.dir, ray.dir);
  const double b = 2.0 * dot(ray.dir, oc);
  const double c = double(dot(oc, oc)) - double(radius) * radius;
  const double disc = b * b - 4 * a * c;
  if (!(disc >= 0) || !(a > 0)) return false;
  // Numerically stable roots (avoid cancellation in -b +- sqrt(disc)).
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  double t0 = q / a;
  double t1 = q != 0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 >= ray.tnear && t0 <= ray.tfar) {
    t_out = float(t0);
    return true;
  }
  if (t1 >= ray.tnear && t1 <= ray.tfar) {
    t_out = float(t1);
    return true;
  }
  return false;
}

bool intersect_triangle_cramer(const Ray& ray, Vec3f a, Vec3f b, Vec3f c, float& t, float& u, float& v) {
  // Columns of the system [b-a, c-a, -d] (u, v, t)^T = e - a.
  const Vec3f e1 = b - a, e2 = c - a, rhs = ray.org - a, nd = -ray.dir;
  const float det = dot(e1, cross(e2, nd));
  if (det == 0 || !std::isfinite(det)) return false;
  const float inv = 1.0f / det;
  const float uu = dot(rhs, cross(e2, nd)) * inv;
  const float vv = dot(e1, cross(rhs, nd)) * inv;
  const float tt = dot(e1, cross(e2, rhs)) * inv;
  if (!(uu >= 0 && vv >= 0 && uu + vv <= 1)) return false;
  if (!(tt >= ray.tnear && tt <= ray.tfar)) return false;
  t = tt;
  u = uu;
  v = vv;
  return true;
}

Vec3f offset_ray_origin(Vec3f p, Vec3f ng, Vec3f dir) {
  constexpr float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
  if (dot(ng, dir) < 0) ng = -ng;
  Vec3f out;
  for (int i = 0; i < 3; ++i) {
    const int of_i = int(kIntScale * ng[i]);
    int32_t bits = std::bit_cast<int32_t>(p[i]);
    bits += (p[i] < 0) ? -of_i : of_i;
    const float p_i = std::bit_cast<float>(bits);
    out[i] = std::fabs(p[i]) < kOrigin ? p[i] + kFloatScale * ng[i] : p_i;
  }
  return out;
}

}  // namespace penumbra
