// Whitted integrator (Whitted, "An Improved Illumination Model for Shaded Display", CACM 1980)
// with Blinn-Phong highlights (Blinn 1977) and front-to-back alpha compositing.
#include "renderer/integrators/whitted.h"

#include "renderer/integrators/visibility.h"
#include "renderer/lights/punctual.h"
#include "renderer/materials/sheen.h"
#include "renderer/materials/thin_film.h"

namespace penumbra {

WhittedParams whitted_params(const MaterialPoint& m) {
  const float metallic = std::clamp(m.metallic, 0.0f, 1.0f);
  const float roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  const float t = std::clamp(m.transmission, 0.0f, 1.0f);
  const float d = std::clamp(m.diffuse_transmission, 0.0f, 1.0f);
  const float coat = std::clamp(m.clearcoat, 0.0f, 1.0f);
  const float d0 = m.specular * m.f0;  // 0.04 for the core glTF model
  const Vec3f dc{m.specular * std::min(m.f0 * m.specular_color.x, 1.0f),
                 m.specular * std::min(m.f0 * m.specular_color.y, 1.0f),
                 m.specular * std::min(m.f0 * m.specular_color.z, 1.0f)};
  Vec3f f0 = dc * (1 - metallic) + m.base_color * metallic;
  if (m.iridescence > 0)
    f0 = f0 * (1 - m.iridescence) +
         iridescence_fresnel(1, m.iridescence_ior, 1, m.iridescence_thickness, f0) * m.iridescence;
  WhittedParams w;
  w.kd = m.base_color * ((1 - metallic) * (1 - t) * (1 - d) * (1 - 0.04f * coat));
  if (max_component(m.sheen_color) > 0) w.kd += m.sheen_color * sheen_albedo(1, m.sheen_roughness);
  w.ka = w.kd;
  const float coat_mirror = 0.04f * coat * (1 - m.clearcoat_roughness) * (1 - m.clearcoat_roughness);
  w.ks = f0 + Vec3f{0.04f, 0.04f, 0.04f} * coat;
  const float alpha = std::max(roughness * roughness, 1e-3f);
  w.exponent = std::clamp(2.0f / (alpha * alpha) - 2.0f, 1.0f, 10000.0f);
  w.kr = f0 * ((1 - roughness) * (1 - roughness)) + Vec3f{coat_mirror, coat_mirror, coat_mirror};
  w.emission = m.emissive;
  w.kt = m.base_color * ((1 - metallic) * t * (1 - d0));
  w.kdt = m.diffuse_transmission_color * ((1 - metallic) * (1 - t) * d);
  w.ior = m.volume ? std::max(1.0f, m.ior) : 1.0f;
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
  mp.specular_color = m.specular_color;
  mp.ior = m.ior;
  mp.transmission = m.transmission;
  mp.volume = m.volume && m.transmission > 0;
  mp.clearcoat = m.clearcoat;
  mp.clearcoat_roughness = m.clearcoat_roughness;
  mp.sheen_color = m.sheen_color;
  mp.sheen_roughness = m.sheen_roughness;
  mp.iridescence = m.iridescence;
  mp.iridescence_ior = m.iridescence_ior;
  mp.iridescence_thickness = m.iridescence_thickness_max;
  mp.diffuse_transmission = m.diffuse_transmission;
  mp.diffuse_transmission_color = m.diffuse_transmission_color;
  return whitted_params(mp);
}

float ShadowRayVisibility::transmittance(const void* context, int, const SurfaceInteraction& si,
                                         const LightSample& ls, RayCounts& counts) {
  const auto& c = *static_cast<const ShadowRayVisibility*>(context);
  ++counts.shadow;
  return shadow_transmittance(c.scene, c.accel, shadow_ray(si, ls.wi, ls.distance), c.hit_filter);
}

Vec3f whitted_local(const Scene& scene, const WhittedConfig& cfg, const SurfaceInteraction& si,
                    const MaterialPoint& mp, const WhittedParams& w, Vec3f v,
                    const LightVisibility& visibility, RayCounts& counts) {
  // Ambient (scaled by the occlusion texture) plus emission.
  Vec3f radiance = w.emission + w.ka * cfg.ambient * mp.occlusion;
  // Direct light: diffuse + Blinn-Phong specular, each light as visible as `visibility` says.
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    LightSample ls;
    Light moved;
    if (!sample_light(light_at(scene, i, si.time, moved), si.p, ls)) continue;
    const float ndotl = dot(mp.ns, ls.wi);
    const bool from_back = dot(ls.wi, si.ng) <= 0;  // light below the geometric surface
    if (from_back != (ndotl <= 0) || (from_back && !(max_component(w.kdt) > 0))) continue;
    const float transmittance = visibility.transmittance(visibility.context, int(i), si, ls, counts);
    if (!(transmittance > 0)) continue;
    if (from_back) {
      radiance += ls.irradiance * w.kdt * (transmittance * -ndotl / kPi);
      continue;
    }
    const Vec3f h = normalize(v + ls.wi);
    const float ndoth = std::max(0.0f, dot(mp.ns, h));
    const float spec = (w.exponent + 8) / (8 * kPi) * std::pow(ndoth, w.exponent);
    radiance += ls.irradiance * transmittance * (w.kd * (ndotl / kPi) + w.ks * (spec * ndotl));
  }
  return radiance;
}

namespace {

struct Tracer {
  const Scene& scene;
  const Accelerator& accel;
  const WhittedConfig& cfg;
  RayCounts& counts;
  DeepTrace* deep = nullptr;  // the camera ray's layers, when recorded

  // Radiance along `ray`; `weight` is the ray's contribution to the pixel (for pruning);
  // `coverage` (may be null) receives the composited coverage of this ray.
  Vec3f trace(const Ray& ray, const RayDifferential& rd, int depth, int layers, Vec3f weight,
              float* coverage) {
    Hit hit;
    SplatLayer splats;
    const bool found = intersect_visible(scene, accel, ray, hit, cfg.hit_filter, &splats);
    if (splats.count == 0) return shade(ray, rd, depth, layers, weight, coverage, found, hit);
    // Gaussian splats in front: their baked radiance over what lies behind them.
    if (coverage && deep) deep->add(splat_deep_hit(scene, splats, ray, *deep, weight.x));
    float behind_coverage = 0;
    Vec3f behind{0, 0, 0};
    if (splats.transmittance > 0)
      behind = shade(ray, rd, depth, layers, weight * splats.transmittance,
                     coverage ? &behind_coverage : nullptr, found, hit);
    if (coverage) *coverage = 1 - splats.transmittance + splats.transmittance * behind_coverage;
    return splats.radiance + behind * splats.transmittance;
  }

  // Radiance along `ray` from its visible surface `hit` (found false: the background).
  Vec3f shade(const Ray& ray, const RayDifferential& rd, int depth, int layers, Vec3f weight, float* coverage,
              bool found, const Hit& hit) {
    if (!found) {
      if (coverage) *coverage = 0;
      // On the camera ray's chain of Blend layers all weights are the transmittance in front.
      if (coverage && deep && max_component(cfg.background) > 0)
        deep->add({0, 0, kInfinity, 0, cfg.background * weight.x, {}, {}});
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
    if (mp.unlit) {  // KHR_materials_unlit
      if (coverage && deep) record(si, mp, mp.base_color, a * weight.x);
      return mp.base_color * a + behind * (1 - a);
    }

    const WhittedParams w = whitted_params(mp);
    const Vec3f v = normalize(-ray.dir);
    const ShadowRayVisibility shadows{scene, accel, cfg.hit_filter};
    constexpr LightVisibility unoccluded{
        [](const void*, int, const SurfaceInteraction&, const LightSample&, RayCounts&) { return 1.0f; },
        nullptr};
    Vec3f radiance =
        whitted_local(scene, cfg, si, mp, w, v, cfg.shadows ? shadows.visibility() : unoccluded, counts);

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
      refl.time = ray.time;
      ++counts.reflection;
      radiance += w.kr * trace(refl, reflect_differential(si, rd, v, n, r), depth + 1, 0, rweight, nullptr);
    }
    radiance += transmitted(ray, rd, si, mp, w, depth, weight * a);
    if (coverage && deep) record(si, mp, radiance, a * weight.x);
    return radiance * a + behind * (1 - a);
  }

  // A layer of the camera ray: its surface, the coverage it takes and the radiance it sends.
  void record(const SurfaceInteraction& si, const MaterialPoint& mp, Vec3f radiance, float taken) {
    const Instance& inst = scene.instances[si.instance];
    deep->add({si.instance + 1, inst.node >= 0 ? uint32_t(inst.node) + 1 : 0, deep->depth_of(si.p), taken,
               radiance * taken, mp.ns, mp.base_color});
  }

  // The ideal transmission: refracted by Snell's law into a volume (total internal reflection
  // sends it back as a mirror ray), straight through a thin wall.
  Vec3f transmitted(const Ray& ray, const RayDifferential& rd, const SurfaceInteraction& si,
                    const MaterialPoint& mp, const WhittedParams& w, int depth, Vec3f weight) {
    const Vec3f tweight = weight * w.kt;
    if (depth >= cfg.max_depth || !(max_component(tweight) >= cfg.min_reflectance)) return {};
    const Vec3f v = normalize(-ray.dir);
    Vec3f dir = -v;
    if (w.ior != 1 && !refract(v, mp.ns, si.back_face ? 1 / w.ior : w.ior, dir)) dir = reflect(-v, mp.ns);
    if ((dot(dir, si.ng) < 0) != (dot(dir, mp.ns) < 0)) return {};
    Ray next;
    next.org = spawn_origin(si, dir);
    next.dir = dir;
    next.time = ray.time;
    ++counts.reflection;
    return w.kt * trace(next, rd, depth + 1, 0, tweight, nullptr);
  }
};

}  // namespace

Vec3f whitted_radiance(const Scene& scene, const Accelerator& accel, const WhittedConfig& cfg,
                       const Ray& camera_ray, const RayDifferential& rd, float& coverage, RayCounts& counts,
                       DeepTrace* deep) {
  ++counts.camera;
  Tracer tracer{scene, accel, cfg, counts, deep};
  return tracer.trace(camera_ray, rd, 0, 0, {1, 1, 1}, &coverage);
}

}  // namespace penumbra
