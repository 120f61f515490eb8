// The GGX directional-albedo table and the Kulla-Conty compensation lobe.
#include "renderer/materials/ggx_albedo.h"

#include <algorithm>
#include <cmath>

#include "renderer/materials/microfacet.h"

namespace penumbra {
namespace {

constexpr int kN = 32;          // table entries along mu and along alpha
constexpr int kSamples = 1024;  // visible-normal samples per entry

// Node i of the table lies at mu = i / (kN - 1); its value is sampled at node_mu(i) (at mu = 0,
// where the view grazes the surface, E is its limit, sampled at 1e-4).
float node_mu(int i) {
  return std::max(float(i) / float(kN - 1), 1e-4f);
}

// Node j lies at roughness sqrt(alpha) = j / (kN - 1) (alpha at least kMinGgxAlpha): E changes
// fastest at small alpha, where these nodes crowd.
float node_alpha(int j) {
  const float r = float(j) / float(kN - 1);
  return std::max(r * r, kMinGgxAlpha);
}

float radical_inverse(uint32_t bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return float(bits) * 2.3283064365386963e-10f;
}

// E(mu, alpha) by sampling visible normals (Hammersley points): a reflected direction l has
// weight f cos / pdf = G2(v, l) / G1(v), 0 below the horizon.
float albedo_by_sampling(float mu, float alpha) {
  const Vec3f v{std::sqrt(std::max(0.0f, 1 - mu * mu)), 0, mu};
  const GgxAlpha a{alpha, alpha};
  const float g1 = smith_g1(v, a);
  double sum = 0;
  for (int s = 0; s < kSamples; ++s) {
    const Vec2f u{(float(s) + 0.5f) / float(kSamples), radical_inverse(uint32_t(s))};
    const Vec3f h = sample_ggx_vndf(v, a, u);
    const Vec3f l = h * (2 * dot(v, h)) - v;
    if (l.z > 0 && g1 > 0) sum += smith_g2(v, l, a) / g1;
  }
  return float(sum / kSamples);
}

struct Tables {
  float e[kN][kN];  // [alpha][mu]
  float e_avg[kN];  // [alpha]
};

Tables compute_tables() {
  Tables t{};
  for (int j = 0; j < kN; ++j) {
    for (int i = 0; i < kN; ++i) t.e[j][i] = std::min(1.0f, albedo_by_sampling(node_mu(i), node_alpha(j)));
    // 2 int E mu dmu over the interpolant, linear between the nodes i / (kN - 1).
    double avg = 0;
    for (int i = 0; i + 1 < kN; ++i) {
      const double a = double(i) / (kN - 1), b = double(i + 1) / (kN - 1), ea = t.e[j][i], eb = t.e[j][i + 1];
      const double slope = (eb - ea) / (b - a);
      avg += ea * (b * b - a * a) / 2 + slope * ((b * b * b - a * a * a) / 3 - a * (b * b - a * a) / 2);
    }
    t.e_avg[j] = float(2 * avg);
  }
  return t;
}

const Tables& tables() {
  static const Tables t = compute_tables();
  return t;
}

// Position of x among the nodes: cell index k (k + 1 < kN) and fraction f.
void locate(float x, float first, float last, int& k, float& f) {
  const float s = std::clamp((x - first) / (last - first), 0.0f, 1.0f) * float(kN - 1);
  k = std::min(int(s), kN - 2);
  f = s - float(k);
}

}  // namespace

float ggx_albedo(float cos_theta, float alpha) {
  const Tables& t = tables();
  const float mu = std::clamp(cos_theta, 0.0f, 1.0f);
  int i = 0, j = 0;
  float fi = 0, fj = 0;
  locate(mu, 0, 1, i, fi);
  locate(std::sqrt(std::max(alpha, 0.0f)), 0, 1, j, fj);
  const float e0 = t.e[j][i] * (1 - fi) + t.e[j][i + 1] * fi;
  const float e1 = t.e[j + 1][i] * (1 - fi) + t.e[j + 1][i + 1] * fi;
  return e0 * (1 - fj) + e1 * fj;
}

float ggx_average_albedo(float alpha) {
  const Tables& t = tables();
  int j = 0;
  float fj = 0;
  locate(std::sqrt(std::max(alpha, 0.0f)), 0, 1, j, fj);
  return t.e_avg[j] * (1 - fj) + t.e_avg[j + 1] * fj;
}

float ggx_multiscatter(float cos_v, float cos_l, float alpha) {
  if (!(cos_v > 0) || !(cos_l > 0)) return 0;
  const float e_avg = ggx_average_albedo(alpha);
  if (!(1 - e_avg > 1e-6f)) return 0;
  return (1 - ggx_albedo(cos_v, alpha)) * (1 - ggx_albedo(cos_l, alpha)) / (kPi * (1 - e_avg));
}

}  // namespace penumbra
