// The GGX albedo table and Kulla-Conty energy compensation (renderer/materials/ggx_albedo.h):
// the table against an independent quadrature of the single-scattering lobe; the white furnace
// (a white metal reflects all light at every roughness and angle with compensation, what the
// table says without it); a white dielectric never reflects more than it receives.
#include "renderer/materials/ggx_albedo.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "renderer/core/rng.h"
#include "renderer/materials/bsdf.h"

using namespace penumbra;

namespace {

Vec3f view_at(float mu) {
  return {std::sqrt(1 - mu * mu), 0, mu};
}

/// The single-scattering albedo for a Fresnel of 1 by quadrature over half vectors:
/// int D(h) G2(v, l) (v.h) / mu_v dh, l the mirror of v about h (dl = 4 (v.h) dh). theta_h is
/// stepped as atan(alpha tan x) for x uniform, which spreads the steps over D's peak.
double albedo_by_quadrature(float mu, float alpha) {
  const Vec3f v = view_at(mu);
  const int n_x = 1500, n_phi = 384;
  double sum = 0;
  for (int i = 0; i < n_x; ++i) {
    const double x = (i + 0.5) / n_x * (M_PI / 2);
    const double th = std::atan(alpha * std::tan(x));
    const double dth = alpha / (std::cos(x) * std::cos(x)) / (1 + alpha * alpha * std::tan(x) * std::tan(x)) *
                       (M_PI / 2) / n_x;
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2 * M_PI * (j + 0.5) / n_phi;
      const Vec3f h{float(std::sin(th) * std::cos(phi)), float(std::sin(th) * std::sin(phi)),
                    float(std::cos(th))};
      const float vh = dot(v, h);
      if (!(vh > 0)) continue;
      const Vec3f l = h * (2 * vh) - v;
      if (!(l.z > 0)) continue;
      sum += double(ggx_d(h, alpha)) * smith_g2(v, l, GgxAlpha{alpha, alpha}) * vh / mu * std::sin(th) * dth *
             (2 * M_PI / n_phi);
    }
  }
  return sum;
}

/// The directional albedo by n x n BSDF samples, jittered in an n x n grid of strata, the lobe
/// choice independent of them.
Vec3f sampled_albedo_rgb(const GltfBsdf& b, float mu, int n) {
  const Vec3f wo = view_at(mu);
  Rng rng = make_pixel_rng(1, 2, 3, 4);
  Vec3f sum;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      BsdfSample s;
      const float u1 = rng.next_float();
      const Vec2f u{(i + rng.next_float()) / n, (j + rng.next_float()) / n};
      if (bsdf_sample(b, wo, u1, u, s)) sum += s.weight;
    }
  return sum / float(n * n);
}

double sampled_albedo(const GltfBsdf& b, float mu) {
  return sampled_albedo_rgb(b, mu, 256).x;
}

}  // namespace

TEST_CASE("ggx albedo: the table equals a quadrature of the single-scattering lobe", "[bsdf][quick]") {
  for (float alpha : {0.04f, 0.16f, 0.36f, 0.64f, 1.0f})
    for (float mu : {0.1f, 0.3f, 0.6f, 0.95f}) {
      const double quad = albedo_by_quadrature(mu, alpha);
      INFO("alpha " << alpha << " mu " << mu << ": quadrature " << quad << ", table "
                    << ggx_albedo(mu, alpha));
      CHECK(std::fabs(ggx_albedo(mu, alpha) - quad) < 3e-3);
    }
  // Analytic: at alpha = 1, D = 1 / pi and Lambda(l) = (1 / mu_l - 1) / 2, so seen head-on
  // E = int_0^1 mu / (1 + mu) dmu = 1 - ln 2. A smooth lobe keeps everything; rougher ones lose more.
  CHECK(ggx_albedo(1, 1) == Approx(1 - std::log(2.0)).margin(2e-3));
  CHECK(ggx_albedo(1, kMinGgxAlpha) > 0.999f);
  CHECK(ggx_average_albedo(1) < ggx_average_albedo(0.25f));
  CHECK(ggx_average_albedo(0.25f) < ggx_average_albedo(0.01f));
}

TEST_CASE("ggx albedo: white furnace: a white metal reflects all light with compensation", "[bsdf]") {
  for (float roughness : {0.2f, 0.4f, 0.6f, 0.8f, 1.0f})
    for (float mu : {0.2f, 0.5f, 0.9f}) {
      GltfBsdf b;
      b.base_color = {1, 1, 1};
      b.metallic = 1;
      b.roughness = roughness;
      const double on = sampled_albedo(b, mu);
      b.energy_compensation = false;
      const double off = sampled_albedo(b, mu);
      const float alpha = roughness * roughness;
      INFO("roughness " << roughness << " mu " << mu << ": compensated " << on << ", single scattering "
                        << off << ", table " << ggx_albedo(mu, alpha));
      CHECK(std::fabs(on - 1) < 0.005);
      CHECK(std::fabs(off - ggx_albedo(mu, alpha)) < 0.005);
      if (roughness == 1.0f) CHECK(off < 0.9);  // the energy single scattering loses
    }
}

TEST_CASE("ggx albedo: coloured metals and dielectrics gain energy without creating any", "[bsdf][quick]") {
  for (float roughness : {0.3f, 0.7f, 1.0f})
    for (float mu : {0.2f, 0.6f, 1.0f}) {
      INFO("roughness " << roughness << " mu " << mu);
      GltfBsdf gold;
      gold.base_color = {1.0f, 0.78f, 0.34f};
      gold.metallic = 1;
      gold.roughness = roughness;
      const Vec3f on = sampled_albedo_rgb(gold, mu, 128);
      gold.energy_compensation = false;
      const Vec3f off = sampled_albedo_rgb(gold, mu, 128);
      for (int c = 0; c < 3; ++c) {
        CHECK(on[c] >= off[c]);
        CHECK(on[c] <= 1.005f);
      }
      // A white dielectric keeps the specification's layering below 1 at normal incidence.
      GltfBsdf plastic;
      plastic.base_color = {1, 1, 1};
      plastic.metallic = 0;
      plastic.roughness = roughness;
      if (mu == 1.0f) CHECK(sampled_albedo(plastic, mu) <= 1.005);
    }
}
