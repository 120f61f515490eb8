// Material evaluation at a surface point: glTF factors times textures (base colour, alpha,
// metallic-roughness, normal map, occlusion, emission, transmission and the KHR material
// extensions' layers) and vertex colours, the BSDF they make, and
// the coverage (alpha) of a hit for visibility filtering. Evaluation only: the ray queries
// that use it are in integrators/visibility.h.
#pragma once

#include "renderer/materials/bsdf.h"
#include "renderer/scene/interaction.h"

namespace penumbra {

/// A material's values at one surface point.
struct MaterialPoint {
  Vec3f base_color{1, 1, 1};          ///< linear RGB: factor x texture x COLOR_0
  float alpha = 1;                    ///< coverage: factor x texture.a x COLOR_0.a (1 for Opaque)
  float metallic = 1, roughness = 1;  ///< factor x texture (B, G)
  Vec3f emissive{0, 0, 0};            ///< emitted radiance: factor x strength x texture
  float occlusion = 1;                ///< 1 + strength (texture.r - 1); ambient-only (not path traced)
  Vec3f ns;                           ///< unit shading normal after normal mapping, facing the viewer
  bool unlit = false;
  float f0 = 0.04f;               ///< dielectric reflectance at normal incidence, from the ior
  float ior = 1.5f;               ///< KHR_materials_ior
  float specular = 1;             ///< KHR_materials_specular factor x texture (A)
  Vec3f specular_color{1, 1, 1};  ///< KHR_materials_specular colour factor x texture (RGB)
  float transmission = 0;         ///< factor x texture (R)
  bool volume = false;            ///< transmission refracts into a volume (Material::volume)
  Vec3f sigma_a{0, 0, 0};         ///< the volume's absorption coefficient -ln(attenuation colour) / distance
  float dispersion = 0;           ///< KHR_materials_dispersion
  float clearcoat = 0, clearcoat_roughness = 0;
  Vec3f ns_coat;  ///< the coat's unit normal (its normal map over the unmapped shading normal)
  Vec3f sheen_color{0, 0, 0};
  float sheen_roughness = 0;
  float anisotropy = 0;  ///< strength x texture
  Vec3f tangent;         ///< unit anisotropy direction perpendicular to ns (when anisotropy > 0)
  float iridescence = 0, iridescence_ior = 1.3f, iridescence_thickness = 400;
  float diffuse_transmission = 0;
  Vec3f diffuse_transmission_color{1, 1, 1};
};

/// Index of refraction at the representative wavelength of RGB channel `channel` (610, 550 and
/// 465 nm; -1: the base index) under KHR_materials_dispersion's Abbe-number model
/// ior(lambda) = ior + (ior - 1) / V (523655 / lambda^2 - 1.5168), V = 20 / dispersion.
float dispersion_ior(float ior, float dispersion, int channel);

/// The BSDF of a material point for a ray arriving at the front (back_face false) or the back of
/// the surface; `channel` picks the dispersive index (-1: none, see dispersion_ior). A volume of
/// index 1 gets the thin transmission lobe (light goes straight through, the volume still absorbs).
GltfBsdf make_bsdf(const MaterialPoint& mp, bool back_face, int channel);

/// Dielectric reflectance at normal incidence for an index of refraction (glTF's 1.5 gives
/// 0.04): ((ior - 1) / (ior + 1))^2.
inline float ior_to_f0(float ior) {
  const float r = (ior - 1) / (ior + 1);
  return r * r;
}

/// The material used by meshes without one (glTF's default: white, metallic 1, roughness 1).
const Material& default_material();
inline const Material& material_of(const Scene& scene, int material) {
  return material >= 0 ? scene.materials[size_t(material)] : default_material();
}

/// True if evaluating the material reads si's derivatives (it has a texture or a procedural
/// texture); otherwise compute_differentials changes none of its values.
inline bool material_reads_footprint(const Material& m) {
  return m.base_color_tex.texture >= 0 || m.metallic_roughness_tex.texture >= 0 ||
         m.normal_tex.texture >= 0 || m.occlusion_tex.texture >= 0 || m.emissive_tex.texture >= 0 ||
         m.transmission_tex.texture >= 0 || m.procedural >= 0 || m.clearcoat_tex.texture >= 0 ||
         m.clearcoat_roughness_tex.texture >= 0 || m.clearcoat_normal_tex.texture >= 0 ||
         m.sheen_color_tex.texture >= 0 || m.sheen_roughness_tex.texture >= 0 ||
         m.anisotropy_tex.texture >= 0 || m.iridescence_tex.texture >= 0 ||
         m.iridescence_thickness_tex.texture >= 0 || m.diffuse_transmission_tex.texture >= 0 ||
         m.diffuse_transmission_color_tex.texture >= 0;
}

/// Value of a texture reference at si (uv set, KHR_texture_transform, filtered at the level
/// si's UV derivatives select). {1,1,1,1} for ref.texture < 0.
Vec4f eval_texture(const Scene& scene, const TextureRef& ref, const SurfaceInteraction& si);

/// Evaluates every material input at si (si must come from make_interaction; derivatives
/// from compute_differentials are optional). with_occlusion = false leaves occlusion at 1
/// without its texture lookup (for integrators that ignore it). Never allocates.
MaterialPoint eval_material(const Scene& scene, const SurfaceInteraction& si, bool with_occlusion = true);

/// True if eval_emission is the same at every point of a surface of this material (then it is
/// m.emissive): opaque, no emissive texture, no procedural texture.
inline bool emission_is_uniform(const Material& m) {
  return m.alpha_mode == AlphaMode::Opaque && m.emissive_tex.texture < 0 && m.procedural < 0;
}

/// Emitted radiance times coverage at si: eval_material's emissive * alpha, bit for bit,
/// reading only the textures those two need. Never allocates.
Vec3f eval_emission(const Scene& scene, const SurfaceInteraction& si);

/// Coverage of the surface at barycentrics (u, v) of triangle `prim` of instance `instance`: alpha
/// factor x base colour texture alpha (finest level) x COLOR_0 alpha; for a shape instance the
/// alpha factor alone. 1 for Opaque materials.
float eval_alpha(const Scene& scene, uint32_t instance, uint32_t prim, float u, float v);

}  // namespace penumbra
