// Path tracer with next-event estimation and MIS (see path.h for the model and references).
#include "renderer/integrators/path.h"

#include "renderer/materials/bsdf.h"
#include "renderer/lights/punctual.h"

namespace penumbra {

namespace {

struct PathState {
  Vec3f radiance{0, 0, 0};
  const PathConfig& cfg;
  LightGroups* groups = nullptr;
  Vec3f share0{0, 0, 0};  // diffuse share (per channel) of the direction sampled at hit 0

  // Adds a contribution of light reaching surface hit `vertex` (-1 = the camera itself).
  // `diffuse_share`: the diffuse part's share of a light sample at hit 0 (else share0).
  void add(Vec3f c, int vertex, const Vec3f* diffuse_share = nullptr) {
    if (!is_finite(c)) return;
    if (cfg.clamp_indirect > 0 && vertex >= 1) {
      const float m = max_component(c);
      if (m > cfg.clamp_indirect) c *= cfg.clamp_indirect / m;
    }
    radiance += c;
    if (!groups) return;
    if (vertex < 0) {
      groups->emission += c;
      return;
    }
    const Vec3f d = c * (diffuse_share ? *diffuse_share : share0);
    const Vec3f sp = c - d;
    if (vertex == 0) {
      groups->diffuse_direct += d;
      groups->specular_direct += sp;
    } else {
      groups->diffuse_indirect += d;
      groups->specular_indirect += sp;
    }
  }
};

// Per-channel d / (d + s), 0 where both vanish.
Vec3f diffuse_share(Vec3f d, Vec3f s) {
  Vec3f r;
  for (int c = 0; c < 3; ++c) r[c] = d[c] + s[c] > 0 ? d[c] / (d[c] + s[c]) : 0.0f;
  return r;
}

// The shadow ray from a surface point towards direction wi, up to `distance` (kInfinity
// for lights at infinity).
Ray shadow_ray(const SurfaceInteraction& si, Vec3f wi, float distance) {
  Ray r;
  r.org = offset_ray_origin(si.p, si.ng, wi);
  r.dir = wi;
  r.tnear = 0;
  r.tfar = std::isfinite(distance) ? distance * (1 - 1e-4f) : kInfinity;
  return r;
}

}  // namespace

Vec3f path_radiance(const Scene& scene, const Accelerator& accel, const PathLights& lights,
                    const PathConfig& cfg, const Ray& camera_ray, const RayDifferential& rd,
                    SampleStream& samples, float& coverage, RayCounts& counts,
                    LightGroups* groups) {
  ++counts.camera;
  coverage = 0;
  PathState path{{0, 0, 0}, cfg, groups};
  const AreaLights& area = *lights.area;
  const Environment& env = *lights.environment;
  const bool env_lit = !is_black(env);
  const bool sample_lights = cfg.strategy != LightStrategy::Bsdf;
  const bool bsdf_lights = cfg.strategy != LightStrategy::Light;

  Ray ray = camera_ray;
  ray.dir = normalize(ray.dir);
  Vec3f beta{1, 1, 1};
  float prev_pdf = 0;      // solid-angle density of the direction that produced `ray`
  bool prev_delta = true;  // the camera ray or a delta lobe produced `ray`: no MIS
  int layers = 0;          // Blend surfaces passed on this segment

  for (int vertex = 0;;) {
    Hit hit;
    if (!intersect_visible(scene, accel, ray, hit, cfg.hit_filter)) {
      if (env_lit) {
        float w = 1;
        if (!prev_delta) w = !bsdf_lights ? 0.0f : (sample_lights ? power_heuristic(prev_pdf, env_pdf(env, ray.dir)) : 1.0f);
        if (w > 0) path.add(beta * env_eval(env, ray.dir) * w, vertex - 1);
      }
      break;
    }
    SurfaceInteraction si = make_interaction(scene, ray, hit);
    if (vertex == 0 && layers == 0) compute_differentials(scene, si, rd);
    const MaterialPoint mp = eval_material(scene, si);

    // Blend: hit with probability alpha, else continue along the same ray.
    const float a = layers < cfg.max_blend_layers ? mp.alpha : 1.0f;
    if (a < 1 && samples.get1d() >= a) {
      ray.tnear = std::nextafter(std::max(hit.t, ray.tnear), kInfinity);
      ++layers;
      continue;
    }
    layers = 0;
    if (vertex == 0) coverage = 1;

    // Emission seen by the previous vertex (or the camera).
    if (max_component(mp.emissive) > 0 && !mp.unlit) {
      float w = 1;
      if (!prev_delta) {
        if (!bsdf_lights) {
          w = 0;
        } else if (sample_lights) {
          const float cos_l = std::fabs(dot(si.ng, ray.dir));
          const float pdf_l = cos_l > 0 ? area_light_pdf(area, hit.geom_id, hit.prim_id) * hit.t * hit.t / cos_l : 0.0f;
          w = power_heuristic(prev_pdf, pdf_l);
        }
      }
      if (w > 0) path.add(beta * mp.emissive * w, vertex - 1);
    }
    if (mp.unlit) {  // KHR_materials_unlit: radiance = base colour, no lighting, no bounce
      path.add(beta * mp.base_color, vertex - 1);
      break;
    }
    if (vertex > cfg.max_depth) break;

    GltfBrdf brdf;
    brdf.base_color = mp.base_color;
    brdf.metallic = mp.metallic;
    brdf.roughness = mp.roughness;
    brdf.n = mp.ns;
    brdf.f0 = mp.f0;
    brdf.specular = mp.specular;
    brdf.transmission = std::clamp(mp.transmission, 0.0f, 1.0f);
    const Vec3f wo = -ray.dir;
    auto share_at = [&](Vec3f wi) {  // diffuse share of the BRDF towards wi (light groups)
      Vec3f d, sp;
      brdf_eval_parts(brdf, wo, wi, d, sp);
      return diffuse_share(d, sp);
    };
    // Thin transmission: a delta lobe straight through, chosen with probability p_t.
    const float cos_o = std::fabs(dot(mp.ns, wo));
    const Vec3f trans_weight = mp.base_color * ((1 - mp.metallic) * brdf.transmission * (1 - dielectric_fresnel(brdf, cos_o)));
    // Lobe choice by estimated energy: transmitted vs reflected (Fresnel-weighted specular plus
    // the remaining diffuse) at this view angle.
    float p_t = 0;
    if (brdf.transmission > 0) {
      const float t = luminance(trans_weight);
      const float fd = dielectric_fresnel(brdf, cos_o);
      const float r = (1 - mp.metallic) * (fd + (1 - fd) * (1 - brdf.transmission) * luminance(mp.base_color)) +
                      mp.metallic * luminance(mp.base_color);
      p_t = t + r > 0 ? std::clamp(t / (t + r), 0.0f, 1.0f) : 0.0f;
    }
    const float p_r = 1 - p_t;  // share of the BRDF's (non-delta) sampling

    // Next-event estimation.
    for (const Light& light : scene.lights) {  // punctual lights: delta, always sampled
      LightSample ls;
      if (!sample_light(light, si.p, ls) || dot(ls.wi, si.ng) <= 0) continue;
      const Vec3f f = brdf_eval(brdf, wo, ls.wi);
      if (!(max_component(f) > 0)) continue;
      ++counts.shadow;
      const float t = shadow_transmittance(scene, accel, shadow_ray(si, ls.wi, ls.distance), cfg.hit_filter);
      if (t > 0) {
        const Vec3f share = groups && vertex == 0 ? share_at(ls.wi) : Vec3f{};
        path.add(beta * f * ls.irradiance * (std::max(0.0f, dot(mp.ns, ls.wi)) * t), vertex, groups && vertex == 0 ? &share : nullptr);
      }
    }
    if (sample_lights && !area.pmf.empty()) {
      const float u1 = samples.get1d();
      const Vec2f u2 = samples.get2d();
      AreaLightSample ls;
      if (sample_area_light(area, scene, u1, u2, ls)) {
        const Vec3f d = ls.p - si.p;
        const float dist2 = dot(d, d), dist = std::sqrt(dist2);
        const Vec3f wi = d / dist;
        const float cos_l = dot(ls.ng, wi);  // > 0: the point sees the light's back side
        const Material& lm = material_of(scene, scene.meshes[size_t(scene.instances[ls.instance].mesh)].material);
        const bool visible_side = lm.double_sided || cos_l < 0;
        if (dist2 > 0 && std::isfinite(dist) && visible_side && std::fabs(cos_l) > 0 && dot(wi, si.ng) > 0) {
          float pdf_b = 0;
          const Vec3f f = brdf_eval_pdf(brdf, wo, wi, pdf_b);
          if (max_component(f) > 0) {
            Ray to_light;
            to_light.org = si.p;
            to_light.dir = wi;
            Hit lh;
            lh.t = dist;
            lh.u = ls.u;
            lh.v = ls.v;
            lh.geom_id = ls.instance;
            lh.prim_id = ls.prim;
            // The emission there, times the light's own coverage: a Blend emitter is hit by
            // BSDF-sampled rays with probability alpha, a Mask hole not at all.
            const MaterialPoint lp = eval_material(scene, make_interaction(scene, to_light, lh));
            const Vec3f le = lp.emissive * lp.alpha;
            if (max_component(le) > 0) {
              ++counts.shadow;
              const float t = shadow_transmittance(scene, accel, shadow_ray(si, wi, dist), cfg.hit_filter);
              const float pdf_l = ls.pdf_area * dist2 / std::fabs(cos_l);
              const float w = bsdf_lights ? power_heuristic(pdf_l, p_r * pdf_b) : 1.0f;
              if (t > 0 && w > 0) {
                const Vec3f share = groups && vertex == 0 ? share_at(wi) : Vec3f{};
                path.add(beta * f * le * (std::max(0.0f, dot(mp.ns, wi)) * t * w / pdf_l), vertex, groups && vertex == 0 ? &share : nullptr);
              }
            }
          }
        }
      }
    }
    if (sample_lights && env_lit) {
      Vec3f wi, le;
      float pdf_e = 0;
      if (env_sample(env, samples.get2d(), wi, le, pdf_e) && dot(wi, si.ng) > 0) {
        float pdf_b = 0;
        const Vec3f f = brdf_eval_pdf(brdf, wo, wi, pdf_b);
        if (max_component(f) > 0 && max_component(le) > 0) {
          ++counts.shadow;
          const float t = shadow_transmittance(scene, accel, shadow_ray(si, wi, kInfinity), cfg.hit_filter);
          const float w = bsdf_lights ? power_heuristic(pdf_e, p_r * pdf_b) : 1.0f;
          if (t > 0 && w > 0) {
            const Vec3f share = groups && vertex == 0 ? share_at(wi) : Vec3f{};
            path.add(beta * f * le * (std::max(0.0f, dot(mp.ns, wi)) * t * w / pdf_e), vertex, groups && vertex == 0 ? &share : nullptr);
          }
        }
      }
    }

    // Continue the path.
    const float u_lobe = samples.get1d();
    const Vec2f u_dir = samples.get2d();
    Vec3f wi;
    if (u_lobe < p_t) {
      wi = ray.dir;
      if (vertex == 0) path.share0 = {0, 0, 0};  // transmission counts as specular
      beta *= trans_weight / p_t;
      prev_delta = true;
      prev_pdf = 0;
    } else {
      BrdfSample bs;
      if (!brdf_sample(brdf, wo, (u_lobe - p_t) / p_r, u_dir, bs)) break;
      if (dot(bs.wi, si.ng) <= 0) break;  // below the geometric surface
      wi = bs.wi;
      if (vertex == 0 && groups) path.share0 = share_at(wi);
      beta *= bs.weight / p_r;
      prev_delta = false;
      prev_pdf = p_r * bs.pdf;
    }
    if (!(max_component(beta) > 0) || !is_finite(beta)) break;
    ++vertex;
    if (vertex >= cfg.rr_depth) {  // Russian roulette
      const float q = std::min(1.0f, max_component(beta));
      if (samples.get1d() >= q) break;
      beta = beta / q;
    }
    ray = Ray{};
    ray.org = offset_ray_origin(si.p, si.ng, wi);
    ray.dir = wi;
    ++counts.reflection;
  }
  return path.radiance;
}

}  // namespace penumbra
