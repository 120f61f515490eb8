// Whitted integrator (Whitted, "An Improved Illumination Model for Shaded Display", CACM 1980)
// with Blinn-Phong highlights (Blinn 1977).
#include "renderer/whitted.h"

#include "renderer/interaction.h"
#include "renderer/lights.h"

namespace penumbra {

WhittedParams whitted_params(const Material& m) {
  const float metallic = std::clamp(m.metallic, 0.0f, 1.0f);
  const float roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  const Vec3f f0 = Vec3f{0.04f, 0.04f, 0.04f} * (1 - metallic) + m.base_color * metallic;
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

namespace {
const Material kDefaultMaterial{};  // glTF default: white, metallic 1, roughness 1
}

Vec3f whitted_radiance(const Scene& scene, const Accelerator& accel, const WhittedConfig& cfg,
                       const Ray& camera_ray, float& coverage, RayCounts& counts) {
  Vec3f radiance{0, 0, 0};
  Vec3f throughput{1, 1, 1};
  Ray ray = camera_ray;
  coverage = 0;
  ++counts.camera;
  for (int depth = 0;; ++depth) {
    Hit hit;
    if (!accel.intersect(ray, hit)) {
      radiance += throughput * cfg.background;
      break;
    }
    if (depth == 0) coverage = 1;
    const SurfaceInteraction si = make_interaction(scene, ray, hit);
    const Material& mat = si.material >= 0 ? scene.materials[size_t(si.material)] : kDefaultMaterial;
    if (mat.unlit) {  // KHR_materials_unlit: the base colour is the outgoing radiance
      radiance += throughput * mat.base_color;
      break;
    }
    const WhittedParams w = whitted_params(mat);
    const Vec3f v = normalize(-ray.dir);

    // Ambient once, plus emission.
    radiance += throughput * (w.emission + w.ka * cfg.ambient);

    // Direct light: diffuse + Blinn-Phong specular, each light behind a shadow ray.
    for (const Light& light : scene.lights) {
      LightSample ls;
      if (!sample_light(light, si.p, ls)) continue;
      if (dot(ls.wi, si.ng) <= 0) continue;  // light below the geometric surface
      const float ndotl = dot(si.ns, ls.wi);
      if (ndotl <= 0) continue;
      Ray shadow;
      shadow.org = offset_ray_origin(si.p, si.ng, ls.wi);
      shadow.dir = ls.wi;
      shadow.tnear = 0;
      shadow.tfar = std::isfinite(ls.distance) ? ls.distance * (1 - 1e-4f) : kInfinity;
      ++counts.shadow;
      if (accel.occluded(shadow)) continue;
      const Vec3f h = normalize(v + ls.wi);
      const float ndoth = std::max(0.0f, dot(si.ns, h));
      const float spec = (w.exponent + 8) / (8 * kPi) * std::pow(ndoth, w.exponent);
      radiance += throughput * ls.irradiance * (w.kd * (ndotl / kPi) + w.ks * (spec * ndotl));
    }

    // Ideal mirror reflection.
    // Reflections whose weight on the pixel is below min_reflectance are not traced.
    if (depth >= cfg.max_depth || max_component(throughput * w.kr) < cfg.min_reflectance) break;
    Vec3f r = reflect(normalize(ray.dir), si.ns);
    if (dot(r, si.ng) <= 0) r = reflect(normalize(ray.dir), si.ng);
    throughput *= w.kr;
    ray.org = offset_ray_origin(si.p, si.ng, r);
    ray.dir = r;
    ray.tnear = 0;
    ray.tfar = kInfinity;
    ++counts.reflection;
  }
  return radiance;
}

}  // namespace penumbra
