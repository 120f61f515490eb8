// Next-event estimation: the one direct-lighting routine of the path tracer, for punctual,
// area and environment lights alike.
#pragma once

// At a surface point it takes one sample of every light kind (each punctual light, one
// emissive triangle or shape chosen by power, one environment direction), brings each to the same form
// (direction, incident radiance, distance, density), and estimates it the same way: BRDF
// value, one shadow ray, the MIS weight against BSDF sampling (none for delta lights).

#include "renderer/accel/accelerator.h"
#include "renderer/core/sampler.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/ray_counts.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"
#include "renderer/materials/bsdf.h"
#include "renderer/scene/interaction.h"

namespace penumbra {

/// What a path tracer needs besides the scene: its lights (built once per render).
struct PathLights {
  const AreaLights* area = nullptr;          ///< may be empty; never null in path_radiance
  const Environment* environment = nullptr;  ///< never null in path_radiance
};

/// One light sample seen from a surface point, whatever the light's kind.
struct IncidentLight {
  Vec3f wi;            ///< unit direction towards the light
  float distance = 0;  ///< to the sampled point (kInfinity: at infinity)
  Vec3f li;            ///< radiance arriving along -wi (irradiance for delta lights)
  float pdf = 1;       ///< solid-angle density of wi; for a delta light 1, or the probability of
                       ///< choosing it when it was chosen among the area lights
  bool delta = true;   ///< a punctual light: no MIS
};

/// Samples of each light kind towards point p; false when the light sends nothing there.
bool sample_incident(const Light& light, Vec3f p, IncidentLight& out);
/// An emissive triangle or shape chosen as `choice` says (from its point p) with u1 and a point
/// on it with u2, where the light is at ray time `time`; li is the emission there times the emitter's
/// coverage (a Blend emitter is hit by BSDF-sampled rays with probability alpha, a Mask hole not at all).
/// False for the emitter's invisible side.
bool sample_incident(const AreaLights& area, const Scene& scene, const LightChoice& choice, float time,
                     float u1, Vec2f u2, IncidentLight& out);
/// An environment direction from u.
bool sample_incident(const Environment& env, Vec2f u, IncidentLight& out);

/// The shading point and path state next-event estimation works on.
struct DirectLightingVertex {
  const SurfaceInteraction& si;
  const GltfBsdf& brdf;  ///< its n is the shading normal
  Vec3f wo;              ///< unit direction towards the previous vertex
  Vec3f beta;            ///< path throughput up to this vertex
  int vertex = 0;        ///< surface hit index along the path (0 = first)
  float bsdf_share = 1;  ///< probability that BSDF sampling here uses the BRDF (MIS weight)
  Vec3f sigma_above{};   ///< absorption of the volume on the geometric normal's side (shadow rays)
  Vec3f sigma_below{};   ///< and on the other side
};

/// Which estimators run, as PathConfig's LightStrategy and hit filter set them.
struct DirectLightingMode {
  bool sample_lights = true;                         ///< sample emissive triangles and the environment here
  bool bsdf_mis = true;                              ///< BSDF sampling also finds them: weight by MIS
  bool hit_filter = true;                            ///< filtered shadow rays (visibility.h)
  LightSampler light_sampler = LightSampler::Power;  ///< how the area-light sample is chosen
  int light_samples = 1;                             ///< area-light samples (>= 1), each weighted 1 / count
};

/// Adds the direct light at v to `out`: every punctual light that is not among the sampled
/// entries of lights.area (every one without sample_lights), then (with sample_lights)
/// mode.light_samples area-light samples (an emissive triangle or shape, or a punctual light
/// divided by its pmf; each density multiplied by the count, as the MIS of a multi-sample
/// technique; each draws 1d + 2d when the scene has sampled emitters) and one environment
/// sample (draws 2d when it emits), each counted as one shadow ray when it reaches the BRDF.
/// Never allocates, throws or logs.
void sample_direct_lighting(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                            const DirectLightingVertex& v, const DirectLightingMode& mode,
                            SampleStream& samples, RayCounts& counts, PathRadiance& out);

/// Power heuristic weight of a technique with density `a` against one with density `b`.
inline float power_heuristic(float a, float b) {
  if (!(a > 0)) return 0;
  if (!std::isfinite(a)) return 1;
  const float r = b / a;
  return 1 / (1 + r * r);
}

}  // namespace penumbra
