// The glTF metallic-roughness BRDF (renderer/bsdf.h) against quadrature and analytic facts:
// D is normalised (int D cos = 1), the visible-normal density integrates to 1 and the VNDF
// sampler draws from it, the BRDF is reciprocal, its pdf integrates to the share of samples
// that stay above the horizon, sampled estimates of the directional albedo match quadrature (the GGX
// "furnace"), metals never reflect more than they receive, and a smooth white metal reflects
// everything at normal incidence.
#include "renderer/materials/bsdf.h"

#include <catch2/catch.hpp>

#include "renderer/core/rng.h"
#include "support/quadrature.h"

using namespace penumbra;

namespace {

using test::hemisphere_integral;

Vec3f view_at(float theta) {
  return {std::sin(theta), 0, std::cos(theta)};
}

/// Mean sample weight (f cos / pdf) over n stratified samples: the directional albedo.
Vec3f sampled_albedo(const GltfBsdf& b, Vec3f wo, int n, uint64_t seed) {
  Rng rng = make_pixel_rng(1, 2, 3, seed);
  Vec3f sum;
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    if (bsdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s)) sum += s.weight;
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
    GltfBsdf b;
    b.base_color = {rng.next_float(), rng.next_float(), rng.next_float()};
    b.metallic = rng.next_float();
    b.roughness = rng.next_float();
    b.n = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3f wo = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3f wi = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Vec3f f1 = bsdf_eval(b, wo, wi), f2 = bsdf_eval(b, wi, wo);
    CHECK(f1.x == Approx(f2.x).epsilon(1e-4).margin(1e-6));
    CHECK(f1.y == Approx(f2.y).epsilon(1e-4).margin(1e-6));
    if (dot(wo, b.n) <= 0 || dot(wi, b.n) <= 0) {
      CHECK(f1 == Vec3f{});
      CHECK(bsdf_pdf(b, wo, wi) == 0);
    }
  }
}

TEST_CASE("bsdf: the pdf integrates to 1 and sampling agrees with it", "[bsdf][quick]") {
  for (float rough : {0.3f, 0.7f, 1.0f})
    for (float metal : {0.0f, 0.5f, 1.0f})
      for (float theta : {0.2f, 1.0f}) {
        GltfBsdf b;
        b.base_color = {0.8f, 0.5f, 0.2f};
        b.metallic = metal;
        b.roughness = rough;
        const Vec3f wo = view_at(theta);
        const double total = hemisphere_integral([&](Vec3f wi) { return bsdf_pdf(b, wo, wi); });
        INFO("roughness " << rough << ", metallic " << metal << ", theta " << theta);
        // Specular samples reflected below the horizon are lost (half of them for a rough
        // metal seen from above), so the pdf's mass is the share of samples that succeed.
        CHECK(total <= 1.002);
        Rng rng = make_pixel_rng(9, 9, 9, 9);
        const int n = 100000;
        int accepted = 0;
        for (int i = 0; i < n; ++i) {
          BsdfSample s;
          accepted += bsdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s);
        }
        CHECK(double(accepted) / n == Approx(total).margin(0.006));
        // Every sample's weight is f cos / pdf as the other two functions say.
        for (int i = 0; i < 200; ++i) {
          BsdfSample s;
          if (!bsdf_sample(b, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
          CHECK(s.pdf == Approx(bsdf_pdf(b, wo, s.wi)).epsilon(1e-5));
          const Vec3f expect = bsdf_eval(b, wo, s.wi) * (s.wi.z / s.pdf);
          CHECK(s.weight.x == Approx(expect.x).epsilon(1e-5));
        }
      }
}

TEST_CASE("bsdf: GGX furnace: sampled directional albedo equals quadrature; smooth metal keeps all energy",
          "[bsdf][heavy]") {
  for (float rough : {0.25f, 0.5f, 1.0f})
    for (float metal : {0.0f, 1.0f})
      for (float theta : {0.0f, 0.8f, 1.3f}) {
        GltfBsdf b;
        b.base_color = {1, 1, 1};
        b.metallic = metal;
        b.roughness = rough;
        b.energy_compensation = false;  // the specification's single scattering
        const Vec3f wo = view_at(theta);
        const double quad =
            hemisphere_integral([&](Vec3f wi) { return bsdf_eval(b, wo, wi).x * wi.z; }, 6000, 256);
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
  GltfBsdf smooth;
  smooth.roughness = 0.05f;
  CHECK(sampled_albedo(smooth, view_at(0), 100000, 5).x == Approx(1).epsilon(0.01));
}

// ---- The KHR extensions' layers and lobes ----

namespace {

/// int g(w) dw over the whole sphere (upper and lower hemispheres).
template <typename G>
double sphere_integral(G&& g, int n_mu, int n_phi) {
  return hemisphere_integral(g, n_mu, n_phi) + hemisphere_integral(
                                                   [&](Vec3f w) {
                                                     return g(Vec3f{w.x, w.y, -w.z});
                                                   },
                                                   n_mu, n_phi);
}

/// Energy leaving for wo: int (f_r + eta^2 f_t) |cos| (the refracted radiance's 1/eta^2 undone).
double furnace(const GltfBsdf& b, Vec3f wo, int n_mu = 300, int n_phi = 96) {
  return sphere_integral(
      [&](Vec3f wi) {
        const float scale = wi.z < 0 && b.volume ? b.eta * b.eta : 1.0f;
        return double(max_component(bsdf_eval(b, wo, wi))) * std::fabs(wi.z) * scale;
      },
      n_mu, n_phi);
}

/// A BSDF with every layer set from one parameter draw (white base, a random mix of lobes).
GltfBsdf random_layers(Rng& rng) {
  GltfBsdf b;
  b.base_color = {0.3f + 0.7f * rng.next_float(), 0.3f + 0.7f * rng.next_float(),
                  0.3f + 0.7f * rng.next_float()};
  b.metallic = rng.next_float() < 0.3f ? 1.0f : rng.next_float() * 0.5f;
  b.roughness = 0.2f + 0.8f * rng.next_float();
  b.clearcoat = rng.next_float();
  b.clearcoat_roughness = 0.1f + 0.9f * rng.next_float();
  b.sheen_color = Vec3f{rng.next_float(), rng.next_float(), rng.next_float()};
  b.sheen_roughness = 0.2f + 0.8f * rng.next_float();
  b.anisotropy = rng.next_float();
  b.t = {1, 0, 0};
  b.iridescence = rng.next_float();
  b.iridescence_thickness = 100 + 700 * rng.next_float();
  b.diffuse_transmission = rng.next_float();
  b.diffuse_transmission_color = {rng.next_float(), rng.next_float(), rng.next_float()};
  return b;
}

}  // namespace

TEST_CASE("bsdf layers: white furnace on a parameter grid: no layer adds energy to the base",
          "[bsdf][heavy]") {
  double worst = 0, worst_excess = -1;
  std::string worst_case;
  for (float rough : {0.3f, 1.0f})
    for (float metal : {0.0f, 1.0f})
      for (float theta : {0.0f, 0.8f, 1.3f}) {
        GltfBsdf base;
        base.base_color = {1, 1, 1};
        base.metallic = metal;
        base.roughness = rough;
        const Vec3f wo = view_at(theta);
        const double base_energy = furnace(base, wo);
        // The bound: what the base alone reflects (glTF's base exceeds 1 slightly at grazing
        // views, see the GGX furnace above), and never more than 1 where the base stays below.
        // Iridescence replaces the Fresnel term of that same per-direction layering with the
        // thin film's, whose interference peaks raise it by up to a few percent more.
        const double bound = std::max(1.0, base_energy) + 2e-3;
        auto check = [&](const GltfBsdf& b, const std::string& what) {
          const double e = furnace(b, wo);
          INFO(what << ", roughness " << rough << ", metallic " << metal << ", theta " << theta << ": " << e
                    << " (base " << base_energy << ")");
          CHECK(e <= bound + (b.iridescence > 0 ? 0.06 : 0.0));
          if (e > worst) {
            worst = e;
            worst_case = what;
          }
          worst_excess = std::max(worst_excess, e - std::max(1.0, base_energy));
        };
        for (float c : {0.5f, 1.0f})
          for (float cr : {0.05f, 0.5f, 1.0f}) {
            GltfBsdf b = base;
            b.clearcoat = c;
            b.clearcoat_roughness = cr;
            check(b, "clearcoat " + std::to_string(c) + "/" + std::to_string(cr));
          }
        for (float s : {0.5f, 1.0f})
          for (float sr : {0.2f, 0.6f, 1.0f}) {
            GltfBsdf b = base;
            b.sheen_color = {s, s, s};
            b.sheen_roughness = sr;
            check(b, "sheen " + std::to_string(s) + "/" + std::to_string(sr));
          }
        for (float a : {0.5f, 1.0f}) {
          GltfBsdf b = base;
          b.anisotropy = a;
          check(b, "anisotropy " + std::to_string(a));
        }
        for (float d : {150.0f, 400.0f, 800.0f}) {
          GltfBsdf b = base;
          b.iridescence = 1;
          b.iridescence_thickness = d;
          check(b, "iridescence " + std::to_string(d));
        }
        for (float dt : {0.5f, 1.0f}) {
          GltfBsdf b = base;
          b.diffuse_transmission = dt;
          check(b, "diffuse transmission " + std::to_string(dt));
        }
        for (float eta : {1.5f, 1 / 1.5f}) {
          GltfBsdf b = base;
          b.transmission = 1;
          b.volume = true;
          b.eta = eta;
          check(b, "refraction eta " + std::to_string(eta));
        }
      }
  WARN("bsdf layers: largest furnace energy " << worst << " (" << worst_case << "); largest excess over "
                                              << "max(1, base) " << worst_excess);
}

TEST_CASE("bsdf layers: reciprocity, and the refraction lobe's eta^2", "[bsdf][quick]") {
  Rng rng = make_pixel_rng(7, 7, 7, 7);
  for (int i = 0; i < 500; ++i) {
    const GltfBsdf b = random_layers(rng);
    const Vec3f wo =
        normalize(Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() + 0.05f});
    const Vec3f wi =
        normalize(Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() + 0.05f});
    const Vec3f f1 = bsdf_eval(b, wo, wi), f2 = bsdf_eval(b, wi, wo);
    for (int c = 0; c < 3; ++c) CHECK(f1[c] == Approx(f2[c]).epsilon(1e-3).margin(1e-5));
    // Diffuse transmission: the same value seen from the other side (normal flipped).
    const Vec3f wt{wi.x, wi.y, -wi.z};
    GltfBsdf back = b;
    back.n = -b.n;
    back.clearcoat_n = -b.n;
    const Vec3f t1 = bsdf_eval(b, wo, wt), t2 = bsdf_eval(back, wt, wo);
    for (int c = 0; c < 3; ++c) CHECK(t1[c] == Approx(t2[c]).epsilon(1e-3).margin(1e-5));
  }
  // Refraction carries radiance's 1/eta^2: f(l -> v) = eta^2 f(v -> l).
  for (int i = 0; i < 300; ++i) {
    GltfBsdf b;
    b.base_color = {1, 1, 1};
    b.metallic = 0;
    b.roughness = 0.3f + 0.7f * rng.next_float();
    b.transmission = 1;
    b.volume = true;
    b.eta = rng.next_float() < 0.5f ? 1.5f : 1.33f;
    const Vec3f v =
        normalize(Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() + 0.05f});
    const Vec3f l =
        normalize(Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, -rng.next_float() - 0.05f});
    GltfBsdf inside = b;
    inside.n = -b.n;
    inside.eta = 1 / b.eta;
    const float forward = bsdf_eval(b, v, l).x, backward = bsdf_eval(inside, l, v).x;
    CHECK(backward == Approx(b.eta * b.eta * forward).epsilon(2e-3).margin(1e-6));
  }
}

TEST_CASE("bsdf layers: sampling agrees with pdf and eval, and the pdf integrates to the accepted share",
          "[bsdf][quick]") {
  Rng rng = make_pixel_rng(5, 4, 3, 2);
  for (int k = 0; k < 8; ++k) {
    GltfBsdf b = random_layers(rng);
    if (k % 3 == 0) {
      b.metallic = 0;
      b.transmission = 0.8f;
      b.volume = true;
      b.eta = k % 2 ? 1.5f : 1 / 1.5f;
    }
    const Vec3f wo = view_at(0.2f + 0.1f * float(k));
    const double total = sphere_integral([&](Vec3f wi) { return bsdf_pdf(b, wo, wi); }, 1000, 256);
    Rng srng = make_pixel_rng(1, 2, 3, uint64_t(k));
    const int n = 60000;
    int accepted = 0;
    for (int i = 0; i < n; ++i) {
      BsdfSample s;
      accepted += bsdf_sample(b, wo, srng.next_float(), {srng.next_float(), srng.next_float()}, s);
    }
    INFO("draw " << k);
    CHECK(total <= 1.005);
    CHECK(double(accepted) / n == Approx(total).margin(0.01));
    for (int i = 0; i < 300; ++i) {
      BsdfSample s;
      if (!bsdf_sample(b, wo, srng.next_float(), {srng.next_float(), srng.next_float()}, s)) continue;
      CHECK(s.pdf == Approx(bsdf_pdf(b, wo, s.wi)).epsilon(1e-4));
      const Vec3f expect = bsdf_eval(b, wo, s.wi) * (std::fabs(s.wi.z) / s.pdf);
      for (int c = 0; c < 3; ++c) CHECK(s.weight[c] == Approx(expect[c]).epsilon(1e-4).margin(1e-7));
    }
  }
}

TEST_CASE("bsdf layers: sampled albedo equals quadrature within 1%", "[bsdf][heavy]") {
  Rng rng = make_pixel_rng(8, 6, 4, 2);
  for (int k = 0; k < 6; ++k) {
    GltfBsdf b = random_layers(rng);
    if (k % 4 == 1) {
      b.metallic = 0;
      b.transmission = 1;
      b.volume = true;
      b.eta = 1.5f;
    }
    const Vec3f wo = view_at(0.15f * float(k));
    const double quad = sphere_integral(
        [&](Vec3f wi) { return double(luminance(bsdf_eval(b, wo, wi))) * std::fabs(wi.z); }, 1500, 256);
    Rng srng = make_pixel_rng(2, 3, 4, uint64_t(k));
    double mc = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      BsdfSample s;
      if (bsdf_sample(b, wo, srng.next_float(), {srng.next_float(), srng.next_float()}, s))
        mc += luminance(s.weight);
    }
    mc /= n;
    INFO("draw " << k << ": quadrature " << quad << ", sampled " << mc);
    CHECK(mc == Approx(quad).epsilon(0.01));
  }
}

TEST_CASE(
    "bsdf layers: a smooth dielectric volume reflects ((n-1)/(n+1))^2 at normal incidence, all "
    "beyond the critical angle",
    "[bsdf][quick]") {
  GltfBsdf b;
  b.base_color = {1, 1, 1};
  b.metallic = 0;
  b.roughness = 0;
  b.transmission = 1;
  b.volume = true;
  b.eta = 1.5f;
  Rng rng = make_pixel_rng(6, 6, 6, 6);
  const int n = 200000;
  double reflected = 0, refracted = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    if (!bsdf_sample(b, view_at(0), rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
    (s.wi.z > 0 ? reflected : refracted) += s.weight.x * (s.wi.z > 0 ? 1.0 : b.eta * b.eta);
  }
  CHECK(reflected / n == Approx(0.04).epsilon(0.03));
  CHECK((reflected + refracted) / n == Approx(1).epsilon(0.01));
  // From inside, beyond asin(1/1.5) = 41.8 degrees, nothing leaves.
  b.eta = 1 / 1.5f;
  refracted = reflected = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample s;
    if (!bsdf_sample(b, view_at(0.9f), rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
    (s.wi.z > 0 ? reflected : refracted) += s.weight.x;
  }
  CHECK(refracted == 0);
  CHECK(reflected / n == Approx(1).epsilon(0.01));
}

TEST_CASE("bsdf layers: only transmission lobes send samples to the far side", "[bsdf][quick]") {
  // An opaque clear-coated material whose coat normal leans away from the base normal: coat
  // samples may fall below the base normal, but they are reflections.
  GltfBsdf b;
  b.base_color = {0.8f, 0.8f, 0.8f};
  b.metallic = 0;
  b.roughness = 0.5f;
  b.clearcoat = 1;
  b.clearcoat_roughness = 0.3f;
  b.clearcoat_n = normalize(Vec3f{0.6f, 0, 0.8f});
  REQUIRE_FALSE(has_transmission_lobes(b));
  Rng rng = make_pixel_rng(4, 4, 4, 4);
  int below_n = 0;
  for (int i = 0; i < 20000; ++i) {
    BsdfSample s;
    if (!bsdf_sample(b, view_at(-0.55f), rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
    CHECK_FALSE(s.transmitted);
    below_n += s.wi.z < 0;
  }
  CHECK(below_n > 0);  // the case exists: coat reflections below the base normal
  // With diffuse transmission, samples of that lobe are marked.
  b.diffuse_transmission = 1;
  REQUIRE(has_transmission_lobes(b));
  int transmitted = 0;
  for (int i = 0; i < 20000; ++i) {
    BsdfSample s;
    if (!bsdf_sample(b, view_at(0.2f), rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
    if (s.transmitted) {
      ++transmitted;
      CHECK(s.wi.z < 0);
    }
  }
  CHECK(transmitted > 0);
}

TEST_CASE("bsdf layers: KHR_materials_specular's colour tints the dielectric f0 per channel",
          "[bsdf][quick]") {
  // A black dielectric seen along its normal reflects s min(f0 c, 1) of what the white one's
  // f0 gives there (Schlick at v.h = 1 is f0): the ratio is exact at the mirror direction.
  GltfBsdf b;
  b.base_color = {0, 0, 0};
  b.metallic = 0;
  b.roughness = 0.3f;
  b.specular = 0.8f;
  GltfBsdf plain = b;
  b.specular_color = {1, 0.5f, 30};
  const Vec3f n = view_at(0);
  const Vec3f f = bsdf_eval(b, n, n), f1 = bsdf_eval(plain, n, n);
  REQUIRE(f1.x > 0);
  CHECK(f.x / f1.x == Approx(1).epsilon(1e-5));
  CHECK(f.y / f1.y == Approx(0.5).epsilon(1e-5));
  CHECK(f.z / f1.z == Approx(1 / 0.04).epsilon(1e-4));  // f0 c clamped to 1
}
