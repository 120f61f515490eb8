// Thin-film interference: Belcour & Barla's series with Schlick interface reflectances.
#include "renderer/materials/thin_film.h"

#include <algorithm>
#include <cmath>

#include "renderer/materials/microfacet.h"

namespace penumbra {

namespace {

float sq(float x) {
  return x * x;
}

float ior_to_f0(float n, float outside) {
  return sq((n - outside) / (n + outside));
}

// Index of a base from its normal-incidence reflectance against air (f0 < 1).
float f0_to_ior(float f0) {
  const float s = std::sqrt(std::clamp(f0, 0.0f, 0.9999f));
  return (1 + s) / (1 - s);
}

// The film's geometry: the index used (blended to the outside index as the film vanishes),
// cos theta inside the film, and the first interface's reflectance and phase shift. False on
// total internal reflection at the first interface (then the reflectance is 1).
struct Film {
  float ior, cos2, r12, t121, phi21;
};

// smoothstep(0, 30 nm): how much of the film a thickness makes.
float film_blend(float thickness_nm) {
  const float t = std::clamp(thickness_nm / 30.0f, 0.0f, 1.0f);
  return t * t * (3 - 2 * t);
}

bool film_of(float outside_ior, float film_ior, float cos1, float thickness_nm, Film& f) {
  f.ior = outside_ior + (film_ior - outside_ior) * film_blend(thickness_nm);
  const float sin2 = sq(outside_ior / f.ior) * (1 - sq(cos1));
  if (sin2 >= 1) return false;
  f.cos2 = std::sqrt(1 - sin2);
  f.r12 = schlick(ior_to_f0(f.ior, outside_ior), cos1);
  f.t121 = 1 - f.r12;
  const float phi12 = f.ior < outside_ior ? kPi : 0.0f;
  f.phi21 = kPi - phi12;
  return true;
}

// The second interface (film to base) for one channel: reflectance and phase shift.
void base_interface(const Film& f, float base_f0, float& r23, float& phi23) {
  const float base_ior = f0_to_ior(base_f0);
  r23 = schlick(ior_to_f0(base_ior, f.ior), f.cos2);
  phi23 = base_ior < f.ior ? kPi : 0.0f;
}

// XYZ sensitivity of the m-th order term at optical path difference opd (nm) and phase shift,
// converted to linear Rec.709 (the specification's Gaussian fit of the CIE 1931 functions).
Vec3f sensitivity(float opd, Vec3f shift) {
  const double phase = 2 * M_PI * double(opd) * 1e-9;
  const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13};
  const double pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06};
  const double var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
  double xyz[3];
  for (int c = 0; c < 3; ++c)
    xyz[c] = val[c] * std::sqrt(2 * M_PI * var[c]) * std::cos(pos[c] * phase + shift[c]) *
             std::exp(-phase * phase * var[c]);
  xyz[0] += 9.7470e-14 * std::sqrt(2 * M_PI * 4.5282e+09) * std::cos(2.2399e+06 * phase + shift[0]) *
            std::exp(-4.5282e+09 * phase * phase);
  for (double& x : xyz) x /= 1.0685e-7;
  return {float(3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2]),
          float(-0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2]),
          float(0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2])};
}

// One channel of the series: C0 + sum_m C_m S_m with C_m = (Rs - T121) sqrt(R12 R23)^m.
template <typename Sens>
float series(const Film& f, float r23, int terms, Sens&& s_m) {
  const float r123 = std::clamp(f.r12 * r23, 1e-5f, 0.9999f);
  const float rs = sq(f.t121) * r23 / (1 - r123);
  float result = f.r12 + rs;
  float cm = rs - f.t121;
  for (int m = 1; m <= terms; ++m) {
    cm *= std::sqrt(r123);
    result += cm * s_m(m);
  }
  return std::max(result, 0.0f);
}

}  // namespace

Vec3f iridescence_fresnel(float outside_ior, float film_ior, float cos_theta, float thickness_nm,
                          Vec3f base_f0) {
  Film f;
  if (!film_of(outside_ior, film_ior, cos_theta, thickness_nm, f)) return {1, 1, 1};
  if (!(thickness_nm > 0)) return schlick(base_f0, cos_theta);
  float r23[3];
  Vec3f phi;
  for (int c = 0; c < 3; ++c) base_interface(f, base_f0[c], r23[c], phi[c]);
  phi = phi + Vec3f{f.phi21, f.phi21, f.phi21};
  const float opd = 2 * f.ior * thickness_nm * f.cos2;
  // The sensitivities are shared by the three channels: two orders, as in the specification.
  const Vec3f s1 = sensitivity(opd, phi) * 2, s2 = sensitivity(2 * opd, phi * 2) * 2;
  // The film fades into the bare base over its first 30 nm (the index blend of film_of alone
  // leaves a residue of the first interface's Schlick term at grazing angles).
  const float blend = film_blend(thickness_nm);
  Vec3f out;
  for (int c = 0; c < 3; ++c) {
    const float film = std::min(1.0f, series(f, r23[c], 2, [&](int m) { return m == 1 ? s1[c] : s2[c]; }));
    out[c] = schlick(base_f0[c], cos_theta) * (1 - blend) + film * blend;
  }
  return out;
}

float iridescence_fresnel_mono(float outside_ior, float film_ior, float cos_theta, float thickness_nm,
                               float base_f0, float lambda_nm, int terms) {
  Film f;
  if (!film_of(outside_ior, film_ior, cos_theta, thickness_nm, f)) return 1;
  float r23, phi23;
  base_interface(f, base_f0, r23, phi23);
  const float delta = 2 * kPi * (2 * f.ior * thickness_nm * f.cos2) / lambda_nm;
  const float phi = f.phi21 + phi23;
  return series(f, r23, terms, [&](int m) { return 2 * std::cos(float(m) * (delta + phi)); });
}

}  // namespace penumbra
