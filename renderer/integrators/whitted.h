// The Whitted integrator: ambient once, per punctual light Lambert diffuse plus Blinn-Phong
// specular behind a shadow ray, and ideal mirror reflection up to a maximum depth. glTF
// metallic-roughness factors map to Whitted coefficients by whitted_params().
#pragma once

#include "renderer/accel/accelerator.h"
#include "renderer/film/deep.h"
#include "renderer/integrators/ray_counts.h"
#include "renderer/lights/punctual.h"
#include "renderer/materials/material.h"
#include "renderer/scene/interaction.h"

namespace penumbra {

/// Whitted coefficients of a surface (all linear RGB, dimensionless).
struct WhittedParams {
  Vec3f ka;        ///< ambient reflectance
  Vec3f kd;        ///< Lambert albedo
  Vec3f ks;        ///< specular reflectance at the highlight
  Vec3f kr;        ///< ideal mirror reflectance
  Vec3f emission;  ///< emitted radiance
  float exponent;  ///< Blinn-Phong exponent p in [1, 10000]
  Vec3f kt;        ///< ideal transmission (refraction for a volume, straight through if thin)
  Vec3f kdt;       ///< diffuse transmission: Lambert albedo of light from behind
  float ior = 1;   ///< index the transmitted ray refracts into (1: straight through)
};

/// The documented mapping from glTF factors (README "Whitted material mapping"):
///   f0 = mix(s d0, base_color, metallic)      specular colour at normal incidence (d0 = 0.04
///        from the ior, s = KHR_materials_specular's factor, 1 by default)
///   kd = ka = base_color x (1 - metallic)
///   ks = f0
///   p  = clamp(2 / alpha^2 - 2, 1, 10000), alpha = roughness^2 (Beckmann-equivalent
///        Blinn-Phong exponent, Walter et al. 2007)
///   kr = f0 x (1 - roughness)^2               smooth metals mirror, smooth plastics glint
///   emission = emissive
/// and for the KHR extensions (c = clearcoat, t = transmission, d = diffuse transmission):
///   f0 is mixed with the thin film's reflectance at normal incidence by the iridescence factor
///   kd = base_color x (1 - metallic)(1 - t)(1 - d)(1 - 0.04 c) + sheenColor x E_sheen(1)
///   ks += 0.04 c, kr += 0.04 c (1 - clearcoatRoughness)^2
///   kt = base_color x (1 - metallic) t (1 - f0), refracting with the ior for a volume
///   kdt = diffuseTransmissionColor x (1 - metallic)(1 - t) d
/// Materials with `unlit` skip all of this: their radiance is base_color.
/// The inputs are the material's values at the shaded point (factors x textures).
WhittedParams whitted_params(const MaterialPoint& m);
/// The same for a material's factors alone (no textures, no vertex colours).
WhittedParams whitted_params(const Material& m);

/// Integrator settings, validated by the CLI.
struct WhittedConfig {
  int max_depth = 5;                   ///< maximum number of mirror bounces (0 = none)
  Vec3f ambient{0.05f, 0.05f, 0.05f};  ///< ambient intensity Ia (radiance units)
  Vec3f background{0, 0, 0};           ///< radiance of rays that escape (alpha stays 0)
  float min_reflectance = 1e-3f;       ///< mirror rays with path weight below this are not traced
  int max_blend_layers = 16;           ///< alpha-blended surfaces composited along one ray; deeper
                                       ///< layers count as opaque
  bool hit_filter = true;              ///< false skips alpha/back-face filtering of hits: a speed-up,
                                       ///< valid only when scene_needs_hit_filter() is false
  bool shadows = true;                 ///< false: every light reaches every surface unoccluded (no
                                       ///< shadow rays), so no object darkens another
};

/// How much of a punctual light reaches a surface point: transmittance(context, light index,
/// si, light sample, counts) in [0, 1] (shadow rays, shadow maps, or none). Thread-safe.
struct LightVisibility {
  float (*transmittance)(const void* context, int light, const SurfaceInteraction& si, const LightSample& ls,
                         RayCounts& counts) = nullptr;
  const void* context = nullptr;
};

/// Light visibility by a shadow ray through the accelerator (shadow_transmittance), counted as
/// a shadow ray: what the Whitted integrator uses.
struct ShadowRayVisibility {
  const Scene& scene;
  const Accelerator& accel;
  bool hit_filter = true;  ///< as WhittedConfig::hit_filter
  static float transmittance(const void* context, int light, const SurfaceInteraction& si,
                             const LightSample& ls, RayCounts& counts);
  LightVisibility visibility() const { return {&ShadowRayVisibility::transmittance, this}; }
};

/// The Whitted integrator's local terms at a surface point seen from unit direction v (towards
/// the viewer): emission + ka Ia occlusion + sum over the scene's lights of the visible
/// fraction of [kd/pi max(0, n.l) + ks (p+8)/(8 pi) max(0, n.h)^p max(0, n.l)] E, and the
/// diffuse transmission of lights behind the surface (see whitted_radiance). No reflection, no
/// transmission, no alpha: the caller composites. Never allocates, throws or logs.
Vec3f whitted_local(const Scene& scene, const WhittedConfig& cfg, const SurfaceInteraction& si,
                    const MaterialPoint& mp, const WhittedParams& w, Vec3f v,
                    const LightVisibility& visibility, RayCounts& counts);

/// Radiance along a camera ray (counted as one camera ray) with its differentials (for texture
/// filtering; may be invalid), and its coverage (1 if it hit opaque geometry, 0 if it
/// escaped, alpha-composited over Blend layers). The outgoing radiance at a hit is
///   L = emission + ka Ia occlusion + sum_lights V E [ kd/pi max(0, n.l)
///                                           + ks (p+8)/(8 pi) max(0, n.h)^p max(0, n.l) ]
///       + kr L(reflected ray)
/// with E the light's irradiance (lights/punctual.h), V its shadow-ray transmittance
/// (integrators/visibility.h) and
/// h = (v + l)/|v + l|; n is the normal-mapped shading normal. A Blend surface of coverage a
/// contributes a L + (1 - a) L(behind), front to back. The 1/pi and (p+8)/(8 pi) factors normalise the lobes
/// so that kd and ks are albedos under glTF's physical light units. With `deep`, each layer the
/// camera ray composites is recorded (its coverage a x the transmittance in front, and its
/// radiance L x that coverage), and a non-black background seen past them. Thread-safe; never
/// allocates, throws or logs.
Vec3f whitted_radiance(const Scene& scene, const Accelerator& accel, const WhittedConfig& cfg,
                       const Ray& camera_ray, const RayDifferential& rd, float& coverage, RayCounts& counts,
                       DeepTrace* deep = nullptr);

}  // namespace penumbra
