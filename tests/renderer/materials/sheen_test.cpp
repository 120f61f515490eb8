// The Charlie sheen lobe (renderer/materials/sheen.h): its distribution is normalised, its
// tabulated directional albedo equals direct quadrature, and it never reflects more than it
// receives.
#include "renderer/materials/sheen.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "support/quadrature.h"

using namespace penumbra;

namespace {

template <typename G>
double hemisphere_integral(G&& g) {
  return test::hemisphere_integral(g, 1500, 256);
}

}  // namespace

TEST_CASE("sheen: the Charlie distribution is normalised", "[bsdf][quick]") {
  for (float r : {0.3f, 0.5f, 0.8f, 1.0f}) {
    INFO("roughness " << r);
    CHECK(hemisphere_integral([&](Vec3f h) { return charlie_d(h, r) * h.z; }) == Approx(1).epsilon(3e-3));
  }
}

TEST_CASE("sheen: the albedo table equals quadrature, and the lobe never creates energy", "[bsdf][quick]") {
  double max_albedo = 0;
  for (float r : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f})
    for (float mu : {0.05f, 0.3f, 0.6f, 1.0f}) {
      const Vec3f v{std::sqrt(1 - mu * mu), 0, mu};
      const double quad = hemisphere_integral([&](Vec3f l) { return sheen_brdf(v, l, r) * l.z; });
      INFO("roughness " << r << ", cos " << mu << ": quadrature " << quad);
      CHECK(sheen_albedo(mu, r) == Approx(quad).epsilon(0.02).margin(2e-3));
      CHECK(quad <= 1.0);
      max_albedo = std::max(max_albedo, quad);
    }
  WARN("sheen: largest directional albedo on the grid " << max_albedo);
  // Reciprocal by construction: the visibility is symmetric in the two cosines.
  CHECK(sheen_visibility(0.3f, 0.8f, 0.5f) == Approx(sheen_visibility(0.8f, 0.3f, 0.5f)));
}
