// Path tracer with next-event estimation and MIS (see path.h for the model and references),
// in the phases of pbrt-v4's PathIntegrator::Li and Mitsuba 3's path integrator: emitter hit,
// next-event estimation (direct_lighting.h), BSDF sampling, Russian roulette.
#include "renderer/integrators/path.h"

#include "renderer/integrators/direct_lighting.h"
#include "renderer/integrators/visibility.h"

namespace penumbra {

namespace {

// What stays fixed along a path.
struct PathContext {
  const Scene& scene;
  const Accelerator& accel;
  const PathLights& lights;
  const PathConfig& cfg;
  bool env_lit;        // the environment emits
  bool sample_lights;  // light sampling finds emitters and the environment
  bool bsdf_lights;    // BSDF sampling finds them
};

// The ray about to be traced and what produced it.
struct Segment {
  Ray ray;
  Vec3f beta{1, 1, 1};
  float prev_pdf = 0;      // solid-angle density of the direction that produced `ray`
  Vec3f prev_p, prev_n;    // the surface point that produced `ray` and its geometric normal
  bool prev_delta = true;  // the camera ray or a delta lobe produced `ray`: no MIS
  int layers = 0;          // Blend surfaces passed on this segment
  Vec3f sigma_a{0, 0, 0};  // absorption coefficient of the volume the ray travels in
  int channel = -1;        // RGB channel a dispersive volume restricted the path to, -1: none
};

// The BSDF at a hit and the choice between it and thin transmission (a delta lobe straight
// through, chosen with probability p_t; materials without a volume only).
struct Lobes {
  GltfBsdf brdf;
  Vec3f trans_weight;
  float p_t = 0;
  float p_r = 1;  // share of the BSDF's (non-delta) sampling
};

// Emitter hit: the environment seen by a ray that escaped, MIS-weighted against the
// environment sample of the previous vertex.
void add_escaped(const PathContext& ctx, const Segment& seg, int vertex, PathRadiance& path) {
  if (!ctx.env_lit) return;
  const Environment& env = *ctx.lights.environment;
  float w = 1;
  if (!seg.prev_delta)
    w = !ctx.bsdf_lights
            ? 0.0f
            : (ctx.sample_lights ? power_heuristic(seg.prev_pdf, env_pdf(env, seg.ray.dir)) : 1.0f);
  if (w > 0) path.add(seg.beta * env_eval(env, seg.ray.dir) * w, vertex - 1);
}

// Emitter hit: emission of the surface hit, seen by the previous vertex (or the camera),
// MIS-weighted against the area-light sample taken there (a triangle's or a shape's).
void add_emission(const PathContext& ctx, const Segment& seg, const Hit& hit, const SurfaceInteraction& si,
                  const MaterialPoint& mp, int vertex, PathRadiance& path) {
  if (!(max_component(mp.emissive) > 0) || mp.unlit) return;
  float w = 1;
  if (!seg.prev_delta) {
    if (!ctx.bsdf_lights) {
      w = 0;
    } else if (ctx.sample_lights) {
      const float cos_l = std::fabs(dot(si.ng, seg.ray.dir));
      const LightChoice choice{seg.prev_p, seg.prev_n, ctx.cfg.light_sampler};
      const float pdf_a =
          si.shape >= 0
              ? shape_light_pdf(*ctx.lights.area, ctx.scene, choice, hit.geom_id, si.p, seg.ray.time)
              : area_light_pdf(*ctx.lights.area, choice, hit.geom_id, hit.prim_id, si.tri);
      // The light technique took light_samples samples at the previous vertex.
      const float pdf_l = cos_l > 0 ? float(ctx.cfg.light_samples) * pdf_a * hit.t * hit.t / cos_l : 0.0f;
      w = power_heuristic(seg.prev_pdf, pdf_l);
    }
  }
  if (w > 0) path.add(seg.beta * mp.emissive * w, vertex - 1);
}

// The BSDF and, for thin-walled transmission, the transmission/reflection choice by
// estimated energy: transmitted vs reflected (Fresnel-weighted specular plus the remaining
// diffuse) at this view angle.
Lobes choose_lobes(const MaterialPoint& mp, const SurfaceInteraction& si, Vec3f wo, int channel,
                   bool energy_compensation) {
  Lobes l;
  l.brdf = make_bsdf(mp, si.back_face, channel);
  l.brdf.energy_compensation = energy_compensation;
  if (l.brdf.volume || !(l.brdf.transmission > 0)) return l;
  const float cos_o = std::fabs(dot(mp.ns, wo));
  const float fd = dielectric_fresnel(l.brdf, cos_o);
  l.trans_weight = thin_transmission(l.brdf, cos_o);
  const float t = luminance(l.trans_weight);
  const float r = (1 - mp.metallic) * (fd + (1 - fd) * (1 - l.brdf.transmission) * luminance(mp.base_color)) +
                  mp.metallic * luminance(mp.base_color);
  l.p_t = t + r > 0 ? std::clamp(t / (t + r), 0.0f, 1.0f) : 0.0f;
  l.p_r = 1 - l.p_t;
  return l;
}

// A dispersive volume restricts the path to one RGB channel, chosen uniformly (the throughput
// keeps that channel, times 3); the channel's index of refraction then applies (material.h).
void choose_channel(const MaterialPoint& mp, SampleStream& samples, Segment& seg) {
  if (seg.channel >= 0 || !mp.volume || !(mp.dispersion > 0)) return;
  seg.channel = std::min(2, int(samples.get1d() * 3));
  Vec3f keep{0, 0, 0};
  keep[seg.channel] = 3;
  seg.beta *= keep;
}

// BSDF sampling: the next direction (thin transmission or the BSDF), updating the throughput,
// the MIS state and the volume the ray travels in. False when the path ends here.
bool sample_bsdf(const Lobes& lobes, const SurfaceInteraction& si, const MaterialPoint& mp, Vec3f wo,
                 int vertex, SampleStream& samples, Segment& seg, PathRadiance& path, Vec3f& wi) {
  const float u_lobe = samples.get1d();
  const Vec2f u_dir = samples.get2d();
  if (u_lobe < lobes.p_t) {
    wi = seg.ray.dir;
    if (mp.volume) seg.sigma_a = si.back_face ? Vec3f{} : mp.sigma_a;  // through a volume of index 1
    if (vertex == 0) path.share0 = {0, 0, 0};                          // transmission counts as specular
    seg.beta *= lobes.trans_weight / lobes.p_t;
    seg.prev_delta = true;
    seg.prev_pdf = 0;
  } else {
    BsdfSample bs;
    if (!bsdf_sample(lobes.brdf, wo, (u_lobe - lobes.p_t) / lobes.p_r, u_dir, bs)) return false;
    // The geometric surface must agree with the side the lobe chose.
    const bool through = bs.transmitted;
    if ((dot(bs.wi, si.ng) <= 0) != through) return false;
    wi = bs.wi;
    if (through && mp.volume) seg.sigma_a = si.back_face ? Vec3f{} : mp.sigma_a;  // into or out of the volume
    if (vertex == 0 && path.groups) path.share0 = diffuse_share(lobes.brdf, wo, wi);
    seg.beta *= bs.weight / lobes.p_r;
    seg.prev_delta = false;
    seg.prev_pdf = lobes.p_r * bs.pdf;
  }
  return max_component(seg.beta) > 0 && is_finite(seg.beta);
}

// Beer-Lambert transmittance exp(-sigma_a d) over distance d.
Vec3f beer_lambert(Vec3f sigma_a, float d) {
  return {std::exp(-sigma_a.x * d), std::exp(-sigma_a.y * d), std::exp(-sigma_a.z * d)};
}

// Russian roulette (Arvo & Kirk 1990): survive with probability min(1, max beta), reweighted.
bool survives_roulette(SampleStream& samples, Vec3f& beta) {
  const float q = std::min(1.0f, max_component(beta));
  if (samples.get1d() >= q) return false;
  beta = beta / q;
  return true;
}

}  // namespace

Vec3f path_radiance(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                    const PathConfig& cfg, const Ray& camera_ray, const RayDifferential& rd,
                    SampleStream& samples, float& coverage, RayCounts& counts, LightGroups* groups,
                    DeepTrace* deep) {
  const LazyDifferential lazy{[](const void* ctx) { return *static_cast<const RayDifferential*>(ctx); }, &rd};
  return path_radiance(scene, accel, lights, cfg, camera_ray, lazy, samples, coverage, counts, groups, deep);
}

Vec3f path_radiance(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                    const PathConfig& cfg, const Ray& camera_ray, const LazyDifferential& rd,
                    SampleStream& samples, float& coverage, RayCounts& counts, LightGroups* groups,
                    DeepTrace* deep) {
  ++counts.camera;
  DeepHit first;  // the surface the camera ray stops at (key 0: none)
  coverage = 0;
  PathRadiance path;
  path.clamp_indirect = cfg.clamp_indirect;
  path.groups = groups;
  const PathContext ctx{scene,
                        accel,
                        lights,
                        cfg,
                        !is_black(*lights.environment),
                        cfg.strategy != LightStrategy::Bsdf,
                        cfg.strategy != LightStrategy::Light};
  const DirectLightingMode mode{ctx.sample_lights, ctx.bsdf_lights, cfg.hit_filter, cfg.light_sampler,
                                cfg.light_samples};
  Vec3f splats_seen{0, 0, 0};  // what the deep records of splats in front of the camera hold
  Segment seg;
  seg.ray = camera_ray;
  seg.ray.dir = normalize(seg.ray.dir);

  for (int vertex = 0;;) {
    Hit hit;
    SplatLayer splats;
    const bool found = intersect_visible(scene, accel, seg.ray, hit, cfg.hit_filter, &splats);
    if (splats.count > 0) {  // Gaussian splats in front: their baked radiance, as emission
      path.add(seg.beta * splats.radiance, vertex - 1);
      if (vertex == 0) {  // the camera ray: coverage 1 - the transmittance so far
        if (deep) {
          deep->add(splat_deep_hit(scene, splats, seg.ray, *deep, 1 - coverage));
          if (is_finite(splats.radiance)) splats_seen += seg.beta * splats.radiance;
        }
        coverage = 1 - (1 - coverage) * splats.transmittance;
      }
      seg.beta *= splats.transmittance;
      if (!(max_component(seg.beta) > 0)) break;
    }
    if (!found) {
      add_escaped(ctx, seg, vertex, path);
      break;
    }
    if (max_component(seg.sigma_a) > 0) seg.beta *= beer_lambert(seg.sigma_a, hit.t - seg.ray.tnear);
    SurfaceInteraction si = make_interaction(scene, seg.ray, hit);
    if (vertex == 0 && seg.layers == 0 && rd.make &&
        material_reads_footprint(material_of(scene, si.material)))
      compute_differentials(scene, si, rd.make(rd.ctx));
    const MaterialPoint mp = eval_material(scene, si, false);  // occlusion is ambient-only

    // Blend: hit with probability alpha, else continue along the same ray.
    const float a = seg.layers < cfg.max_blend_layers ? mp.alpha : 1.0f;
    if (a < 1 && samples.get1d() >= a) {
      seg.ray.tnear = std::nextafter(std::max(hit.t, seg.ray.tnear), kInfinity);
      ++seg.layers;
      continue;
    }
    seg.layers = 0;
    if (vertex == 0) {
      if (deep) {  // its weight: the transmittance of the splats in front
        const Instance& inst = scene.instances[si.instance];
        first = {si.instance + 1,
                 inst.node >= 0 ? uint32_t(inst.node) + 1 : 0,
                 deep->depth_of(si.p),
                 1 - coverage,
                 {},
                 mp.ns,
                 mp.base_color};
      }
      coverage = 1;
    }

    // Emitter hit.
    add_emission(ctx, seg, hit, si, mp, vertex, path);
    if (mp.unlit) {  // KHR_materials_unlit: radiance = base colour, no lighting, no bounce
      path.add(seg.beta * mp.base_color, vertex - 1);
      break;
    }
    if (vertex > cfg.max_depth) break;

    // Next-event estimation.
    const Vec3f wo = -seg.ray.dir;
    choose_channel(mp, samples, seg);
    const Lobes lobes = choose_lobes(mp, si, wo, seg.channel, cfg.energy_compensation);
    // Shadow rays cross the volume the ray arrived in, or through the surface the volume behind it.
    const Vec3f behind = mp.volume ? (si.back_face ? Vec3f{} : mp.sigma_a) : seg.sigma_a;
    sample_direct_lighting(scene, accel, lights,
                           {si, lobes.brdf, wo, seg.beta, vertex, lobes.p_r, seg.sigma_a, behind}, mode,
                           samples, counts, path);

    // BSDF sampling.
    Vec3f wi;
    if (!sample_bsdf(lobes, si, mp, wo, vertex, samples, seg, path, wi)) break;
    seg.prev_p = si.p;
    seg.prev_n = si.ng;
    ++vertex;

    // Russian roulette.
    if (vertex >= cfg.rr_depth && !survives_roulette(samples, seg.beta)) break;
    seg.ray = Ray{};
    seg.ray.org = spawn_origin(si, wi);
    seg.ray.dir = wi;
    seg.ray.time = si.time;
    ++counts.reflection;
  }
  if (deep && (first.key != 0 || max_component(path.radiance - splats_seen) > 0)) {
    first.radiance = path.radiance - splats_seen;
    if (first.key == 0) first.depth = kInfinity;
    deep->add(first);
  }
  return path.radiance;
}

}  // namespace penumbra
