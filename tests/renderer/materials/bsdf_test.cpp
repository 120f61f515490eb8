// The glTF metallic-roughness BRDF (renderer/bsdf.h) against quadrature and analytic facts:
// D is normalised (int D cos = 1), the visible-normal density integrates to 1 and the VNDF
// sampler draws from it, the BRDF is reciprocal, its pdf integrates to the share of samples
// that stay above the horizon, sampled estimates of the directional albedo match quadrature (the GGX
// "furnace"), metals never reflect more than they receive, and a smooth white metal reflects
// everything at normal incidence.
#include "renderer/materials/bsdf.h"

#include <catch2/catch.hpp>

#include "renderer/core/rng.h"

using namespace penumbra;

namespace {

/// Midpoint quadrature over the upper hemisphere in (cos theta, phi): int g(w) dw.
template <typename G>
double hemisphere_integral(G&& g, int n_mu = 3000, int n_phi = 256) {
  double sum = 0;
  for (int i = 0; i < n_mu; ++i) {
    const double mu = (i + 0.5) / n_mu, s = std::sqrt(1 - mu * mu);
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2 * M_PI * (j + 0.5) / n_phi;
      sum += g(Vec3f{float(s * std::cos(phi)), float(s * std::sin(phi)), float(mu)});
    }
  }
  return sum * (2 * M_PI) / (double(n_mu) * n_phi);
}

Vec3f view_at(float theta) {
  return {std::sin(theta), 0, std::cos(theta)};
}

/// Mean sample weight (f cos / pdf) over n stratified samples: the directional albedo.
Vec3f sampled_albedo(const GltfBrdf& b, Vec3f wo, int n, uint64_t seed) {
  Rng rng = make_pixel_rng(1, 2, 3, seed);
  Vec3f sum;
  for (int i = 0; i < n; ++i) {
    BrdfSample s;
    if (brdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s)) sum += s.weight;
  }
  return sum / float(n);
}

}  // namespace

TEST_CASE("bsdf: GGX D is normalised and the visible normals integrate to 1", "[bsdf][quick]") {
  for (float alpha : {0.1f, 0.3f, 0.7f, 1.0f}) {
    INFO("alpha " << alpha);
    CHECK(hemisphere_integral([&](Vec3f h) { return ggx_d(h, alpha) * h.z; }) == Approx(1).epsilon(2e-3));
    for (float theta : {0.0f, 0.6f, 1.3f}) {
      const Vec3f v = view_at(theta);
      const double dv = hemisphere_integral(
          [&](Vec3f h) { return smith_g1(v, alpha) * std::max(0.0f, dot(v, h)) * ggx_d(h, alpha) / v.z; });
      CHECK(dv == Approx(1).epsilon(3e-3));
    }
  }
}

TEST_CASE("bsdf: the VNDF sampler draws visible normals with their density", "[bsdf][quick]") {
  Rng rng = make_pixel_rng(4, 5, 6, 7);
  for (float alpha : {0.2f, 0.6f}) {
    for (float theta : {0.3f, 1.2f}) {
      const Vec3f v = view_at(theta);
      auto density = [&](Vec3f h) {
        return smith_g1(v, alpha) * std::max(0.0f, dot(v, h)) * ggx_d(h, alpha) / v.z;
      };
      // Moments of the sampled normals against quadrature of the density.
      const int n = 200000;
      double mz = 0, mx = 0, mz4 = 0;
      for (int i = 0; i < n; ++i) {
        const Vec3f h = sample_ggx_vndf(v, alpha, {rng.next_float(), rng.next_float()});
        REQUIRE(h.z > 0);
        REQUIRE(dot(h, v) >= -1e-6f);  // a visible normal never faces away from the viewer
        mz += h.z;
        mx += h.x;
        mz4 += std::pow(h.z, 4.0f);
      }
      INFO("alpha " << alpha << ", theta " << theta);
      CHECK(mz / n == Approx(hemisphere_integral([&](Vec3f h) { return density(h) * h.z; })).epsilon(5e-3));
      CHECK(mx / n == Approx(hemisphere_integral([&](Vec3f h) { return density(h) * h.x; })).margin(5e-3));
      CHECK(mz4 / n == Approx(hemisphere_integral([&](Vec3f h) {
                         return density(h) * std::pow(h.z, 4.0f);
                       })).epsilon(1e-2));
    }
  }
}

TEST_CASE("bsdf: reciprocity, and no light below the surface", "[bsdf][quick]") {
  Rng rng = make_pixel_rng(1, 1, 1, 1);
  for (int i = 0; i < 1000; ++i) {
    GltfBrdf b;
    b.base_color = {rng.next_float(), rng.next_float(), rng.next_float()};
    b.metallic = rng.next_float();
    b.roughness = rng.next_float();
    b.n = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3f wo = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3f wi = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3f f1 = brdf_eval(b, wo, wi), f2 = brdf_eval(b, wi, wo);
    CHECK(f1.x == Approx(f2.x).epsilon(1e-4).margin(1e-6));
    CHECK(f1.y == Approx(f2.y).epsilon(1e-4).margin(1e-6));
    if (dot(wo, b.n) <= 0 || dot(wi, b.n) <= 0) {
      CHECK(f1 == Vec3f{});
      CHECK(brdf_pdf(b, wo, wi) == 0);
    }
  }
}

TEST_CASE("bsdf: the pdf integrates to 1 and sampling agrees with it", "[bsdf][quick]") {
  for (float rough : {0.3f, 0.7f, 1.0f})
    for (float metal : {0.0f, 0.5f, 1.0f})
      for (float theta : {0.2f, 1.0f}) {
        GltfBrdf b;
        b.base_color = {0.8f, 0.5f, 0.2f};
        b.metallic = metal;
        b.roughness = rough;
        const Vec3f wo = view_at(theta);
        const double total = hemisphere_integral([&](Vec3f wi) { return brdf_pdf(b, wo, wi); });
        INFO("roughness " << rough << ", metallic " << metal << ", theta " << theta);
        // Specular samples reflected below the horizon are lost (half of them for a rough
        // metal seen from above), so the pdf's mass is the share of samples that succeed.
        CHECK(total <= 1.002);
        Rng rng = make_pixel_rng(9, 9, 9, 9);
        const int n = 100000;
        int accepted = 0;
        for (int i = 0; i < n; ++i) {
          BrdfSample s;
          accepted += brdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s);
        }
        CHECK(double(accepted) / n == Approx(total).margin(0.006));
        // Every sample's weight is f cos / pdf as the other two functions say.
        for (int i = 0; i < 200; ++i) {
          BrdfSample s;
          if (!brdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
          CHECK(s.pdf == Approx(brdf_pdf(b, wo, s.wi)).epsilon(1e-5));
          const Vec3f expect = brdf_eval(b, wo, s.wi) * (s.wi.z / s.pdf);
          CHECK(s.weight.x == Approx(expect.x).epsilon(1e-5));
        }
      }
}

TEST_CASE("bsdf: GGX furnace: sampled directional albedo equals quadrature; smooth metal keeps all energy",
          "[bsdf]") {
  for (float rough : {0.25f, 0.5f, 1.0f})
    for (float metal : {0.0f, 1.0f})
      for (float theta : {0.0f, 0.8f, 1.3f}) {
        GltfBrdf b;
        b.base_color = {1, 1, 1};
        b.metallic = metal;
        b.roughness = rough;
        const Vec3f wo = view_at(theta);
        const double quad =
            hemisphere_integral([&](Vec3f wi) { return brdf_eval(b, wo, wi).x * wi.z; }, 6000, 256);
        const Vec3f mc = sampled_albedo(b, wo, 400000, 3);
        INFO("roughness " << rough << ", metallic " << metal << ", theta " << theta << ": quadrature " << quad
                          << ", sampled " << mc.x);
        CHECK(mc.x == Approx(quad).epsilon(0.01));
        // Metals never create energy (single scattering loses some). glTF's dielectric mix weights
        // the diffuse lobe by 1 - F(v.h) per direction rather than by the specular lobe's albedo,
        // so at grazing views it can exceed 1 (e.g. 1.16 at roughness 0.25, 74 degrees): that
        // is the specified model, so only normal incidence is bounded for it.
        if (metal == 1 || theta == 0.0f) CHECK(quad <= 1.0);
        if (metal == 1 && rough == 1.0f && theta == 0.0f) CHECK(quad < 0.9);  // rough metals lose energy
      }
  // Analytic: a smooth white metal (F = 1, G -> 1) reflects everything at normal incidence.
  GltfBrdf smooth;
  smooth.roughness = 0.05f;
  CHECK(sampled_albedo(smooth, view_at(0), 100000, 5).x == Approx(1).epsilon(0.01));
}
