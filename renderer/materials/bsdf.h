// The glTF 2.0 BSDF: the metallic-roughness BRDF of the core specification (Appendix B) with the
// layers and lobes of the ratified KHR material extensions, evaluated, sampled and given a
// density in world-space directions.
#pragma once

// The model, from the outside in (the Khronos extension specifications' layering, made
// reciprocal by applying each layer's Fresnel attenuation on both directions):
//
//   f = coat + A_c(v) A_c(l) [ sheen + S(v, l) base ]
//
// - coat (KHR_materials_clearcoat): c F_c(v.h_c) D_c V_c, an isotropic GGX layer of index 1.5
//   (f0 = 0.04) with its own normal; A_c(w) = 1 - c F_c(|n_c.w|). The coat's cosine is its own
//   normal's: its value carries n_c.l / |n.l| so that the estimators' |n.l| gives it (with a
//   coat normal map this breaks reciprocity, as any shading normal does).
// - sheen (KHR_materials_sheen): sheenColor D_charlie V_sheen (sheen.h); the layers below are
//   scaled by S = 1 - max(sheenColor) max(E(|n.v|), E(|n.l|)), E the sheen's directional albedo.
// - base, reflection (l above the surface):
//     [(1 - m) F_d + m F_m] D V  +  (1 - m)(1 - t)(1 - d)(1 - max F_d) c / pi
//   with anisotropic GGX (KHR_materials_anisotropy: alpha_t = mix(alpha, 1, A^2) along the
//   anisotropy direction, alpha_b = alpha = roughness^2), F_d = s Schlick(min(f0 c_s, 1)) per
//   channel (KHR_materials_specular's factor s and colour c_s) and F_m =
//   Schlick(c), each mixed with the thin-film Fresnel by the iridescence factor
//   (KHR_materials_iridescence, thin_film.h).
//   plus, with energy_compensation, Kulla and Conty's multiple-scattering lobe
//     [(1 - m) F_ms,d + m F_ms,m] (1 - E(n.v)) (1 - E(n.l)) / (pi (1 - E_avg))
//   (ggx_albedo.h; F_avg of Schlick per channel, for a volume that of eta's f0; the
//   anisotropic lobe uses the table at sqrt(alpha_t alpha_b)), which makes a white metal's
//   albedo 1 at every roughness. The specular lobe samples it by cosine with probability
//   1 - E(n.v), its visible normals otherwise.
// - base, transmission (l below the surface):
//     (1 - m)(1 - t) d c_d / pi (1 - F_d(|n.v|))(1 - F_d(|n.l|))       diffuse transmission
//   + (1 - m) t c (1 - F) D G2 |v.h||l.h| / (|n.v||n.l| (l.h + v.h/eta)^2 eta^2)
//                                                  rough refraction (Walter et al., EGSR 2007)
//   The refraction lobe exists only for a volume (KHR_materials_volume); then the dielectric F
//   of both lobes is the exact Fresnel of the relative index eta, so light inside meets total
//   internal reflection. Without a volume, transmission is the integrator's thin delta lobe
//   straight through and here only removes the diffuse share t (see path.h).
//
// Reciprocal except for the refraction lobe, which carries radiance's 1/eta^2. Sampling picks
// one lobe by its estimated albedo at wo (every present lobe at least 5% of the time); pdf() is
// the density of the whole mixture, so estimators may combine the three functions freely.

#include "renderer/materials/microfacet.h"

namespace penumbra {

/// A BSDF at one point. Requires a unit shading normal n (on the side of wo), and a unit
/// tangent t perpendicular to it when anisotropy > 0.
struct GltfBsdf {
  Vec3f base_color{1, 1, 1};
  float metallic = 1;
  float roughness = 1;
  Vec3f n{0, 0, 1};
  float f0 = 0.04f;               ///< dielectric reflectance at normal incidence
  float specular = 1;             ///< KHR_materials_specular factor: scales the dielectric Fresnel
  Vec3f specular_color{1, 1, 1};  ///< KHR_materials_specular colour: tints the dielectric f0
  float transmission = 0;         ///< KHR_materials_transmission: share of the diffuse base transmitted
  bool volume = false;            ///< transmission refracts into a volume (the rough lobe above)
  float eta = 1.5f;               ///< relative index behind the surface over in front (volume lobe)
  Vec3f t{1, 0, 0};               ///< anisotropy direction (unit, perpendicular to n)
  float anisotropy = 0;           ///< KHR_materials_anisotropy strength in [0, 1]
  float iridescence = 0;          ///< KHR_materials_iridescence factor in [0, 1]
  float iridescence_ior = 1.3f;
  float iridescence_thickness = 400;  ///< nanometres
  Vec3f sheen_color{0, 0, 0};         ///< KHR_materials_sheen colour (black: no sheen)
  float sheen_roughness = 0;
  float clearcoat = 0;  ///< KHR_materials_clearcoat factor in [0, 1]
  float clearcoat_roughness = 0;
  Vec3f clearcoat_n{0, 0, 0};                 ///< unit coat normal; zero: the shading normal n
  float diffuse_transmission = 0;             ///< KHR_materials_diffuse_transmission factor
  Vec3f diffuse_transmission_color{1, 1, 1};  ///< its colour
  /// Kulla-Conty multiple-scattering compensation of the base's GGX reflection (ggx_albedo.h),
  /// metal and dielectric: the energy single scattering loses at high roughness comes back.
  bool energy_compensation = true;
};

/// Fresnel reflectance of the dielectric layer at cos(theta) = cos_theta: s Schlick(f0), or
/// for a volume s times the exact Fresnel of eta.
float dielectric_fresnel(const GltfBsdf& b, float cos_theta);

/// Weight of the thin-walled transmission the integrator traces straight through (a delta lobe,
/// not part of bsdf_eval) at cos(theta) = cos_theta: (1 - metallic) t (1 - F) base colour per
/// channel (F with the thin film), times the coat's attenuation in and out and the sheen's
/// albedo scaling, as the layers above the base attenuate it.
Vec3f thin_transmission(const GltfBsdf& b, float cos_theta);

/// True if the BSDF scatters light to the far side of the surface (diffuse transmission or
/// the volume's refraction lobe).
inline bool has_transmission_lobes(const GltfBsdf& b) {
  return b.metallic < 1 && (b.diffuse_transmission > 0 || (b.volume && b.transmission > 0));
}

/// f(wo, wi) for wi on either side of the surface; zero if wo is below it.
Vec3f bsdf_eval(const GltfBsdf& b, Vec3f wo, Vec3f wi);
/// The diffuse (reflected and transmitted) and the other terms of bsdf_eval (their sum), for
/// light-group AOVs.
void bsdf_eval_parts(const GltfBsdf& b, Vec3f wo, Vec3f wi, Vec3f& diffuse, Vec3f& specular);
/// bsdf_eval and bsdf_pdf together, sharing the frames and half vectors (pdf is set).
Vec3f bsdf_eval_pdf(const GltfBsdf& b, Vec3f wo, Vec3f wi, float& pdf);
/// Solid-angle density with which bsdf_sample() produces wi (all lobes combined).
float bsdf_pdf(const GltfBsdf& b, Vec3f wo, Vec3f wi);

struct BsdfSample {
  Vec3f wi;
  Vec3f weight;  ///< f |cos(theta_i)| / pdf (0 when the sample fails)
  float pdf = 0;
  bool transmitted = false;  ///< a transmission lobe chose wi (to the far side of the surface)
};
/// Samples wi from u1 (lobe choice) and u (direction), both uniform in [0, 1).
/// Returns false (and a zero weight) if wo is below the surface or the sample fails.
bool bsdf_sample(const GltfBsdf& b, Vec3f wo, float u1, Vec2f u, BsdfSample& out);

}  // namespace penumbra
