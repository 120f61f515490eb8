// Multiple-scattering energy compensation for GGX reflection (Kulla & Conty, "Revisiting
// Physically Based Shading at Imageworks", SIGGRAPH 2017 course): a single-scattering microfacet
// lobe loses the energy of light that bounces more than once between microfacets (at roughness 1
// a white metal reflects about 60% of grazing light); the compensation adds the lobe
//
//   f_ms(v, l) = F_ms (1 - E(mu_v)) (1 - E(mu_l)) / (pi (1 - E_avg)),
//   F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)),
//
// with E(mu) the lobe's directional albedo for a Fresnel of 1, E_avg = 2 int E(mu) mu dmu its
// cosine-weighted average and F_avg = 2 int F(mu) mu dmu the Fresnel's. For F = 1 the albedo is
// then exactly 1 at every angle and roughness (the white furnace).
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// E(mu, alpha): the directional albedo of the isotropic GGX reflection lobe D G2 / (4 mu_v mu_l)
/// with height-correlated Smith masking and a Fresnel of 1, at cos(theta_v) = cos_theta (clamped
/// to [0, 1]) and alpha (clamped to [kMinGgxAlpha, 1]). Interpolated bilinearly in a 32 x 32
/// table over mu and sqrt(alpha) (the roughness), computed once on first use by sampling visible
/// normals (1024 stratified samples per entry, weight G2 / G1). Never allocates.
float ggx_albedo(float cos_theta, float alpha);

/// E_avg(alpha) = 2 int_0^1 E(mu, alpha) mu dmu, integrated exactly over the table's
/// interpolant, so that the compensation lobe's albedo is exactly 1 - E(mu_v).
float ggx_average_albedo(float alpha);

/// (1 - E(mu_v)) (1 - E(mu_l)) / (pi (1 - E_avg)): the compensation lobe for F_ms = 1; 0 when
/// either cosine is not positive or the lobe loses no energy (E_avg within 1e-6 of 1).
float ggx_multiscatter(float cos_v, float cos_l, float alpha);

/// F_avg of Schlick's Fresnel with normal reflectance f0: f0 + (1 - f0) / 21.
inline float schlick_average(float f0) {
  return f0 + (1 - f0) / 21;
}

/// F_ms of Kulla and Conty for an average Fresnel f_avg (per channel) and E_avg.
inline Vec3f multiscatter_fresnel(Vec3f f_avg, float e_avg) {
  Vec3f f;
  for (int c = 0; c < 3; ++c) f[c] = f_avg[c] * f_avg[c] * e_avg / (1 - f_avg[c] * (1 - e_avg));
  return f;
}

}  // namespace penumbra
