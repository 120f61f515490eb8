// The physically based path tracer: unidirectional paths with next-event estimation and
// MIS between light and BSDF sampling, Russian roulette, thin transmission and stochastic
// Blend alpha, over the glTF BRDF of materials/bsdf.h.
#pragma once

// The physically based path tracer: unidirectional paths with next-event estimation and
// multiple importance sampling (Veach & Guibas, "Optimally Combining Sampling Techniques for
// Monte Carlo Rendering", SIGGRAPH 1995; power heuristic, beta = 2) between light sampling
// and BSDF sampling, for emissive triangles and the environment; punctual lights are delta
// lights and are always sampled directly. Russian roulette (Arvo & Kirk 1990) after a few
// bounces, optional clamping of indirect light (biased), and the glTF BRDF of materials/bsdf.h.
//
// Transmission (KHR_materials_transmission) is thin-walled: light passes straight through
// the surface (no refraction, roughness ignored for the transmitted part) with weight
// (1 - metallic) x transmission x (1 - F) x base colour, as a delta lobe. Blend alpha is
// stochastic: a Blend surface of coverage a is hit with probability a, else the ray
// continues straight on. Shadow rays see the same visibility as the Whitted integrator
// (integrators/visibility.h): Blend surfaces attenuate, Mask holes pass, transmissive surfaces block.

#include "renderer/accel/accelerator.h"
#include "renderer/core/sampler.h"
#include "renderer/film/deep.h"
#include "renderer/integrators/direct_lighting.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/ray_counts.h"
#include "renderer/materials/material.h"
#include "renderer/scene/interaction.h"

namespace penumbra {

/// Which estimators collect light from emissive triangles and the environment. Mis is the
/// production setting; Bsdf and Light are the single-technique estimators (unbiased too, only
/// noisier) kept for validation and debugging.
enum class LightStrategy : uint8_t { Mis, Bsdf, Light };

/// Path tracer settings with their defaults (validated by the CLI).
struct PathConfig {
  int max_depth = 12;        ///< bounces: light reaching the k-th surface hit (k = 0, 1, ...)
                             ///< counts while k <= max_depth; 0 = direct light only
  int rr_depth = 3;          ///< Russian roulette from this surface hit on
  float clamp_indirect = 0;  ///< > 0: each indirect contribution (light reaching hit k >= 1)
                             ///< is scaled so its largest channel is at most this. Biased;
                             ///< 0 = off (default)
  LightStrategy strategy = LightStrategy::Mis;
  int max_blend_layers = 16;        ///< Blend surfaces passed along one ray segment before the next
                                    ///< counts as opaque
  bool hit_filter = true;           ///< as WhittedConfig::hit_filter
  bool energy_compensation = true;  ///< GltfBsdf::energy_compensation (multiple-scattering GGX)
  LightSampler light_sampler = LightSampler::Power;  ///< how next-event estimation chooses an area light
  int light_samples = 1;  ///< lights chosen (each with its shadow ray) at every vertex, 1..64; the
                          ///< MIS weights of BSDF samples that hit an emitter count all of them
};

/// A camera ray's differentials, made on demand: only a first hit whose material reads texture
/// footprints asks for them. make(ctx) returns them; make == nullptr: none (finest level).
struct LazyDifferential {
  RayDifferential (*make)(const void* ctx) = nullptr;
  const void* ctx = nullptr;
};

/// Radiance along a camera ray (counted as one camera ray; bounce rays are counted as
/// `reflection`, shadow rays as `shadow`). `rd` gives texture footprints at the first hit
/// (may be invalid). `coverage` is 1 if the path hit a surface, 0 if the camera ray escaped
/// (then the environment is returned). Draws its random numbers from `samples`.
/// Non-finite contributions are dropped. With `groups`, also adds each contribution to its
/// light group. With `deep`, records the sample's whole radiance (indirect light included) on the
/// first surface it did not pass (coverage 1), or, escaped, as the background. Thread-safe; never
/// allocates, throws or logs.
Vec3f path_radiance(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                    const PathConfig& cfg, const Ray& camera_ray, const RayDifferential& rd,
                    SampleStream& samples, float& coverage, RayCounts& counts, LightGroups* groups = nullptr,
                    DeepTrace* deep = nullptr);
/// As above, with the differentials made only if the first hit's material reads them.
Vec3f path_radiance(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                    const PathConfig& cfg, const Ray& camera_ray, const LazyDifferential& rd,
                    SampleStream& samples, float& coverage, RayCounts& counts, LightGroups* groups = nullptr,
                    DeepTrace* deep = nullptr);

}  // namespace penumbra
