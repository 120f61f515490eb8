// Next-event estimation for punctual, area and environment lights.
#include "renderer/integrators/direct_lighting.h"

#include "renderer/integrators/visibility.h"
#include "renderer/lights/punctual.h"
#include "renderer/materials/material.h"

namespace penumbra {

bool sample_incident(const Light& light, Vec3f p, IncidentLight& out) {
  LightSample ls;
  if (!sample_light(light, p, ls)) return false;
  out = IncidentLight{ls.wi, ls.distance, ls.irradiance, 1.0f, true};
  return true;
}

bool sample_incident(const AreaLights& area, const Scene& scene, const LightChoice& choice, float time,
                     float u1, Vec2f u2, IncidentLight& out) {
  AreaLightSample ls;
  if (!sample_area_light(area, scene, choice, time, u1, u2, ls)) return false;
  const Vec3f p = choice.p;
  if (ls.light >= 0) {  // a punctual light, chosen with probability ls.pdf_area
    Light moved;
    if (!sample_incident(light_at(scene, size_t(ls.light), time, moved), p, out)) return false;
    out.pdf = ls.pdf_area;
    return true;
  }
  const Vec3f d = ls.p - p;
  const float dist2 = dot(d, d), dist = std::sqrt(dist2);
  const Vec3f wi = d / dist;
  const float cos_l = dot(ls.ng, wi);  // > 0: the point sees the light's back side
  const Material& lm = material_of(scene, instance_material(scene, scene.instances[ls.instance]));
  const bool visible_side = lm.double_sided || cos_l < 0;
  if (!(dist2 > 0 && std::isfinite(dist) && visible_side && std::fabs(cos_l) > 0)) return false;
  Vec3f le = lm.emissive;
  if (!emission_is_uniform(lm)) {
    Ray to_light;
    to_light.org = p;
    to_light.dir = wi;
    to_light.time = time;
    Hit lh;
    lh.t = dist;
    lh.u = ls.u;
    lh.v = ls.v;
    lh.geom_id = ls.instance;
    lh.prim_id = ls.prim;
    le = eval_emission(scene, ls.shape ? make_interaction(scene, to_light, lh)
                                       : make_interaction(scene, to_light, lh, ls.tri));
  }
  if (!(max_component(le) > 0)) return false;
  out = IncidentLight{wi, dist, le, ls.pdf_area * dist2 / std::fabs(cos_l), false};
  return true;
}

bool sample_incident(const Environment& env, Vec2f u, IncidentLight& out) {
  Vec3f wi, le;
  float pdf = 0;
  if (!env_sample(env, u, wi, le, pdf) || !(max_component(le) > 0)) return false;
  out = IncidentLight{wi, kInfinity, le, pdf, false};
  return true;
}

namespace {

// One light sample's contribution: BSDF, shadow ray, MIS weight.
void estimate(const Scene& scene, const Accelerator& accel, const DirectLightingVertex& v,
              const DirectLightingMode& mode, const IncidentLight& l, RayCounts& counts, PathRadiance& out) {
  // A light below the geometric surface lights it only through a transmission lobe, and then
  // the shading normal must see it on the same side (else reflected light would leak through).
  const bool below = !(dot(l.wi, v.si.ng) > 0);
  const bool transmits = has_transmission_lobes(v.brdf);
  if (below && !transmits) return;
  if (transmits && below != (dot(l.wi, v.brdf.n) < 0)) return;
  float pdf_b = 0;
  const Vec3f f = bsdf_eval_pdf(v.brdf, v.wo, l.wi, pdf_b);
  if (!(max_component(f) > 0)) return;
  ++counts.shadow;
  const float t = shadow_transmittance(scene, accel, shadow_ray(v.si, l.wi, l.distance), mode.hit_filter);
  const Vec3f sigma = below ? v.sigma_below : v.sigma_above;  // the volume the shadow ray crosses
  const float w = l.delta || !mode.bsdf_mis ? 1.0f : power_heuristic(l.pdf, v.bsdf_share * pdf_b);
  if (!(t > 0 && w > 0)) return;
  const bool split = out.groups && v.vertex == 0;
  const Vec3f share = split ? diffuse_share(v.brdf, v.wo, l.wi) : Vec3f{};
  Vec3f absorbed{1, 1, 1};
  if (max_component(sigma) > 0)
    for (int c = 0; c < 3; ++c) absorbed[c] = std::exp(-sigma[c] * l.distance);
  out.add(v.beta * f * l.li * absorbed * (std::fabs(dot(v.brdf.n, l.wi)) * t * w / l.pdf), v.vertex,
          split ? &share : nullptr);
}

}  // namespace

void sample_direct_lighting(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                            const DirectLightingVertex& v, const DirectLightingMode& mode,
                            SampleStream& samples, RayCounts& counts, PathRadiance& out) {
  IncidentLight l;
  // Every punctual light the area lights do not choose among (all of them without light sampling).
  const std::vector<uint8_t>& sampled = lights.area->sampled;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    if (mode.sample_lights && i < sampled.size() && sampled[i]) continue;
    Light moved;
    if (sample_incident(light_at(scene, i, v.si.time, moved), v.si.p, l))
      estimate(scene, accel, v, mode, l, counts, out);
  }
  if (!mode.sample_lights) return;
  if (!lights.area->pmf.empty()) {
    // n samples of one technique: each an estimate of density n p (Veach 1997, 9.2.2).
    const int n = mode.light_samples;
    for (int k = 0; k < n; ++k) {
      const float u1 = samples.get1d();
      const Vec2f u2 = samples.get2d();
      if (!sample_incident(*lights.area, scene, {v.si.p, v.si.ng, mode.light_sampler}, v.si.time, u1, u2, l))
        continue;
      l.pdf *= float(n);
      estimate(scene, accel, v, mode, l, counts, out);
    }
  }
  if (!is_black(*lights.environment)) {
    if (sample_incident(*lights.environment, samples.get2d(), l))
      estimate(scene, accel, v, mode, l, counts, out);
  }
}

}  // namespace penumbra
