// First-hit data AOVs.
#include "renderer/integrators/aov.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/parallel.h"
#include "renderer/film/denoise.h"
#include "renderer/integrators/visibility.h"
#include "renderer/materials/material.h"

namespace penumbra {

DataAovs make_data_aovs(const PixelWindow& win, bool halves) {
  DataAovs a;
  a.width = win.width();
  a.height = win.height();
  const size_t n = size_t(a.width) * size_t(a.height);
  a.albedo.assign(n * 3, 0.0f);
  a.normal.assign(n * 3, 0.0f);
  a.position.assign(n * 3, 0.0f);
  a.uv.assign(n * 2, 0.0f);
  a.depth.assign(n, kInfinity);
  a.object_id.assign(n, 0.0f);
  a.material_id.assign(n, 0.0f);
  if (halves) a.halves.assign(n * 2 * kDenoiseFeatures, 0.0f);
  return a;
}

void AovPixel::clear() {
  m_albedo = m_normal = m_position = Vec3f{};
  m_uv = Vec2f{};
  m_hits = 0;
  m_depth = kInfinity;
  m_objects.clear();
  m_materials.clear();
  for (int h = 0; h < 2; ++h) {
    m_half_samples[h] = m_half_hits[h] = 0;
    m_half_albedo[h] = m_half_normal[h] = Vec3f{};
    m_half_depth[h] = kInfinity;
  }
}

void AovPixel::add_miss(uint32_t s) {
  m_objects.push_back(0);
  m_materials.push_back(0);
  // The halves see the background as white: an edge's albedo is then the same blend of the
  // object's and the background's as its colour, which a first-order fit can follow.
  ++m_half_samples[s & 1u];
  m_half_albedo[s & 1u] += Vec3f{1, 1, 1};
}

void AovPixel::add_hit(const Scene& scene, const SurfaceInteraction& si, const MaterialPoint& mp, float depth,
                       uint32_t s, const DenoiseFeature* feature) {
  const int h = int(s & 1u);
  ++m_half_samples[h];
  if (!feature || feature->hit) {
    ++m_half_hits[h];
    m_half_albedo[h] += feature ? feature->albedo : mp.base_color;
    m_half_normal[h] += feature ? feature->normal : mp.ns;
    m_half_depth[h] = std::min(m_half_depth[h], feature ? feature->depth : depth);
  }
  m_albedo += mp.base_color;
  m_normal += mp.ns;
  m_position += si.p;
  m_uv = {m_uv.x + si.uv[0].x, m_uv.y + si.uv[0].y};
  ++m_hits;
  m_depth = std::min(m_depth, depth);
  const Instance& inst = scene.instances[si.instance];
  m_objects.push_back(inst.node >= 0 ? uint32_t(inst.node) + 1 : 0);
  const int m = instance_material(scene, inst);
  m_materials.push_back(m >= 0 ? uint32_t(m) + 1 : 0);
}

void AovPixel::add_splats(Vec3f p, Vec3f n, Vec3f albedo, float depth, int node, uint32_t s) {
  const int h = int(s & 1u);
  ++m_half_samples[h];
  ++m_half_hits[h];
  m_half_albedo[h] += albedo;
  m_half_normal[h] += n;
  m_half_depth[h] = std::min(m_half_depth[h], depth);
  m_albedo += albedo;
  m_normal += n;
  m_position += p;
  ++m_hits;
  m_depth = std::min(m_depth, depth);
  m_objects.push_back(node >= 0 ? uint32_t(node) + 1 : 0);
  m_materials.push_back(0);
}

namespace {
// The most frequent id (ties: the smaller one).
float majority(std::vector<uint32_t>& ids) {
  std::sort(ids.begin(), ids.end());
  uint32_t best = 0;
  size_t best_count = 0;
  for (size_t k = 0; k < ids.size();) {
    size_t e = k;
    while (e < ids.size() && ids[e] == ids[k]) ++e;
    if (e - k > best_count) {
      best = ids[k];
      best_count = e - k;
    }
    k = e;
  }
  return float(best);
}
}  // namespace

void AovPixel::store(DataAovs& a, size_t i, int spp) {
  a.depth[i] = m_depth;
  a.object_id[i] = majority(m_objects);
  a.material_id[i] = majority(m_materials);
  const float inv_spp = 1.0f / float(spp);
  for (int c = 0; c < 3; ++c) a.albedo[i * 3 + size_t(c)] = m_albedo[c] * inv_spp;
  if (m_hits > 0) {
    const float inv = 1.0f / float(m_hits);
    const Vec3f nn = normalize(m_normal);
    const Vec3f pp = m_position * inv;
    for (int c = 0; c < 3; ++c) {
      a.normal[i * 3 + size_t(c)] = nn[c];
      a.position[i * 3 + size_t(c)] = pp[c];
    }
    a.uv[i * 2] = m_uv.x * inv;
    a.uv[i * 2 + 1] = m_uv.y * inv;
  }
  if (a.halves.empty()) return;
  for (int h = 0; h < 2; ++h) {
    // A pixel of one sample has no odd half: the even one stands in for it.
    const int src = m_half_samples[h] > 0 ? h : 0;
    float* f = &a.halves[(i * 2 + size_t(h)) * kDenoiseFeatures];
    const float inv_n = m_half_samples[src] > 0 ? 1.0f / float(m_half_samples[src]) : 0.0f;
    const Vec3f nn = m_half_hits[src] > 0 ? normalize(m_half_normal[src]) : Vec3f{};
    for (int c = 0; c < 3; ++c) {
      f[c] = m_half_albedo[src][c] * inv_n;
      f[3 + c] = nn[c];
    }
    f[6] = m_half_depth[src];
  }
}

DenoiseFeature denoise_feature(const Scene& scene, const Accelerator& accel, const Ray& ray,
                               const SurfaceInteraction& first, const MaterialPoint& first_mp, float depth,
                               bool filter) {
  constexpr int kMaxSmooth = 4;
  DenoiseFeature f;
  Vec3f tint{1, 1, 1};
  SurfaceInteraction si = first;
  MaterialPoint mp = first_mp;
  Ray r = ray;
  float travelled = 0;  // after the first hit
  for (int bounce = 0;; ++bounce) {
    const bool mirror = mp.metallic >= 0.9f && mp.roughness <= 0.1f;
    const bool glass = !mirror && mp.transmission >= 0.9f && mp.roughness <= 0.1f;
    if ((!mirror && !glass) || bounce == kMaxSmooth) {
      f.hit = true;
      f.albedo = tint * (mp.base_color + mp.emissive);  // a light differs from a white wall
      f.normal = first_mp.ns;
      f.depth = depth + travelled;
      return f;
    }
    tint = tint * mp.base_color;
    const Vec3f d = normalize(r.dir);
    Vec3f next = reflect(d, mp.ns);
    if (glass) {  // Snell's law through the shading normal (total internal reflection: reflect)
      const float cosi = std::min(1.0f, -dot(d, mp.ns));
      const float eta = si.back_face ? mp.ior : 1 / mp.ior;
      const float k = 1 - eta * eta * (1 - cosi * cosi);
      if (k >= 0) next = d * eta + mp.ns * (eta * cosi - std::sqrt(k));
    }
    Ray n{spawn_origin(si, next), 0, next, kInfinity, r.time};
    Hit hit;
    if (!intersect_visible(scene, accel, n, hit, filter)) {
      // Reflects the background: the smooth surfaces' own colour (a mirror's texture) and the
      // last one's normal remain the features; the depth is a miss's.
      f.hit = true;
      f.albedo = tint;
      f.normal = first_mp.ns;
      return f;
    }
    travelled += hit.t * length(next);
    si = make_interaction(scene, n, hit);
    mp = eval_material(scene, si);
    r = n;
  }
}

DataAovs render_data_aovs(const Scene& scene, const Accelerator& accel, const Camera& camera,
                          const RenderConfig& config, IntegratorType integrator) {
  const PixelWindow win = render_window(config);
  DataAovs a = make_data_aovs(win, config.halves);
  const bool filter = scene_needs_hit_filter(scene);
  TileScheduler scheduler(win, config.tile_size, config.threads);
  scheduler.for_each_tile([&](const PixelWindow& tile) {
    AovPixel pixel;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = size_t(y - win.y0) * size_t(a.width) + size_t(x - win.x0);
        pixel.clear();
        for (uint32_t s = 0; s < uint32_t(config.spp); ++s) {
          const Ray ray = camera_sample_ray(camera, config, integrator, x, y, s);
          Hit hit;
          SplatLayer splats;
          const bool found = intersect_visible(scene, accel, ray, hit, filter, &splats);
          if (splats.median.valid()) {
            const SplatPoint sp = splat_point(scene, splats, ray);
            pixel.add_splats(sp.p, sp.n, sp.color, dot(sp.p - camera.eye, -camera.w), sp.node, s);
            continue;
          }
          if (!found) {
            pixel.add_miss(s);
            continue;
          }
          const SurfaceInteraction si = make_interaction(scene, ray, hit);
          const MaterialPoint mp = eval_material(scene, si);
          const float depth = dot(si.p - camera.eye, -camera.w);
          if (a.halves.empty()) {
            pixel.add_hit(scene, si, mp, depth, s);
          } else {
            const DenoiseFeature f = denoise_feature(scene, accel, ray, si, mp, depth, filter);
            pixel.add_hit(scene, si, mp, depth, s, &f);
          }
        }
        pixel.store(a, i, config.spp);
      }
  });
  return a;
}

namespace {

/// Blend layers a camera sample passes through before its remaining weight counts as the last
/// surface's (as the Whitted integrator's max_blend_layers).
constexpr int kMaxBlendLayers = 16;

}  // namespace

CryptoImage render_cryptomatte(const Scene& scene, const Accelerator& accel, const Camera& camera,
                               const RenderConfig& config, IntegratorType integrator,
                               const std::vector<CryptoLayerIds>& layers, int depth) {
  CryptoImage img;
  const PixelWindow win = render_window(config);
  img.width = win.width();
  img.height = win.height();
  img.depth = depth;
  img.channels = 4 * ((depth + 1) / 2);
  const size_t n = size_t(img.width) * size_t(img.height);
  img.layers.assign(layers.size(), std::vector<float>(n * size_t(img.channels), 0.0f));
  const bool filter = scene_needs_hit_filter(scene);
  // A sample's weight is split over the Blend layers it passes, in kSlots equal slots.
  constexpr uint32_t kSlots = 8;
  TileScheduler scheduler(win, config.tile_size, config.threads);
  scheduler.for_each_tile([&](const PixelWindow& tile) {
    // Per sample: up to kSlots (instance, weight in slots) entries; expanded into ids whose
    // multiplicity is the weight, so rank_crypto_ids counts coverage in 1/(spp * kSlots) units.
    std::vector<int> hit_instance;
    std::vector<float> ids;
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t i = size_t(y - win.y0) * size_t(img.width) + size_t(x - win.x0);
        hit_instance.clear();
        for (uint32_t s = 0; s < uint32_t(config.spp); ++s) {
          Ray ray = camera_sample_ray(camera, config, integrator, x, y, s);
          float remaining = 1;  // of this sample's weight, not yet given to a surface
          uint32_t given = 0;   // slots handed out
          // Slots up to the cumulative weight given so far (with `a` more of what remains),
          // rounded to the nearest slot, to `id`.
          auto give = [&](float a, int id) {
            const float total = (1 - remaining) + remaining * a;
            const uint32_t upto = std::min(kSlots, uint32_t(std::lround(total * float(kSlots))));
            for (; given < upto; ++given) hit_instance.push_back(id);
            remaining *= 1 - a;
          };
          for (int layer = 0; layer < kMaxBlendLayers && given < kSlots; ++layer) {
            Hit hit;
            SplatLayer splats;
            const bool found = intersect_visible(scene, accel, ray, hit, filter, &splats);
            if (splats.count > 0) {  // the splats in front, as their median (else first) splat's cloud
              const Hit& h = splats.median.valid() ? splats.median : splats.first;
              give(1 - splats.transmittance, int(scene.instances.size() + h.geom_id));
              if (!(remaining > 0)) break;
            }
            if (!found) break;
            const SurfaceInteraction si = make_interaction(scene, ray, hit);
            const float a =
                layer + 1 < kMaxBlendLayers ? std::clamp(eval_material(scene, si).alpha, 0.0f, 1.0f) : 1.0f;
            give(a, int(hit.geom_id));
            if (!(remaining > 0)) break;
            ray.tnear = std::nextafter(std::max(hit.t, ray.tnear), kInfinity);
          }
          for (; given < kSlots; ++given) hit_instance.push_back(-1);
        }
        for (size_t l = 0; l < layers.size(); ++l) {
          ids.clear();
          for (int inst : hit_instance)
            ids.push_back(inst >= 0 ? layers[l].instance_ids[size_t(inst)] : 0.0f);
          rank_crypto_ids(ids, depth, img.channels, &img.layers[l][i * size_t(img.channels)]);
        }
      }
  });
  return img;
}

}  // namespace penumbra
