// The glTF BSDF: every lobe's value and density for a direction pair, lobe selection and
// sampling.
#include "renderer/materials/bsdf.h"

#include <algorithm>
#include <cmath>

#include "renderer/materials/ggx_albedo.h"
#include "renderer/materials/sheen.h"
#include "renderer/materials/thin_film.h"

namespace penumbra {
namespace {

constexpr float kCoatF0 = 0.04f;  // clear coat of index 1.5

struct Local {
  Vec3f t, b, n;
  Vec3f to_local(Vec3f v) const { return {dot(v, t), dot(v, b), dot(v, n)}; }
  Vec3f to_world(Vec3f v) const { return t * v.x + b * v.y + n * v.z; }
};

Local base_frame(const GltfBsdf& b) {
  Local f;
  f.n = b.n;
  if (b.anisotropy > 0) {
    f.t = b.t;
    f.b = cross(b.n, b.t);
  } else {
    make_frame(b.n, f.t, f.b);
  }
  return f;
}

Vec3f coat_normal(const GltfBsdf& b) {
  return b.clearcoat_n.x == 0 && b.clearcoat_n.y == 0 && b.clearcoat_n.z == 0 ? b.n : b.clearcoat_n;
}

GgxAlpha base_alpha(const GltfBsdf& b) {
  const float a = std::max(kMinGgxAlpha, b.roughness * b.roughness);
  const float s = std::clamp(b.anisotropy, 0.0f, 1.0f);
  return {a + (1 - a) * s * s, a};
}

float coat_alpha(const GltfBsdf& b) {
  return std::max(kMinGgxAlpha, b.clearcoat_roughness * b.clearcoat_roughness);
}

Vec3f mix(Vec3f a, Vec3f b, float t) {
  return a * (1 - t) + b * t;
}

// The isotropic GGX values that depend on cosines only, as a local vector.
Vec3f polar(float cos_theta) {
  const float c = std::clamp(cos_theta, -1.0f, 1.0f);
  return {std::sqrt(std::max(0.0f, 1 - c * c)), 0, c};
}

// The dielectric Fresnel of the base at cos, RGB once iridescence mixes in its thin film.
Vec3f dielectric_fresnel_rgb(const GltfBsdf& b, float cos_theta) {
  const float f = dielectric_fresnel(b, cos_theta);
  if (f >= b.specular) return {f, f, f};  // total internal reflection stays total
  // KHR_materials_specular's colour: f0 per channel min(f0 c, 1) under the same f90 = s.
  Vec3f fc{f, f, f};
  const Vec3f c = b.specular_color;
  if (c.x != 1 || c.y != 1 || c.z != 1)
    for (int k = 0; k < 3; ++k)
      fc[k] = b.volume ? std::min(f * c[k], b.specular)
                       : b.specular * schlick(std::min(b.f0 * c[k], 1.0f), cos_theta);
  if (!(b.iridescence > 0)) return fc;
  const Vec3f f0 = Vec3f{std::min(b.f0 * c.x, 1.0f), std::min(b.f0 * c.y, 1.0f), std::min(b.f0 * c.z, 1.0f)};
  const Vec3f film =
      iridescence_fresnel(1, b.iridescence_ior, cos_theta, b.iridescence_thickness, f0) * b.specular;
  return mix(fc, film, b.iridescence);
}

Vec3f metal_fresnel(const GltfBsdf& b, float cos_theta) {
  const Vec3f f = schlick(b.base_color, cos_theta);
  if (!(b.iridescence > 0)) return f;
  return mix(f, iridescence_fresnel(1, b.iridescence_ior, cos_theta, b.iridescence_thickness, b.base_color),
             b.iridescence);
}

float coat_attenuation(const GltfBsdf& b, float cos_theta) {
  return 1 - b.clearcoat * schlick(kCoatF0, std::fabs(cos_theta));
}

// The coat's attenuation of light passing it twice at the same angle (in and out).
float sq_attenuation(const GltfBsdf& b, float cos_theta) {
  const float a = coat_attenuation(b, cos_theta);
  return a * a;
}

// Probabilities of choosing each lobe at wo, summing to 1 (every present lobe >= 5%).
enum Lobe { kCoat, kSheen, kSpecular, kDiffuse, kDiffuseTransmission, kRefraction, kLobes };
struct LobeChoice {
  float p[kLobes] = {};
};

LobeChoice choose(const GltfBsdf& b, float cos_v, float cos_coat) {
  LobeChoice c;
  const float coat = b.clearcoat > 0 ? b.clearcoat * schlick(kCoatF0, std::max(0.0f, cos_coat)) : 0.0f;
  const float rest = 1 - coat;
  const float sheen_max = max_component(b.sheen_color);
  const float sheen = sheen_max > 0 ? sheen_max * sheen_albedo(cos_v, b.sheen_roughness) : 0.0f;
  const float below = rest * (1 - sheen);
  const float fd = max_component(dielectric_fresnel_rgb(b, cos_v));
  const float dielectric = (1 - b.metallic) * (1 - fd);
  c.p[kCoat] = coat;
  c.p[kSheen] = rest * sheen;
  c.p[kSpecular] = below * ((1 - b.metallic) * fd + b.metallic * luminance(b.base_color));
  c.p[kDiffuse] =
      below * dielectric * (1 - b.transmission) * (1 - b.diffuse_transmission) * luminance(b.base_color);
  c.p[kDiffuseTransmission] = below * dielectric * (1 - b.transmission) * b.diffuse_transmission *
                              luminance(b.diffuse_transmission_color);
  c.p[kRefraction] = b.volume ? below * dielectric * b.transmission * luminance(b.base_color) : 0.0f;
  float sum = 0;
  for (float& p : c.p) sum += p = std::max(p, 0.0f);
  if (!(sum > 0)) {  // a black BSDF: sample the specular lobe, whose value is then 0
    c.p[kSpecular] = 1;
    return c;
  }
  float total = 0;
  for (float& p : c.p) total += p = p > 0 ? std::max(p / sum, 0.05f) : 0.0f;
  for (float& p : c.p) p /= total;
  return c;
}

// Every term for one direction pair: diffuse and the rest, and (if pdf is not null) the density.
struct PairEval {
  Vec3f diffuse, other;
  float pdf = 0;
};

// The coat lobe (value and density) at world directions wo, wi. Estimators multiply every value
// by the shading normal's |n.l|; the coat, with its own normal, needs its own n_c.l, so its
// microfacet value D G2 / (4 n_c.v n_c.l) is divided by |n.l| in place of n_c.l (the same when
// the normals agree; without this a coat normal map turns grazing coat samples into fireflies).
void eval_coat(const GltfBsdf& b, Vec3f wo, Vec3f wi, Vec3f nc, Vec3f& value, float& pdf) {
  const float cv = dot(nc, wo), cl = dot(nc, wi), nl = std::fabs(dot(b.n, wi));
  if (!(cv > 0) || !(cl > 0) || !(nl > 1e-6f)) return;
  const Vec3f h = normalize(wo + wi);
  const float a = coat_alpha(b), ch = dot(nc, h);
  const float d = ggx_d(polar(ch), a);
  const float g2 = smith_g2(polar(cv), polar(cl), GgxAlpha{a, a});
  const float f = b.clearcoat * schlick(kCoatF0, std::max(0.0f, dot(wo, h)));
  value = Vec3f{f, f, f} * (d * g2 / (4 * cv * nl));
  pdf = smith_g1(polar(cv), a) * d / (4 * cv);
}

// Kulla and Conty's multiple-scattering lobe of the base's reflection (ggx_albedo.h) at local
// cosines cos_v, cos_l: F_ms mixed between the dielectric's and the metal's by metallic.
Vec3f base_multiscatter(const GltfBsdf& b, GgxAlpha a, float cos_v, float cos_l) {
  const float alpha = std::sqrt(a.x * a.y);
  const float ms = ggx_multiscatter(cos_v, cos_l, alpha);
  if (!(ms > 0)) return {};
  const float e_avg = ggx_average_albedo(alpha);
  Vec3f f_metal, f_dielectric;
  for (int k = 0; k < 3; ++k) {
    f_metal[k] = schlick_average(std::clamp(b.base_color[k], 0.0f, 1.0f));
    const float r = (b.eta - 1) / (b.eta + 1);
    const float f0 = std::min((b.volume ? r * r : b.f0) * b.specular_color[k], 1.0f);
    f_dielectric[k] = b.specular * schlick_average(f0);
  }
  return mix(multiscatter_fresnel(f_dielectric, e_avg), multiscatter_fresnel(f_metal, e_avg), b.metallic) *
         ms;
}

// The share of the specular lobe's samples drawn by cosine for the multiple-scattering lobe at
// view cosine cos_v: its albedo 1 - E(cos_v) for a Fresnel of 1 (0 without compensation). The
// visible normals alone would reach its broad lobe only in their tails.
float multiscatter_share(const GltfBsdf& b, GgxAlpha a, float cos_v) {
  if (!b.energy_compensation) return 0;
  return std::clamp(1 - ggx_albedo(cos_v, std::sqrt(a.x * a.y)), 0.0f, 1.0f);
}

// The base's reflection terms (local v, l above the surface).
void eval_base_reflection(const GltfBsdf& b, Vec3f v, Vec3f l, const LobeChoice& c, PairEval& e) {
  const Vec3f h = normalize(v + l);
  const GgxAlpha a = base_alpha(b);
  const float vh = std::max(0.0f, dot(v, h));
  const float dv = ggx_d(h, a) * smith_g2(v, l, a) / (4 * v.z * l.z);
  const Vec3f fd = dielectric_fresnel_rgb(b, vh);
  e.other = mix(fd, metal_fresnel(b, vh), b.metallic) * dv;
  if (b.energy_compensation) e.other += base_multiscatter(b, a, v.z, l.z);
  e.diffuse = b.base_color * ((1 - max_component(fd)) * (1 - b.metallic) * (1 - b.transmission) *
                              (1 - b.diffuse_transmission) / kPi);
  const float q = multiscatter_share(b, a, v.z);
  e.pdf += c.p[kSpecular] * ((1 - q) * smith_g1(v, a) * ggx_d(h, a) / (4 * v.z) + q * l.z / kPi) +
           c.p[kDiffuse] * l.z / kPi;
}

// The base's transmission terms (local v above, l below the surface).
void eval_base_transmission(const GltfBsdf& b, Vec3f v, Vec3f l, const LobeChoice& c, PairEval& e) {
  const float dielectric = 1 - b.metallic;
  const Vec3f one{1, 1, 1};
  if (b.diffuse_transmission > 0) {
    const Vec3f tv = one - dielectric_fresnel_rgb(b, v.z), tl = one - dielectric_fresnel_rgb(b, -l.z);
    e.diffuse = b.diffuse_transmission_color * tv * tl *
                (dielectric * (1 - b.transmission) * b.diffuse_transmission / kPi);
    e.pdf += c.p[kDiffuseTransmission] * -l.z / kPi;
  }
  if (!b.volume || !(b.transmission > 0) || b.eta == 1) return;
  // Generalised half vector of refraction, on the side of the normal.
  Vec3f h = v + l * b.eta;
  if (!(dot(h, h) > 0)) return;
  h = normalize(h);
  if (h.z < 0) h = -h;
  const float vh = dot(v, h), lh = dot(l, h);
  if (!(vh > 0) || !(lh < 0)) return;  // back-facing microfacet
  const GgxAlpha a = base_alpha(b);
  const float denom = (lh + vh / b.eta) * (lh + vh / b.eta);
  const float d = ggx_d(h, a);
  const Vec3f f = dielectric_fresnel_rgb(b, vh);
  const float ft = d * smith_g2(v, l, a) * std::fabs(lh * vh / (denom * v.z * l.z)) / (b.eta * b.eta);
  e.other = b.base_color * (one - f) * (dielectric * b.transmission * ft);
  e.pdf += c.p[kRefraction] * smith_g1(v, a) * vh * d / v.z * std::fabs(lh) / denom;
}

PairEval eval_pair(const GltfBsdf& b, Vec3f wo, Vec3f wi) {
  PairEval e;
  const Local f = base_frame(b);
  const Vec3f v = f.to_local(wo), l = f.to_local(wi);
  if (!(v.z > 0) || l.z == 0) return e;
  const Vec3f nc = coat_normal(b);
  const LobeChoice c = choose(b, v.z, dot(nc, wo));
  if (l.z > 0)
    eval_base_reflection(b, v, l, c, e);
  else
    eval_base_transmission(b, v, l, c, e);
  // Sheen over the base, with its albedo scaling.
  const float sheen_max = max_component(b.sheen_color);
  if (sheen_max > 0) {
    const float ev = sheen_albedo(v.z, b.sheen_roughness),
                el = sheen_albedo(std::fabs(l.z), b.sheen_roughness);
    const float scale = 1 - sheen_max * std::max(ev, el);
    e.diffuse = e.diffuse * scale;
    e.other = e.other * scale;
    if (l.z > 0) {
      e.other += b.sheen_color * sheen_brdf(v, l, b.sheen_roughness);
      e.pdf += c.p[kSheen] * l.z / kPi;
    }
  }
  // The clear coat over everything.
  if (b.clearcoat > 0) {
    const float att = coat_attenuation(b, dot(nc, wo)) * coat_attenuation(b, dot(nc, wi));
    e.diffuse = e.diffuse * att;
    e.other = e.other * att;
    Vec3f coat;
    float pdf = 0;
    eval_coat(b, wo, wi, nc, coat, pdf);
    e.other += coat;
    e.pdf += c.p[kCoat] * pdf;
  }
  return e;
}

// A direction from lobe `lobe` in world space; false if it fails (total internal reflection,
// below the horizon of a reflection lobe). u_lobe in [0, 1) picks within the specular lobe
// between its visible normals and the multiple-scattering lobe's cosine samples.
bool sample_lobe(const GltfBsdf& b, int lobe, Vec3f wo, Vec2f u, float u_lobe, Vec3f& wi) {
  const Local f = base_frame(b);
  const Vec3f v = f.to_local(wo);
  Vec3f l;
  switch (lobe) {
    case kCoat: {
      Local cf;
      cf.n = coat_normal(b);
      make_frame(cf.n, cf.t, cf.b);
      const Vec3f vc = cf.to_local(wo);
      if (!(vc.z > 0)) return false;
      const Vec3f h = sample_ggx_vndf(vc, coat_alpha(b), u);
      const Vec3f lc = reflect(-vc, h);
      if (!(lc.z > 0)) return false;
      wi = normalize(cf.to_world(lc));
      return true;
    }
    case kSheen:
    case kDiffuse:
      l = sample_cosine_hemisphere(u);
      break;
    case kDiffuseTransmission:
      l = sample_cosine_hemisphere(u);
      l.z = -l.z;
      break;
    case kSpecular:
      if (u_lobe < multiscatter_share(b, base_alpha(b), v.z))
        l = sample_cosine_hemisphere(u);
      else
        l = reflect(-v, sample_ggx_vndf(v, base_alpha(b), u));
      break;
    case kRefraction: {
      const Vec3f h = sample_ggx_vndf(v, base_alpha(b), u);
      if (!refract(v, h, b.eta, l)) return false;
      break;
    }
    default:
      return false;
  }
  if (l.z == 0 || ((lobe == kSpecular || lobe == kSheen || lobe == kDiffuse) && !(l.z > 0))) return false;
  if ((lobe == kDiffuseTransmission || lobe == kRefraction) && !(l.z < 0)) return false;
  wi = normalize(f.to_world(l));
  return true;
}

}  // namespace

Vec3f thin_transmission(const GltfBsdf& b, float cos_theta) {
  const Vec3f through = (Vec3f{1, 1, 1} - dielectric_fresnel_rgb(b, cos_theta)) * b.base_color *
                        ((1 - b.metallic) * b.transmission);
  float layers = 1;
  if (b.clearcoat > 0) layers *= sq_attenuation(b, cos_theta);
  const float sheen_max = max_component(b.sheen_color);
  if (sheen_max > 0) layers *= 1 - sheen_max * sheen_albedo(cos_theta, b.sheen_roughness);
  return through * layers;
}

float dielectric_fresnel(const GltfBsdf& b, float cos_theta) {
  return b.specular * (b.volume ? fresnel_dielectric(cos_theta, b.eta) : schlick(b.f0, cos_theta));
}

void bsdf_eval_parts(const GltfBsdf& b, Vec3f wo, Vec3f wi, Vec3f& diffuse, Vec3f& specular) {
  const PairEval e = eval_pair(b, wo, wi);
  diffuse = e.diffuse;
  specular = e.other;
}

Vec3f bsdf_eval(const GltfBsdf& b, Vec3f wo, Vec3f wi) {
  const PairEval e = eval_pair(b, wo, wi);
  return e.diffuse + e.other;
}

Vec3f bsdf_eval_pdf(const GltfBsdf& b, Vec3f wo, Vec3f wi, float& pdf) {
  const PairEval e = eval_pair(b, wo, wi);
  pdf = e.pdf;
  return e.diffuse + e.other;
}

float bsdf_pdf(const GltfBsdf& b, Vec3f wo, Vec3f wi) {
  return eval_pair(b, wo, wi).pdf;
}

bool bsdf_sample(const GltfBsdf& b, Vec3f wo, float u1, Vec2f u, BsdfSample& out) {
  out = BsdfSample{};
  const float cos_v = dot(b.n, wo);
  if (!(cos_v > 0)) return false;
  const LobeChoice c = choose(b, cos_v, dot(coat_normal(b), wo));
  int lobe = kLobes - 1;
  float acc = 0, u_lobe = 0.5f;
  for (int k = 0; k < kLobes; ++k) {
    acc += c.p[k];
    if (u1 < acc && c.p[k] > 0) {
      lobe = k;
      u_lobe =
          std::clamp((u1 - (acc - c.p[k])) / c.p[k], 0.0f, 0x1.fffffep-1f);  // u1 within the lobe's share
      break;
    }
  }
  while (lobe > 0 && !(c.p[lobe] > 0)) --lobe;  // rounding left u1 past the last lobe
  if (!sample_lobe(b, lobe, wo, u, u_lobe, out.wi)) return false;
  out.transmitted = lobe == kDiffuseTransmission || lobe == kRefraction;
  const Vec3f value = bsdf_eval_pdf(b, wo, out.wi, out.pdf);
  if (!(out.pdf > 0) || !std::isfinite(out.pdf)) return false;
  out.weight = value * (std::fabs(dot(out.wi, b.n)) / out.pdf);
  return is_finite(out.weight);
}

}  // namespace penumbra
