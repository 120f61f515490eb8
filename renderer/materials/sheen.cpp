// Charlie sheen: distribution, visibility and the tabulated directional albedo.
#include "renderer/materials/sheen.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace penumbra {

namespace {

float sheen_alpha(float roughness) {
  const float r = std::clamp(roughness, kMinSheenRoughness, 1.0f);
  return r * r;
}

// The fitted exponent of Lambda (Estevez & Kulla 2017, table 1), blended between its fits at
// roughness 0 and 1 by (1 - alpha)^2.
float lambda_fit(float x, float alpha) {
  const float w = (1 - alpha) * (1 - alpha);
  const float a = 21.5473f + (25.3245f - 21.5473f) * w;
  const float b = 3.82987f + (3.32435f - 3.82987f) * w;
  const float c = 0.19823f + (0.16801f - 0.19823f) * w;
  const float d = -1.97760f + (-1.27393f + 1.97760f) * w;
  const float e = -4.32054f + (-4.85967f + 4.32054f) * w;
  return a / (1 + b * std::pow(x, c)) + d * x + e;
}

float sheen_lambda(float cos_theta, float alpha) {
  return cos_theta < 0.5f ? std::exp(lambda_fit(cos_theta, alpha))
                          : std::exp(2 * lambda_fit(0.5f, alpha) - lambda_fit(1 - cos_theta, alpha));
}

// The table's nodes are uniform in sqrt(cos theta), denser at grazing where E changes fastest.
constexpr int kTableCos = 32, kTableRough = 16;

struct AlbedoTable {
  std::array<float, kTableCos * kTableRough> e{};
  AlbedoTable() {
    // Midpoint quadrature over l in (cos theta, phi) for each (cos theta_v, roughness) node.
    const int n_mu = 128, n_phi = 48;
    for (int r = 0; r < kTableRough; ++r) {
      const float rough = float(r) / (kTableRough - 1);
      for (int c = 0; c < kTableCos; ++c) {
        const float x = float(c) / (kTableCos - 1);
        const float mu_v = std::max(1e-3f, x * x);
        const Vec3f v{std::sqrt(1 - mu_v * mu_v), 0, mu_v};
        double sum = 0;
        for (int i = 0; i < n_mu; ++i) {
          const float mu = (i + 0.5f) / n_mu, s = std::sqrt(1 - mu * mu);
          for (int j = 0; j < n_phi; ++j) {
            const float phi = kPi * (j + 0.5f) / n_phi;  // symmetric in phi: half the circle, twice
            sum += sheen_brdf(v, {s * std::cos(phi), s * std::sin(phi), mu}, rough) * mu;
          }
        }
        e[size_t(r * kTableCos + c)] = float(sum * 2 * kPi / (double(n_mu) * n_phi));
      }
    }
  }
};

}  // namespace

float charlie_d(Vec3f h, float roughness) {
  if (!(h.z > 0)) return 0;
  const float a = sheen_alpha(roughness), inv = 1 / a;
  const float sin2 = std::max(0.0f, 1 - h.z * h.z);
  return (2 + inv) * std::pow(sin2, 0.5f * inv) / (2 * kPi);
}

float sheen_visibility(float n_dot_l, float n_dot_v, float roughness) {
  if (!(n_dot_l > 0) || !(n_dot_v > 0)) return 0;
  const float a = sheen_alpha(roughness);
  const float v = 1 / ((1 + sheen_lambda(n_dot_v, a) + sheen_lambda(n_dot_l, a)) * 4 * n_dot_v * n_dot_l);
  return std::clamp(v, 0.0f, 1.0f);
}

float sheen_brdf(Vec3f v, Vec3f l, float roughness) {
  if (!(v.z > 0) || !(l.z > 0)) return 0;
  const Vec3f h = normalize(v + l);
  return charlie_d(h, roughness) * sheen_visibility(l.z, v.z, roughness);
}

float sheen_albedo(float n_dot_v, float roughness) {
  static const AlbedoTable table;
  const float x = std::sqrt(std::clamp(n_dot_v, 0.0f, 1.0f)) * (kTableCos - 1);
  const float y = std::clamp(roughness, 0.0f, 1.0f) * (kTableRough - 1);
  const int x0 = std::min(int(x), kTableCos - 2), y0 = std::min(int(y), kTableRough - 2);
  const float fx = x - float(x0), fy = y - float(y0);
  auto at = [&](int c, int r) { return table.e[size_t(r * kTableCos + c)]; };
  const float e0 = at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx;
  const float e1 = at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx;
  return e0 * (1 - fy) + e1 * fy;
}

}  // namespace penumbra
