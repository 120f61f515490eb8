// Alpha- and sidedness-aware ray queries over any accelerator.
#include "renderer/integrators/visibility.h"

#include <limits>

#include "renderer/integrators/scene_accel.h"
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

namespace {
// One splat on a ray, ordered by (t, instance, splat) so that ties fall the same way in every
// structure.
struct SplatKey {
  float t;
  uint32_t instance, splat;
};

bool before(const SplatKey& a, const SplatKey& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.instance != b.instance) return a.instance < b.instance;
  return a.splat < b.splat;
}

// The k-buffer: the kSplatChunk first splats after `after` offered so far, in order.
struct SplatChunk {
  SplatKey after{-std::numeric_limits<float>::infinity(), 0, 0};
  SplatKey keys[kSplatChunk];
  int n = 0;
};

// Rejects every hit (so the traversal offers all of them), keeping the first kSplatChunk after
// the last chunk's end. A splat offered twice (duplicated references) is kept once.
bool collect_splat(const void* context, const Ray&, const Hit& hit) {
  auto& c = *const_cast<SplatChunk*>(static_cast<const SplatChunk*>(context));
  const SplatKey k{hit.t, hit.geom_id, hit.prim_id};
  if (!before(c.after, k)) return false;
  if (c.n == kSplatChunk && !before(k, c.keys[kSplatChunk - 1])) return false;
  int at = c.n < kSplatChunk ? c.n : kSplatChunk - 1;
  for (int i = 0; i < c.n; ++i)
    if (c.keys[i].t == k.t && c.keys[i].instance == k.instance && c.keys[i].splat == k.splat) return false;
  if (c.n < kSplatChunk) ++c.n;
  while (at > 0 && before(k, c.keys[at - 1])) {
    c.keys[at] = c.keys[at - 1];
    --at;
  }
  c.keys[at] = k;
  return false;
}

// The ray in a splat instance's cloud space (the same t along it).
Ray to_cloud(const Ray& ray, const Affine3f& to_world) {
  Affine3f inv;
  if (!inverse(to_world, inv)) return Ray{{}, 0, {}, -1};
  Ray r = ray;
  r.org = apply_point(inv, ray.org);
  r.dir = apply_vector(inv, ray.dir);
  return r;
}
}  // namespace

SplatLayer blend_splats(const Scene& scene, const Accelerator& splats, const Ray& ray, float tend) {
  SplatLayer layer;
  Ray r = ray;
  r.tfar = std::min(tend, ray.tfar);
  if (!(r.tnear <= r.tfar)) return layer;
  SplatChunk chunk;
  const HitFilter filter{&collect_splat, &chunk};
  uint32_t cached = UINT32_MAX;  // the instance whose cloud-space ray `local` is
  Ray local;
  while (layer.count < kMaxSplatsPerRay) {
    chunk.n = 0;
    splats.occluded(r, filter);
    for (int i = 0; i < chunk.n; ++i) {
      const SplatKey& k = chunk.keys[i];
      const SplatInstance& inst = scene.splat_instances[k.instance];
      const SplatCloud& cloud = scene.splat_clouds[size_t(inst.cloud)];
      if (k.instance != cached) {
        local = to_cloud(ray, inst.to_world);
        cached = k.instance;
      }
      float t = 0, alpha = 0;
      if (!splat_ray_response(cloud, k.splat, local, t, alpha) || !(alpha > 0)) continue;
      alpha = std::min(alpha, 1.0f);
      const Vec3f color =
          splat_linear_color(cloud.color_space, splat_sh_color(cloud, k.splat, normalize(local.dir)));
      layer.radiance += color * (layer.transmittance * alpha);
      const float before_t = layer.transmittance;
      layer.transmittance *= 1 - alpha;
      ++layer.count;
      if (layer.count == 1) layer.first = Hit{k.t, 0, 0, k.instance, k.splat};
      if (before_t >= 0.5f && layer.transmittance < 0.5f) {
        layer.median.t = k.t;
        layer.median.geom_id = k.instance;
        layer.median.prim_id = k.splat;
      }
      if (layer.transmittance < kSplatMinTransmittance) {
        layer.transmittance = 0;
        return layer;
      }
    }
    if (chunk.n < kSplatChunk) break;
    chunk.after = chunk.keys[kSplatChunk - 1];
    r.tnear = std::max(r.tnear, chunk.after.t);
  }
  return layer;
}

Vec3f splat_normal(const Scene& scene, uint32_t instance, uint32_t splat, Vec3f dir) {
  const SplatInstance& inst = scene.splat_instances[instance];
  Affine3f inv;
  Vec3f n = -dir;
  if (inverse(inst.to_world, inv)) {  // the shortest axis: the largest row of S^-1 R^T
    const Shape s = splat_shape(scene.splat_clouds[size_t(inst.cloud)], splat, splat);
    Vec3f axis = s.whiten[0];
    for (const Vec3f& w : s.whiten)
      if (dot(w, w) > dot(axis, axis)) axis = w;
    n = apply_normal(inv, axis);
  }
  if (!(dot(n, n) > 0) || !is_finite(n)) n = -dir;
  n = normalize(n);
  return dot(n, dir) > 0 ? -n : n;
}

SplatPoint splat_point(const Scene& scene, const SplatLayer& layer, const Ray& ray) {
  const Hit& h = layer.median.valid() ? layer.median : layer.first;
  SplatPoint out;
  out.p = ray.org + ray.dir * h.t;
  out.node = scene.splat_instances[h.geom_id].node;
  const float opacity = 1 - layer.transmittance;
  out.color = opacity > 0 ? layer.radiance / opacity : Vec3f{};
  out.n = splat_normal(scene, h.geom_id, h.prim_id, ray.dir);
  return out;
}

DeepHit splat_deep_hit(const Scene& scene, const SplatLayer& layer, const Ray& ray, const DeepTrace& deep,
                       float weight) {
  const Hit& h = layer.median.valid() ? layer.median : layer.first;
  DeepHit d;
  if (!h.valid()) return d;
  const int node = scene.splat_instances[h.geom_id].node;
  d.key = 0x80000000u + h.geom_id;
  d.object = node >= 0 ? uint32_t(node) + 1 : 0;
  d.depth = deep.depth_of(ray.org + ray.dir * h.t);
  d.weight = (1 - layer.transmittance) * weight;
  d.radiance = layer.radiance * weight;
  return d;
}

bool scene_needs_hit_filter(const Scene& scene) {
  for (const auto& inst : scene.instances) {
    const Material& m = material_of(scene, instance_material(scene, inst));
    if (m.alpha_mode != AlphaMode::Opaque || !m.double_sided) return true;
  }
  return false;
}

namespace {
bool intersect_surface(const Scene& scene, const Accelerator& accel, const Ray& ray, Hit& hit, bool filter) {
  if (!accel.intersect(ray, hit)) return false;
  if (!filter) return true;
  // The plain closest hit is the answer when the filter accepts it, the common case (glTF
  // materials are single-sided by default, and most rays meet front faces): one filter call
  // instead of one per candidate. Otherwise the filtered query finds the closest accepted hit.
  if (accept_visible(&scene, ray, hit)) return true;
  hit = Hit{};
  return accel.intersect(ray, hit, HitFilter{&accept_visible, &scene});
}

float surface_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter);
}  // namespace

bool intersect_visible(const Scene& scene, const Accelerator& accel, const Ray& ray, Hit& hit, bool filter,
                       SplatLayer* splats) {
  const bool found = intersect_surface(scene, accel, ray, hit, filter);
  if (splats) {
    *splats = SplatLayer{};
    const Accelerator* s = scene.splat_instances.empty() ? nullptr : splat_accelerator(accel);
    if (s) *splats = blend_splats(scene, *s, ray, found ? hit.t : ray.tfar);
  }
  return found;
}

float shadow_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter) {
  const float t = surface_transmittance(scene, accel, ray, filter);
  if (!(t > 0)) return 0;
  const Accelerator* s = scene.splat_instances.empty() ? nullptr : splat_accelerator(accel);
  return s ? t * blend_splats(scene, *s, ray, ray.tfar).transmittance : t;
}

namespace {
float surface_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray, bool filter) {
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
}  // namespace

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
