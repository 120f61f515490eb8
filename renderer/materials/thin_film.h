// Thin-film interference for KHR_materials_iridescence: the Fresnel reflectance of a dielectric
// film of given thickness and index over a base, evaluated in RGB by the Fourier series of
// Belcour and Barla, "A Practical Extension to Microfacet Theory for the Modeling of Varying
// Iridescence" (ACM TOG 36(4), 2017), with the interface reflectances and the XYZ-Gaussian
// spectral sensitivity fit of the KHR_materials_iridescence specification.
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// RGB reflectance (linear Rec.709) at cos_theta (outside, in [0, 1]) of a film of index
/// film_ior and thickness_nm nanometres between the outside (index outside_ior) and a base of
/// normal-incidence reflectance base_f0 (per channel). Over its first 30 nm the film fades into
/// the bare base (smoothstep), so thickness 0 gives schlick(base_f0, cos_theta). Components in
/// [0, 1].
Vec3f iridescence_fresnel(float outside_ior, float film_ior, float cos_theta, float thickness_nm,
                          Vec3f base_f0);

/// The same series for monochromatic light of wavelength lambda_nm, summed to `terms` orders
/// (scalar base reflectance): converges to the Airy sum of the film's multiple reflections.
float iridescence_fresnel_mono(float outside_ior, float film_ior, float cos_theta, float thickness_nm,
                               float base_f0, float lambda_nm, int terms);

}  // namespace penumbra
