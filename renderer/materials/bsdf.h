// The glTF 2.0 metallic-roughness BRDF (glTF specification, Appendix B): evaluation, density
// and sampling of its diffuse and GGX specular lobes in world-space directions.
#pragma once

// The glTF 2.0 metallic-roughness BRDF (glTF specification, Appendix B): Trowbridge-Reitz (GGX)
// distribution with alpha = roughness^2, height-correlated Smith visibility, Schlick Fresnel,
// Lambert diffuse under the dielectric's Fresnel layer, and the dielectric/metal mix by
// `metallic`:
//   f = (1 - m)(1 - t)(1 - s F(f0)) c / pi + [(1 - m) s F(f0) + m F(c)] D V
// with f0 = 0.04 for the core model (KHR_materials_ior: ((ior - 1)/(ior + 1))^2), s the
// KHR_materials_specular factor (1 by default) and t the KHR_materials_transmission factor (0 by
// default; the transmitted part is a delta lobe the integrator handles, see path.h).
// Sampling picks the diffuse or the specular lobe, the specular one by its distribution of
// visible normals (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018);
// pdf() is the combined density of both, so estimators may use any of the three functions.
// Directions are unit vectors in world space; the shading frame comes from the normal.

#include "renderer/core/math.h"

namespace penumbra {

/// A BRDF at one point. Requires a unit shading normal n.
struct GltfBrdf {
  Vec3f base_color{1, 1, 1};
  float metallic = 1;
  float roughness = 1;
  Vec3f n{0, 0, 1};
  float f0 = 0.04f;        ///< dielectric reflectance at normal incidence
  float specular = 1;      ///< KHR_materials_specular factor: scales the dielectric Fresnel
  float transmission = 0;  ///< KHR_materials_transmission: share of the diffuse base removed
};

/// Fresnel reflectance of the dielectric layer at cos(theta) = cos_theta: s Schlick(f0).
float dielectric_fresnel(const GltfBrdf& b, float cos_theta);

/// Smallest alpha used: roughness 0 would make D a Dirac delta (below 1e-3 the lobe is
/// narrower than float directions resolve anyway).
inline constexpr float kMinGgxAlpha = 1e-3f;

/// f(wo, wi), zero unless both directions are above the shading surface. Reciprocal.
Vec3f brdf_eval(const GltfBrdf& b, Vec3f wo, Vec3f wi);
/// The diffuse and specular terms of brdf_eval (their sum), for light-group AOVs.
void brdf_eval_parts(const GltfBrdf& b, Vec3f wo, Vec3f wi, Vec3f& diffuse, Vec3f& specular);
/// brdf_eval and brdf_pdf together, sharing the frame and half vector (pdf is set).
Vec3f brdf_eval_pdf(const GltfBrdf& b, Vec3f wo, Vec3f wi, float& pdf);
/// Solid-angle density with which brdf_sample() produces wi (both lobes combined).
float brdf_pdf(const GltfBrdf& b, Vec3f wo, Vec3f wi);

struct BrdfSample {
  Vec3f wi;
  Vec3f weight;  ///< f cos(theta_i) / pdf (0 when the sample fails)
  float pdf = 0;
};
/// Samples wi from u1 (lobe choice) and u (direction), both uniform in [0, 1).
/// Returns false (and a zero weight) if wo is below the surface or the sample is.
bool brdf_sample(const GltfBrdf& b, Vec3f wo, float u1, Vec2f u, BrdfSample& out);

/// Probability of choosing the specular lobe: its share of the Fresnel-at-normal-incidence
/// reflectance, (1 - m) s f0 + m c against (1 - m)(1 - t)(1 - s f0) c (luminances).
float specular_probability(const GltfBrdf& b);

/// The GGX pieces, in the local frame where the normal is +z (exposed for tests).
float ggx_d(Vec3f h, float alpha);
float smith_g1(Vec3f v, float alpha);
/// Height-correlated visibility V = G2 / (4 |n.l| |n.v|) (Heitz 2014, eq. 99).
float smith_visibility(float n_dot_l, float n_dot_v, float alpha);
/// A visible normal for view direction v (local, v.z > 0) from u in [0,1)^2.
Vec3f sample_ggx_vndf(Vec3f v, float alpha, Vec2f u);

/// An orthonormal basis (t, b, n) around unit n (Duff et al., "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1), 2017).
void make_frame(Vec3f n, Vec3f& t, Vec3f& b);

/// Cosine-weighted direction in the local frame (+z up) from u in [0,1)^2 (Malley's method).
Vec3f sample_cosine_hemisphere(Vec2f u);

}  // namespace penumbra
