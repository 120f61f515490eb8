// Microfacet and Fresnel building blocks (renderer/materials/microfacet.h) against analytic
// facts: the anisotropic GGX distribution is normalised and its visible normals integrate to 1
// and are drawn with their density; the exact Fresnel reflectance is ((n-1)/(n+1))^2 at normal
// incidence, 1 beyond the critical angle, and the same from both sides of an interface; refract()
// obeys Snell's law.
#include "renderer/materials/microfacet.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "renderer/core/rng.h"
#include "support/quadrature.h"

using namespace penumbra;

namespace {

template <typename G>
double hemisphere_integral(G&& g) {
  return test::hemisphere_integral(g, 2000, 512);
}

}  // namespace

TEST_CASE("microfacet: anisotropic GGX is normalised and its visible normals integrate to 1",
          "[bsdf][quick]") {
  for (GgxAlpha a : {GgxAlpha{0.2f, 0.6f}, GgxAlpha{0.9f, 0.1f}, GgxAlpha{1.0f, 0.4f}}) {
    INFO("alpha " << a.x << " x " << a.y);
    CHECK(hemisphere_integral([&](Vec3f h) { return ggx_d(h, a) * h.z; }) == Approx(1).epsilon(4e-3));
    for (Vec3f v :
         {Vec3f{0, 0, 1}, normalize(Vec3f{0.6f, 0.3f, 0.5f}), normalize(Vec3f{-0.2f, 0.9f, 0.2f})}) {
      const double dv = hemisphere_integral(
          [&](Vec3f h) { return smith_g1(v, a) * std::max(0.0f, dot(v, h)) * ggx_d(h, a) / v.z; });
      CHECK(dv == Approx(1).epsilon(5e-3));
    }
  }
}

TEST_CASE("microfacet: the anisotropic VNDF sampler draws visible normals with their density",
          "[bsdf][quick]") {
  Rng rng = make_pixel_rng(3, 1, 4, 1);
  const GgxAlpha a{0.7f, 0.15f};
  const Vec3f v = normalize(Vec3f{0.5f, 0.4f, 0.6f});
  auto density = [&](Vec3f h) { return smith_g1(v, a) * std::max(0.0f, dot(v, h)) * ggx_d(h, a) / v.z; };
  const int n = 200000;
  double mx = 0, my = 0, mz = 0;
  for (int i = 0; i < n; ++i) {
    const Vec3f h = sample_ggx_vndf(v, a, {rng.next_float(), rng.next_float()});
    REQUIRE(h.z > 0);
    mx += h.x;
    my += h.y;
    mz += h.z;
  }
  CHECK(mx / n == Approx(hemisphere_integral([&](Vec3f h) { return h.x * density(h); })).margin(4e-3));
  CHECK(my / n == Approx(hemisphere_integral([&](Vec3f h) { return h.y * density(h); })).margin(4e-3));
  CHECK(mz / n == Approx(hemisphere_integral([&](Vec3f h) { return h.z * density(h); })).margin(4e-3));
}

TEST_CASE("microfacet: exact dielectric Fresnel: normal incidence, total internal reflection, both sides",
          "[bsdf][quick]") {
  for (float n : {1.1f, 1.33f, 1.5f, 2.4f}) {
    INFO("ior " << n);
    const float r = (n - 1) / (n + 1);
    CHECK(fresnel_dielectric(1, n) == Approx(r * r).epsilon(1e-5));
    CHECK(fresnel_dielectric(1, 1 / n) == Approx(r * r).epsilon(1e-5));
    // From inside, every angle beyond the critical one reflects everything.
    const float critical = std::asin(1 / n);
    for (float t : {1.02f, 1.2f, 1.5f})
      if (critical * t < float(M_PI) / 2) CHECK(fresnel_dielectric(std::cos(critical * t), 1 / n) == 1);
    CHECK(fresnel_dielectric(std::cos(critical * 0.98f), 1 / n) < 1);
    // Stokes: the reflectance is the same for the refracted ray travelling back.
    for (float ti : {0.1f, 0.6f, 1.2f}) {
      const float tt = std::asin(std::sin(ti) / n);
      CHECK(fresnel_dielectric(std::cos(ti), n) ==
            Approx(fresnel_dielectric(std::cos(tt), 1 / n)).epsilon(1e-4));
    }
    CHECK(fresnel_dielectric(0, n) == Approx(1).margin(1e-6));  // grazing
  }
}

TEST_CASE("microfacet: refract obeys Snell's law and reports total internal reflection", "[bsdf][quick]") {
  const Vec3f m{0, 0, 1};
  for (float eta : {1.5f, 1 / 1.5f, 2.0f})
    for (float ti : {0.0f, 0.3f, 0.7f, 1.3f}) {
      const Vec3f v{std::sin(ti), 0, std::cos(ti)};
      Vec3f t;
      const bool ok = refract(v, m, eta, t);
      const float sin_t = std::sin(ti) / eta;
      INFO("eta " << eta << ", theta " << ti);
      REQUIRE(ok == (sin_t < 1));
      if (!ok) continue;
      CHECK(length(t) == Approx(1).epsilon(1e-5));
      CHECK(t.z < 0);
      CHECK(std::sqrt(t.x * t.x + t.y * t.y) == Approx(sin_t).margin(1e-5));
      CHECK(t.x * v.x <= 0);  // the refracted ray continues on the other side of the normal
    }
}
