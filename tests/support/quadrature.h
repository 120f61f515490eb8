// Midpoint quadrature over the unit hemisphere, the reference the BSDF tests integrate against.
#pragma once

#include <cmath>

#include "renderer/core/math.h"

namespace penumbra::test {

/// int g(w) dw over the upper hemisphere (w.z > 0) by the midpoint rule in (cos theta, phi).
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

}  // namespace penumbra::test
