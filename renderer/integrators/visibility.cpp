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

// The hit filter of camera and mirror rays (context: the Scene): rejects the back faces of
// single-sided materials and Mask texels below the cut-off.
bool accept_visible(const void* context, const Ray& ray, const Hit& hit) {
  const Scene& scene = *static_cast<const Scene*>(context);
  const Material& m = material_of(scene, instance_material(scene, scene.instances[hit.geom_id]));
  if (!m.double_sided && dot(hit_front_normal(scene, ray, hit), ray.dir) > 0) return false;
  return m.alpha_mode != AlphaMode::Mask || eval_alpha(scene, hit.geom_id, hit.prim_id, hit.u, hit.v) >= 1;
}

// What a shadow ray's filters see: the scene, and whether a partly transparent (Blend) layer was
// offered; set by accept_opaque, whose decisions stay a function of the hit alone.
struct ShadowContext {
  const Scene& scene;
  mutable bool translucent = false;
};

// Accepts the surfaces that stop all light (alpha 1), noting the translucent ones it rejects.
bool accept_opaque(const void* context, const Ray&, const Hit& hit) {
  const auto& c = *static_cast<const ShadowContext*>(context);
  const float alpha = eval_alpha(c.scene, hit.geom_id, hit.prim_id, hit.u, hit.v);
  if (alpha > 0 && alpha < 1) c.translucent = true;
  return alpha >= 1;
}

// Accepts every surface that stops some light (alpha > 0): Mask holes are skipped.
bool accept_covering(const void* context, const Ray&, const Hit& hit) {
  const auto& c = *static_cast<const ShadowContext*>(context);
  return eval_alpha(c.scene, hit.geom_id, hit.prim_id, hit.u, hit.v) > 0;
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
  if (!accel.intersect(ray, hit)) return false;
  if (!filter) return true;
  // The plain closest hit is the answer when the filter accepts it, the common case (glTF
  // materials are single-sided by default, and most rays meet front faces): one filter call
  // instead of one per candidate. Otherwise the filtered query finds the closest accepted hit.
  if (accept_visible(&scene, ray, hit)) return true;
  hit = Hit{};
  return accel.intersect(ray, hit, HitFilter{&accept_visible, &scene});
}

float shadow_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter) {
  if (!filter) return accel.occluded(ray) ? 0.0f : 1.0f;
  // One filtered occlusion query settles opaque blockers and rays crossing only holes. An
  // unoccluded query has been offered every hit in range, so `translucent` is then exact.
  ShadowContext context{scene};
  if (accel.occluded(ray, HitFilter{&accept_opaque, &context})) return 0;
  if (!context.translucent) return 1;
  // Blend layers (and nothing opaque) in the way: the product of (1 - alpha) over them, layer
  // by layer, the holes skipped inside traversal.
  const HitFilter covering{&accept_covering, &context};
  float transmittance = 1;
  Ray r = ray;
  for (int layer = 0; layer < kMaxLayers; ++layer) {
    Hit hit;
    if (!accel.intersect(r, hit, covering)) return transmittance;
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
  r.time = si.time;
  r.tnear = 0;
  r.tfar = std::isfinite(distance) ? distance * (1 - 1e-4f) : kInfinity;
  return r;
}

}  // namespace penumbra
