// Thin-film interference (renderer/materials/thin_film.h): the series summed to many orders for
// one wavelength equals the closed-form Airy sum of the film's multiple reflections; a film of
// thickness 0 leaves the base's Fresnel reflectance; the RGB reflectance stays in [0, 1] and
// varies with thickness as interference does.
#include "renderer/materials/thin_film.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <complex>

#include "renderer/materials/microfacet.h"

using namespace penumbra;

namespace {

// The Airy sum r = r12 + t12 t21 r23 e^{i d} / (1 - r21 r23 e^{i d}) with the series' interface
// reflectances (Schlick, amplitude sqrt(R) and phase 0 or pi) and t12 t21 = 1 - R12; returns |r|^2.
double airy(double r12_int, double phi21, double r23_int, double phi23, double delta) {
  using C = std::complex<double>;
  const C r21 = std::polar(std::sqrt(r12_int), phi21), r12 = -r21;  // Stokes: r12 = -r21
  const C r23 = std::polar(std::sqrt(r23_int), phi23);
  const C e = std::polar(1.0, delta);
  const C r = r12 + (1 - r12_int) * r23 * e / (1.0 - r21 * r23 * e);
  return std::norm(r);
}

}  // namespace

TEST_CASE("thin film: the monochromatic series converges to the Airy closed form", "[bsdf][quick]") {
  const float film = 1.33f, base_f0 = 0.04f;  // water-like film on glass-like base
  for (float thickness : {120.0f, 300.0f, 550.0f})
    for (float cos1 : {1.0f, 0.7f, 0.3f})
      for (float lambda : {450.0f, 550.0f, 650.0f}) {
        // The same interface quantities as the implementation (Schlick reflectances, Snell).
        const float r0 = ((film - 1) / (film + 1)) * ((film - 1) / (film + 1));
        const float r12 = schlick(r0, cos1);
        const float cos2 = std::sqrt(1 - (1 - cos1 * cos1) / (film * film));
        const float base_ior = (1 + std::sqrt(base_f0)) / (1 - std::sqrt(base_f0));
        const float r1 = ((base_ior - film) / (base_ior + film)) * ((base_ior - film) / (base_ior + film));
        const float r23 = schlick(r1, cos2);
        const double delta = 2 * M_PI * 2 * film * thickness * cos2 / lambda;
        const double expect =
            airy(r12, M_PI, r23, base_ior < film ? M_PI : 0, delta);  // film above air: phi21 = pi
        INFO("thickness " << thickness << " nm, cos " << cos1 << ", lambda " << lambda);
        CHECK(iridescence_fresnel_mono(1, film, cos1, thickness, base_f0, lambda, 200) ==
              Approx(expect).margin(2e-4));
      }
}

TEST_CASE("thin film: no film leaves the base; the RGB reflectance is bounded and varies", "[bsdf][quick]") {
  const Vec3f f0{0.04f, 0.04f, 0.04f};
  for (float cos1 : {1.0f, 0.5f, 0.1f}) {
    const Vec3f bare = iridescence_fresnel(1, 1.3f, cos1, 0, f0);
    CHECK(bare.x == Approx(schlick(0.04f, cos1)).margin(1e-3));
    CHECK(bare.z == Approx(schlick(0.04f, cos1)).margin(1e-3));
  }
  float lo = 1, hi = 0;
  for (float d = 50; d <= 1200; d += 25)
    for (float cos1 : {1.0f, 0.6f, 0.2f}) {
      const Vec3f r = iridescence_fresnel(1, 1.5f, cos1, d, {0.3f, 0.5f, 0.9f});
      for (int c = 0; c < 3; ++c) {
        REQUIRE(r[c] >= 0);
        REQUIRE(r[c] <= 1);
      }
      if (cos1 == 1) {
        lo = std::min(lo, r.y);
        hi = std::max(hi, r.y);
      }
    }
  CHECK(hi - lo > 0.05f);  // interference makes the green reflectance swing with thickness
}
