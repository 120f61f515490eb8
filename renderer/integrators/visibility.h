// The ray queries of every integrator, AOV and light sample: closest visible hit and shadow
// transmittance, which filter the accelerator's hits by material (Mask cut-outs, single-sided
// back faces) with a HitFilter evaluated inside traversal, and composite Blend layers in a loop
// over them; and the one construction of a shadow ray. Accelerators stay material-agnostic (the
// filters and their context live here); materials stay free of ray queries. Gaussian splats, in
// the structure make_scene_accelerator attaches beside the surfaces' (splat_accelerator), are
// gathered along a ray in depth order and blended front to back (3D Gaussian Ray Tracing,
// Moenne-Loccoz et al. 2024).
#pragma once

#include "renderer/accel/accelerator.h"
#include "renderer/film/deep.h"
#include "renderer/scene/interaction.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// Splats gathered per traversal of the splat structure (the k-buffer's size).
inline constexpr int kSplatChunk = 16;
/// Most splats blended along one ray; the rest are left out.
inline constexpr int kMaxSplatsPerRay = 4096;

/// What the Gaussian splats along a ray put in front of what lies behind them.
struct SplatLayer {
  Vec3f radiance{0, 0, 0};  ///< their baked radiance, scene-linear, blended front to back
  float transmittance = 1;  ///< of the light from behind; 0 once below kSplatMinTransmittance
  /// The splat at which the transmittance falls below 1/2 (geom_id = splat instance, prim_id =
  /// splat, t its maximum's distance): the layer's "surface" for depth and ids; invalid if the
  /// transmittance stays at or above 1/2.
  Hit median;
  Hit first;      ///< the nearest splat blended (invalid: none)
  int count = 0;  ///< splats blended
};

/// Where a splat layer stands for a surface (its median splat, else its first): the point at
/// the splat's maximum along `ray`, the splat's shortest axis (the normal of a flat splat's
/// disc; the gradient of the Mahalanobis distance is perpendicular to the ray at the maximum)
/// turned to face the ray, the layer's colour (radiance over opacity) and
/// the splat instance's glTF node (-1 if none). Requires layer.count > 0.
struct SplatPoint {
  Vec3f p, n, color;
  int node = -1;
};
SplatPoint splat_point(const Scene& scene, const SplatLayer& layer, const Ray& ray);

/// The unit world-space shortest axis of splat `splat` of splat instance `instance`, turned to
/// face a ray of direction `dir` (-dir for a singular placement).
Vec3f splat_normal(const Scene& scene, uint32_t instance, uint32_t splat, Vec3f dir);

/// A splat layer as a deep record of weight `weight` x its opacity, at its median (else its
/// first) splat's depth, keyed apart from surfaces (0x80000000 + splat instance) with the
/// instance's glTF node + 1 as object id.
DeepHit splat_deep_hit(const Scene& scene, const SplatLayer& layer, const Ray& ray, const DeepTrace& deep,
                       float weight);

/// The splats of `splats` (a structure over splat_geometry(scene)) along `ray` with their
/// maximum's t in [ray.tnear, min(tend, ray.tfar)]: gathered kSplatChunk at a time in the order
/// of (t, instance, splat) through an always-rejecting HitFilter (the k-buffer), and blended
/// front to back, alpha = the response at its maximum (splat_ray_response) and colour the
/// spherical harmonics seen along the ray's direction in the cloud's space, until the
/// transmittance falls below kSplatMinTransmittance (it is then 0). The same answer for any
/// structure, build order or thread count. Never allocates, throws or logs.
SplatLayer blend_splats(const Scene& scene, const Accelerator& splats, const Ray& ray, float tend);

/// Whether any material in the scene needs the filtered queries below (Mask, Blend or
/// single-sided); when false they reduce to one accelerator call.
bool scene_needs_hit_filter(const Scene& scene);

/// Closest hit that a camera or mirror ray sees: skips Mask texels below the cut-off and the
/// back faces of single-sided materials (glTF doubleSided = false) inside the accelerator's
/// traversal: the plain closest hit if the filter accepts it, else one filtered query, however
/// many surfaces are skipped. Blend surfaces are returned; the integrator composites them.
/// `filter` false: one plain accelerator query.
/// `splats` non-null: set to the splats in front of the returned hit (along the whole ray on a
/// miss) when `accel` carries a splat structure, to an empty layer otherwise. Splats are never
/// returned as `hit`.
bool intersect_visible(const Scene& scene, const Accelerator& accel, const Ray& ray, Hit& hit, bool filter,
                       SplatLayer* splats = nullptr);

/// Fraction of light passing along a shadow ray: 0 if an opaque surface blocks it, else the
/// product of (1 - alpha) over the Blend surfaces it crosses; Mask holes let light through.
/// Back faces cast shadows whatever the material's sidedness. Splats (when `accel` carries
/// them) multiply in their blended transmittance. One filtered occlusion query
/// unless Blend surfaces lie on the ray; those are then visited one by one (at most 1024; more
/// count as opaque).
float shadow_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter);

/// The shadow ray from surface point si towards unit direction wi, offset off the surface
/// along the geometric normal, ending just short of `distance` (kInfinity for lights at
/// infinity).
Ray shadow_ray(const SurfaceInteraction& si, Vec3f wi, float distance);

}  // namespace penumbra
