// Anisotropic GGX, Smith masking, visible-normal sampling, Fresnel and refraction.
#include "renderer/materials/microfacet.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

float ggx_d(Vec3f h, GgxAlpha a) {
  if (!(h.z > 0)) return 0;
  const float x = h.x / a.x, y = h.y / a.y;
  const float d = x * x + y * y + h.z * h.z;
  return 1 / (kPi * a.x * a.y * d * d);
}

float smith_lambda(Vec3f v, GgxAlpha a) {
  const float z2 = v.z * v.z;
  if (!(z2 > 0)) return kInfinity;
  const float t2 = (a.x * a.x * v.x * v.x + a.y * a.y * v.y * v.y) / z2;
  return 0.5f * (std::sqrt(1 + t2) - 1);
}

float smith_g1(Vec3f v, GgxAlpha a) {
  if (!(v.z > 0)) return 0;
  return 1 / (1 + smith_lambda(v, a));
}

float smith_g2(Vec3f v, Vec3f l, GgxAlpha a) {
  const float lv = smith_lambda(v, a), ll = smith_lambda(l, a);
  if (!std::isfinite(lv) || !std::isfinite(ll)) return 0;
  return 1 / (1 + lv + ll);
}

float smith_visibility(float n_dot_l, float n_dot_v, float alpha) {
  const float a2 = alpha * alpha;
  const float gv = n_dot_l * std::sqrt(n_dot_v * n_dot_v * (1 - a2) + a2);
  const float gl = n_dot_v * std::sqrt(n_dot_l * n_dot_l * (1 - a2) + a2);
  const float s = gv + gl;
  return s > 0 ? 0.5f / s : 0.0f;
}

Vec3f sample_ggx_vndf(Vec3f v, GgxAlpha a, Vec2f u) {
  // Heitz 2018, listing 1: stretch the view, sample the projected hemisphere, unstretch.
  const Vec3f vh = normalize(Vec3f{a.x * v.x, a.y * v.y, v.z});
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const Vec3f t1 = len2 > 0 ? Vec3f{-vh.y, vh.x, 0} / std::sqrt(len2) : Vec3f{1, 0, 0};
  const Vec3f t2 = cross(vh, t1);
  const float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1 + vh.z);
  p2 = (1 - s) * std::sqrt(std::max(0.0f, 1 - p1 * p1)) + s * p2;
  const Vec3f nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0f, 1 - p1 * p1 - p2 * p2));
  return normalize(Vec3f{a.x * nh.x, a.y * nh.y, std::max(1e-6f, nh.z)});
}

Vec3f schlick(Vec3f f0, float cos_theta) {
  const float m = std::clamp(1 - cos_theta, 0.0f, 1.0f), m2 = m * m;
  const float k = m2 * m2 * m;  // (1 - cos)^5
  return f0 + (Vec3f{1, 1, 1} - f0) * k;
}

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  const float sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1;  // total internal reflection
  const float cos_t = std::sqrt(1 - sin2_t);
  const float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  const float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

bool refract(Vec3f v, Vec3f m, float eta, Vec3f& out) {
  const float cos_i = dot(v, m);
  const float sin2_t = std::max(0.0f, 1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return false;
  const float cos_t = std::sqrt(1 - sin2_t);
  out = normalize(-v / eta + m * (cos_i / eta - cos_t));
  return true;
}

void make_frame(Vec3f n, Vec3f& t, Vec3f& b) {
  orthonormal_basis(n, t, b);
}

Vec3f sample_cosine_hemisphere(Vec2f u) {
  const float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1 - u.x))};
}

}  // namespace penumbra
