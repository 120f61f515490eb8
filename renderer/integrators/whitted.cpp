// Whitted integrator (Whitted, "An Improved Illumination Model for Shaded Display", CACM 1980)
// with Blinn-Phong highlights (Blinn 1977) and front-to-back alpha compositing.
#include "renderer/integrators/whitted.h"

#include "renderer/integrators/visibility.h"
#include "renderer/lights/punctual.h"

namespace penumbra {

WhittedParams whitted_params(const MaterialPoint& m) {
  const float metallic = std::clamp(m.metallic, 0.0f, 1.0f);
  const float roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  const float d0 = m.specular * m.f0;  // 0.04 for the core glTF model
  const Vec3f f0 = Vec3f{d0, d0, d0} * (1 - metallic) + m.base_color * metallic;
  WhittedParams w;
  w.kd = m.base_color * (1 - metallic);
  w.ka = w.kd;
  w.ks = f0;
  const float alpha = std::max(roughness * roughness, 1e-3f);
  w.exponent = std::clamp(2.0f / (alpha * alpha) - 2.0f, 1.0f, 10000.0f);
  w.kr = f0 * ((1 - roughness) * (1 - roughness));
  w.emission = m.emissive;
  return w;
}

WhittedParams whitted_params(const Material& m) {
  MaterialPoint mp;
  mp.base_color = m.base_color;
  mp.metallic = m.metallic;
  mp.roughness = m.roughness;
  mp.emissive = m.emissive;
  mp.f0 = ior_to_f0(m.ior);
  mp.specular = m.specular;
  return whitted_params(mp);
}

namespace {

struct Tracer {
  const Scene& scene;
  const Accelerator& accel;
  const WhittedConfig& cfg;
  RayCounts& counts;

  // Radiance along `ray`; `weight` is the ray's contribution to the pixel (for pruning);
  // `coverage` (may be null) receives the composited coverage of this ray.
  Vec3f trace(const Ray& ray, const RayDifferential& rd, int depth, int layers, Vec3f weight,
              float* coverage) {
    Hit hit;
    if (!intersect_visible(scene, accel, ray, hit, cfg.hit_filter)) {
      if (coverage) *coverage = 0;
      return cfg.background;
    }
    SurfaceInteraction si = make_interaction(scene, ray, hit);
    compute_differentials(scene, si, rd);
    const MaterialPoint mp = eval_material(scene, si);

    // Blend: composite this layer over what lies behind it (same ray, past this hit).
    const float a = layers < cfg.max_blend_layers ? mp.alpha : 1.0f;
    Vec3f behind{0, 0, 0};
    float behind_coverage = 0;
    if (a < 1 && max_component(weight) * (1 - a) >= cfg.min_reflectance) {
      Ray next = ray;
      next.tnear = std::nextafter(std::max(hit.t, ray.tnear), kInfinity);
      behind = trace(next, rd, depth, layers + 1, weight * (1 - a), coverage ? &behind_coverage : nullptr);
    }
    if (coverage) *coverage = a + (1 - a) * behind_coverage;
    if (!(a > 0)) return behind;
    if (mp.unlit) return mp.base_color * a + behind * (1 - a);  // KHR_materials_unlit

    const WhittedParams w = whitted_params(mp);
    const Vec3f v = normalize(-ray.dir);
    // Ambient (scaled by the occlusion texture) plus emission.
    Vec3f radiance = w.emission + w.ka * cfg.ambient * mp.occlusion;

    // Direct light: diffuse + Blinn-Phong specular, each light behind a shadow ray.
    for (const Light& light : scene.lights) {
      LightSample ls;
      if (!sample_light(light, si.p, ls)) continue;
      if (dot(ls.wi, si.ng) <= 0) continue;  // light below the geometric surface
      const float ndotl = dot(mp.ns, ls.wi);
      if (ndotl <= 0) continue;
      ++counts.shadow;
      const float transmittance =
          shadow_transmittance(scene, accel, shadow_ray(si, ls.wi, ls.distance), cfg.hit_filter);
      if (!(transmittance > 0)) continue;
      const Vec3f h = normalize(v + ls.wi);
      const float ndoth = std::max(0.0f, dot(mp.ns, h));
      const float spec = (w.exponent + 8) / (8 * kPi) * std::pow(ndoth, w.exponent);
      radiance += ls.irradiance * transmittance * (w.kd * (ndotl / kPi) + w.ks * (spec * ndotl));
    }

    // Ideal mirror reflection, unless its weight on the pixel is below min_reflectance.
    const Vec3f rweight = weight * w.kr * a;
    if (depth < cfg.max_depth && max_component(rweight) >= cfg.min_reflectance) {
      Vec3f n = mp.ns;
      Vec3f r = reflect(normalize(ray.dir), n);
      if (dot(r, si.ng) <= 0) {
        n = si.ng;
        r = reflect(normalize(ray.dir), n);
      }
      Ray refl;
      refl.org = spawn_origin(si, r);
      refl.dir = r;
      ++counts.reflection;
      radiance += w.kr * trace(refl, reflect_differential(si, rd, v, n, r), depth + 1, 0, rweight, nullptr);
    }
    return radiance * a + behind * (1 - a);
  }
};

}  // namespace

Vec3f whitted_radiance(const Scene& scene, const Accelerator& accel, const WhittedConfig& cfg,
                       const Ray& camera_ray, const RayDifferential& rd, float& coverage, RayCounts& counts) {
  ++counts.camera;
  Tracer tracer{scene, accel, cfg, counts};
  return tracer.trace(camera_ray, rd, 0, 0, {1, 1, 1}, &coverage);
}

}  // namespace penumbra
