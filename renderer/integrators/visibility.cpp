// Alpha- and sidedness-aware ray queries over any accelerator.
#include "renderer/integrators/visibility.h"

#include "renderer/materials/material.h"

namespace penumbra {

namespace {
constexpr int kMaxLayers = 1024;

// The same ray, starting just beyond the hit at t (same origin and direction, so the rejected
// triangle reproduces exactly this t and falls outside the new range).
Ray past(const Ray& ray, float t) {
  Ray r = ray;
  r.tnear = std::nextafter(std::max(t, ray.tnear), kInfinity);
  return r;
}
}  // namespace

bool scene_needs_hit_filter(const Scene& scene) {
  for (const auto& inst : scene.instances) {
    const Material& m = material_of(scene, instance_material(scene, inst));
    if (m.alpha_mode != AlphaMode::Opaque || !m.double_sided) return true;
  }
  return false;
}

bool intersect_visible(const Scene& scene, const Accelerator& accel, const Ray& ray, Hit& hit, bool filter) {
  if (!filter) return accel.intersect(ray, hit);
  Ray r = ray;
  for (int layer = 0; layer < kMaxLayers; ++layer) {
    hit = Hit{};
    if (!accel.intersect(r, hit)) return false;
    const Instance& inst = scene.instances[hit.geom_id];
    const Material& m = material_of(scene, instance_material(scene, inst));
    bool skip = false;
    if (!m.double_sided) skip = dot(hit_front_normal(scene, r, hit), r.dir) > 0;
    if (!skip && m.alpha_mode == AlphaMode::Mask)
      skip = eval_alpha(scene, hit.geom_id, hit.prim_id, hit.u, hit.v) < 1;
    if (!skip) return true;
    r = past(ray, hit.t);
  }
  return true;
}

float shadow_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter) {
  if (!filter) return accel.occluded(ray) ? 0.0f : 1.0f;
  if (!accel.occluded(ray)) return 1;  // nothing at all in the way
  float transmittance = 1;
  Ray r = ray;
  for (int layer = 0; layer < kMaxLayers; ++layer) {
    Hit hit;
    if (!accel.intersect(r, hit)) return transmittance;
    transmittance *= 1 - eval_alpha(scene, hit.geom_id, hit.prim_id, hit.u, hit.v);
    if (!(transmittance > 0)) return 0;
    r = past(ray, hit.t);
  }
  return 0;
}

Ray shadow_ray(const SurfaceInteraction& si, Vec3f wi, float distance) {
  Ray r;
  r.org = spawn_origin(si, wi);
  r.dir = wi;
  r.tnear = 0;
  r.tfar = std::isfinite(distance) ? distance * (1 - 1e-4f) : kInfinity;
  return r;
}

}  // namespace penumbra
