// glTF metallic-roughness BRDF: evaluation, VNDF sampling and pdf.
#include "renderer/materials/bsdf.h"

#include <algorithm>
#include <cmath>

namespace penumbra {
namespace {

struct Local {
  Vec3f t, b, n;
  Vec3f to_local(Vec3f v) const { return {dot(v, t), dot(v, b), dot(v, n)}; }
  Vec3f to_world(Vec3f v) const { return t * v.x + b * v.y + n * v.z; }
};

Local frame_of(const GltfBrdf& b) {
  Local f;
  f.n = b.n;
  make_frame(b.n, f.t, f.b);
  return f;
}

float alpha_of(const GltfBrdf& b) {
  return std::max(kMinGgxAlpha, b.roughness * b.roughness);
}

Vec3f schlick(Vec3f f0, float cos_theta) {
  const float m = std::clamp(1 - cos_theta, 0.0f, 1.0f), m2 = m * m;
  const float k = m2 * m2 * m;  // (1 - cos)^5
  return f0 + (Vec3f{1, 1, 1} - f0) * k;
}

Vec3f mix(Vec3f a, Vec3f b, float t) {
  return a * (1 - t) + b * t;
}

/// Density of the specular lobe's wi (local): D_v(h) / (4 v.h) = G1(v) D(h) / (4 n.v).
float specular_pdf(Vec3f v, Vec3f h, float alpha) {
  if (!(v.z > 0)) return 0;
  return smith_g1(v, alpha) * ggx_d(h, alpha) / (4 * v.z);
}

}  // namespace

void make_frame(Vec3f n, Vec3f& t, Vec3f& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = {1 + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

Vec3f sample_cosine_hemisphere(Vec2f u) {
  const float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1 - u.x))};
}

float ggx_d(Vec3f h, float alpha) {
  if (!(h.z > 0)) return 0;
  const float a2 = alpha * alpha;
  const float d = h.z * h.z * (a2 - 1) + 1;
  return a2 / (kPi * d * d);
}

float smith_g1(Vec3f v, float alpha) {
  if (!(v.z > 0)) return 0;
  const float a2 = alpha * alpha;
  // G1 = 2 n.v / (n.v + sqrt(a^2 + (1 - a^2) (n.v)^2))
  return 2 * v.z / (v.z + std::sqrt(a2 + (1 - a2) * v.z * v.z));
}

float smith_visibility(float n_dot_l, float n_dot_v, float alpha) {
  const float a2 = alpha * alpha;
  const float gv = n_dot_l * std::sqrt(n_dot_v * n_dot_v * (1 - a2) + a2);
  const float gl = n_dot_v * std::sqrt(n_dot_l * n_dot_l * (1 - a2) + a2);
  const float s = gv + gl;
  return s > 0 ? 0.5f / s : 0.0f;
}

Vec3f sample_ggx_vndf(Vec3f v, float alpha, Vec2f u) {
  // Heitz 2018, listing 1: stretch the view, sample the projected hemisphere, unstretch.
  const Vec3f vh = normalize(Vec3f{alpha * v.x, alpha * v.y, v.z});
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const Vec3f t1 = len2 > 0 ? Vec3f{-vh.y, vh.x, 0} / std::sqrt(len2) : Vec3f{1, 0, 0};
  const Vec3f t2 = cross(vh, t1);
  const float r = std::sqrt(u.x), phi = 2 * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1 + vh.z);
  p2 = (1 - s) * std::sqrt(std::max(0.0f, 1 - p1 * p1)) + s * p2;
  const Vec3f nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0f, 1 - p1 * p1 - p2 * p2));
  return normalize(Vec3f{alpha * nh.x, alpha * nh.y, std::max(1e-6f, nh.z)});
}

float dielectric_fresnel(const GltfBrdf& b, float cos_theta) {
  return b.specular * schlick(Vec3f{b.f0, b.f0, b.f0}, cos_theta).x;
}

float specular_probability(const GltfBrdf& b) {
  const float sf0 = b.specular * b.f0;
  const float spec = luminance(mix(Vec3f{sf0, sf0, sf0}, b.base_color, b.metallic));
  const float diff = (1 - b.metallic) * (1 - b.transmission) * (1 - sf0) * luminance(b.base_color);
  if (!(diff > 0)) return 1;
  if (!(spec > 0)) return 0;
  return std::clamp(spec / (spec + diff), 0.1f, 0.9f);  // never starve either lobe
}

namespace {
// Everything about one direction pair in one shading frame: the diffuse and specular terms and
// (if pdf is not null) the sampling density, so estimators that need f and pdf together
// (next-event estimation with MIS) build the frame and the half vector once.
void eval_pair(const GltfBrdf& b, Vec3f wo, Vec3f wi, Vec3f& diffuse, Vec3f& specular, float* pdf) {
  diffuse = specular = {0, 0, 0};
  if (pdf) *pdf = 0;
  const Local f = frame_of(b);
  const Vec3f v = f.to_local(wo), l = f.to_local(wi);
  if (!(v.z > 0) || !(l.z > 0)) return;
  const Vec3f h = normalize(v + l);
  const float alpha = alpha_of(b);
  const float v_dot_h = std::max(0.0f, dot(v, h));
  const float dv = ggx_d(h, alpha) * smith_visibility(l.z, v.z, alpha);
  const float fd = dielectric_fresnel(b, v_dot_h);
  const Vec3f f_dielectric{fd, fd, fd};
  const Vec3f f_metal = schlick(b.base_color, v_dot_h);
  diffuse = b.base_color * ((1 - fd) * (1 - b.metallic) * (1 - b.transmission) / kPi);
  specular = mix(f_dielectric, f_metal, b.metallic) * dv;
  if (pdf) {
    const float ps = specular_probability(b);
    *pdf = ps * specular_pdf(v, h, alpha) + (1 - ps) * l.z / kPi;
  }
}
}  // namespace

void brdf_eval_parts(const GltfBrdf& b, Vec3f wo, Vec3f wi, Vec3f& diffuse, Vec3f& specular) {
  eval_pair(b, wo, wi, diffuse, specular, nullptr);
}

Vec3f brdf_eval(const GltfBrdf& b, Vec3f wo, Vec3f wi) {
  Vec3f diffuse, specular;
  eval_pair(b, wo, wi, diffuse, specular, nullptr);
  return diffuse + specular;
}

Vec3f brdf_eval_pdf(const GltfBrdf& b, Vec3f wo, Vec3f wi, float& pdf) {
  Vec3f diffuse, specular;
  eval_pair(b, wo, wi, diffuse, specular, &pdf);
  return diffuse + specular;
}

float brdf_pdf(const GltfBrdf& b, Vec3f wo, Vec3f wi) {
  Vec3f diffuse, specular;
  float pdf = 0;
  eval_pair(b, wo, wi, diffuse, specular, &pdf);
  return pdf;
}

bool brdf_sample(const GltfBrdf& b, Vec3f wo, float u1, Vec2f u, BrdfSample& out) {
  out = BrdfSample{};
  const Local f = frame_of(b);
  const Vec3f v = f.to_local(wo);
  if (!(v.z > 0)) return false;
  Vec3f l;
  if (u1 < specular_probability(b)) {
    const Vec3f h = sample_ggx_vndf(v, alpha_of(b), u);
    l = reflect(-v, h);
  } else {
    l = sample_cosine_hemisphere(u);
  }
  if (!(l.z > 0)) return false;
  out.wi = normalize(f.to_world(l));
  const Vec3f value = brdf_eval_pdf(b, wo, out.wi, out.pdf);
  if (!(out.pdf > 0) || !std::isfinite(out.pdf)) return false;
  out.weight = value * (std::max(0.0f, dot(out.wi, b.n)) / out.pdf);
  return true;
}

}  // namespace penumbra
