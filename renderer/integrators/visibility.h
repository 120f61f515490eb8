// The ray queries of every integrator, AOV and light sample: closest visible hit and shadow
// transmittance, which filter the accelerator's hits by material (Mask cut-outs, single-sided
// back faces) with a HitFilter evaluated inside traversal, and composite Blend layers in a loop
// over them; and the one construction of a shadow ray. Accelerators stay material-agnostic (the
// filters and their context live here); materials stay free of ray queries.
#pragma once

#include "renderer/accel/accelerator.h"
#include "renderer/scene/interaction.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// Whether any material in the scene needs the filtered queries below (Mask, Blend or
/// single-sided); when false they reduce to one accelerator call.
bool scene_needs_hit_filter(const Scene& scene);

/// Closest hit that a camera or mirror ray sees: skips Mask texels below the cut-off and the
/// back faces of single-sided materials (glTF doubleSided = false) inside the accelerator's
/// traversal: the plain closest hit if the filter accepts it, else one filtered query, however
/// many surfaces are skipped. Blend surfaces are returned; the integrator composites them.
/// `filter` false: one plain accelerator query.
bool intersect_visible(const Scene& scene, const Accelerator& accel, const Ray& ray, Hit& hit, bool filter);

/// Fraction of light passing along a shadow ray: 0 if an opaque surface blocks it, else the
/// product of (1 - alpha) over the Blend surfaces it crosses; Mask holes let light through.
/// Back faces cast shadows whatever the material's sidedness. One filtered occlusion query
/// unless Blend surfaces lie on the ray; those are then visited one by one (at most 1024; more
/// count as opaque).
float shadow_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter);

/// The shadow ray from surface point si towards unit direction wi, offset off the surface
/// along the geometric normal, ending just short of `distance` (kInfinity for lights at
/// infinity).
Ray shadow_ray(const SurfaceInteraction& si, Vec3f wi, float distance);

}  // namespace penumbra
