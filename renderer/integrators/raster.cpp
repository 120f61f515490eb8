// The raster integrator: visibility buffer from the rasteriser, Whitted local shading, Blend
// compositing, and the data AOVs.
#include "renderer/integrators/raster.h"

#include <atomic>
#include <chrono>
#include <optional>

#include "renderer/integrators/visibility.h"
#include "renderer/raster/shadow_map.h"
#include "renderer/raster/splat_raster.h"

namespace penumbra {

namespace {

Ray camera_view_ray(const void* context, float x, float y) {
  const auto& cv = *static_cast<const CameraView*>(context);
  return raster_ray(cv.camera, cv.raster, x, y);
}

Vec2f camera_sample(const void* context, int x, int y, uint32_t s) {
  return camera_sample_position(*static_cast<const RenderConfig*>(context), IntegratorType::Raster, x, y, s);
}

/// Light visibility from shadow maps.
struct MapVisibility {
  const ShadowMaps& maps;
  static float transmittance(const void* context, int light, const SurfaceInteraction& si, const LightSample&,
                             RayCounts&) {
    return shadow_map_visibility(static_cast<const MapVisibility*>(context)->maps, light, si.p, si.ng);
  }
};

float fully_visible(const void*, int, const SurfaceInteraction&, const LightSample&, RayCounts&) {
  return 1;
}

/// The surface a fragment shows along its sample's camera ray; with step > 0, a triangle's
/// footprint over `step` pixels from the fragment's screen-space barycentric derivatives
/// (for textured materials).
SurfaceInteraction fragment_interaction(const Scene& scene, const CameraView& cv, const RasterFragment& f,
                                        const Ray& ray, float step) {
  Hit hit = f.hit;
  const bool shape = scene.instances[hit.geom_id].shape >= 0;
  if (!shape) hit.t = f.depth / std::max(dot(ray.dir, -cv.camera.w), 1e-30f);
  SurfaceInteraction si = make_interaction(scene, ray, hit);
  if (!shape && step > 0 && material_reads_footprint(material_of(scene, si.material)))
    set_barycentric_differentials(scene, si, {f.duv_dx.x * step, f.duv_dx.y * step},
                                  {f.duv_dy.x * step, f.duv_dy.y * step});
  return si;
}

/// Shades every sample of a tile and writes the pixels' means into the film.
struct Shader {
  const Scene& scene;
  const CameraView& cv;
  const RenderConfig& config;
  const LightVisibility& visibility;
  Film& film;
  std::span<const ProjectedSplat> splats;  // sorted front to back
  const SplatBins& bins;

  // The local radiance of fragment f seen by the camera ray through raster position p.
  Vec3f local(const RasterFragment& f, Vec2f p, const Ray& ray, float step, float& alpha,
              RayCounts& counts) const {
    SurfaceInteraction si = fragment_interaction(scene, cv, f, ray, step);
    if (si.shape >= 0 && material_reads_footprint(material_of(scene, si.material))) {
      const Ray rx = raster_ray(cv.camera, cv.raster, p.x + step, p.y);
      const Ray ry = raster_ray(cv.camera, cv.raster, p.x, p.y + step);
      compute_differentials(scene, si, RayDifferential{true, rx.org, rx.dir, ry.org, ry.dir});
    }
    const MaterialPoint mp = eval_material(scene, si);
    alpha = mp.alpha;
    if (mp.unlit) return mp.base_color;
    const WhittedParams w = whitted_params(mp);
    return whitted_local(scene, config.whitted, si, mp, w, normalize(-ray.dir), visibility, counts);
  }

  void tile(const RasterTile& t, RayCounts& counts) {
    const float step = differential_step(config.spp);
    size_t i = 0;
    for (int y = t.pixels.y0; y < t.pixels.y1; ++y)
      for (int x = t.pixels.x0; x < t.pixels.x1; ++x) {
        Vec3f sum{0, 0, 0};
        float coverage = 0;
        for (int s = 0; s < t.spp; ++s, ++i) {
          const Vec2f p = t.positions[i];
          const Ray ray = raster_ray(cv.camera, cv.raster, p.x, p.y);
          // Front to back: each Blend layer and each splat in front of it takes its alpha of
          // what is left, the opaque surface (or the background) the rest.
          SplatCursor splat = splat_cursor(splats, bins, p);
          float remaining = 1;
          for (uint32_t k = t.blend_begin[i]; k < t.blend_begin[i + 1] && remaining > 0; ++k) {
            const float before = remaining;
            splat.advance(t.blend[k].depth, sum, remaining);
            coverage += before - remaining;
            if (!(remaining > 0)) break;
            float a = 1;
            const Vec3f l = local(t.blend[k], p, ray, step, a, counts);
            if (!(a > 0)) continue;
            sum += l * (remaining * a);
            coverage += remaining * a;
            remaining *= 1 - a;
          }
          const float before = remaining;
          splat.advance(t.opaque[i].hit.valid() ? t.opaque[i].depth : kInfinity, sum, remaining);
          coverage += before - remaining;
          if (!(remaining > 0)) continue;
          if (t.opaque[i].hit.valid()) {
            float a = 1;
            sum += local(t.opaque[i], p, ray, step, a, counts) * remaining;
            coverage += remaining;
          } else {
            sum += config.whitted.background * remaining;
          }
        }
        const float inv = 1.0f / float(t.spp);
        float* px = film.pixel(x - film.origin_x, y - film.origin_y);
        px[0] = sum.x * inv;
        px[1] = sum.y * inv;
        px[2] = sum.z * inv;
        px[3] = coverage * inv;
      }
  }
};

}  // namespace

void make_camera_view(const Camera& camera, int width, int height, CameraView& out) {
  out.camera = camera;
  out.width = width;
  out.height = height;
  out.raster = camera_raster(camera, width, height);
  out.view.view = view_matrix(camera);
  out.view.projection = projection_matrix(camera, float(width) / float(height));
  out.view.far_plane = std::isfinite(camera.zfar);
  out.view.width = width;
  out.view.height = height;
  out.view.ray = &camera_view_ray;
  out.view.ray_context = &out;
}

RasterPass camera_raster_pass(const RenderConfig& config) {
  RasterPass pass;
  pass.window = render_window(config);
  pass.tile_size = config.tile_size;
  pass.threads = config.threads;
  pass.spp = config.spp;
  pass.position = &camera_sample;
  pass.position_context = &config;
  // Whitted's jittered samples stay inside their pixel with the 1-pixel box; other filters
  // reach half their width beyond the pixel's centre.
  pass.margin = std::max(0.0f, 0.5f * config.filter.width - 0.5f) + 0.01f;
  pass.cull_back_faces = true;
  pass.blend = RasterBlend::Layers;
  pass.max_blend_layers = config.whitted.max_blend_layers;
  return pass;
}

Film render_raster(const Scene& scene, const Accelerator* accel, const Camera& camera,
                   const RenderConfig& config, RenderStats* stats, const ProgressFn& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  CameraView cv;
  make_camera_view(camera, config.width, config.height, cv);
  const RasterPass pass = camera_raster_pass(config);
  const PixelWindow win = pass.window;
  Film film = make_film(win.width(), win.height());
  film.origin_x = win.x0;
  film.origin_y = win.y0;
  film.full_width = config.width;
  film.full_height = config.height;

  // Light visibility: shadow rays, shadow maps or none.
  const bool filter = config.whitted.hit_filter && scene_needs_hit_filter(scene);
  std::optional<ShadowRayVisibility> rays;
  ShadowMaps maps;
  std::optional<MapVisibility> map_visibility;
  LightVisibility visibility{&fully_visible, nullptr};
  if (config.raster.shadows == RasterShadows::Ray) {
    rays.emplace(ShadowRayVisibility{scene, *accel, filter});
    visibility = rays->visibility();
  }
  if (config.raster.shadows == RasterShadows::Map) {
    maps = build_shadow_maps(scene, config.raster.shadow_map_size, config.threads);
    map_visibility.emplace(MapVisibility{maps});
    visibility = {&MapVisibility::transmittance, &*map_visibility};
  }

  // Gaussian splats: projected, sorted and binned once for the frame.
  const std::vector<ProjectedSplat> splats =
      project_splats(scene, camera, config.width, config.height, win, pass.margin, config.threads);
  const SplatBins bins = bin_splats(splats, win, pass.margin);

  std::atomic<uint64_t> shadow_rays{0};
  std::atomic<int> done{0};
  const int tiles = TileScheduler(win, config.tile_size, config.threads).tile_count();
  rasterize(scene, cv.view, pass, [&](const RasterTile& tile) {
    Shader shader{scene, cv, config, visibility, film, splats, bins};
    RayCounts counts;
    shader.tile(tile, counts);
    shadow_rays += counts.shadow;
    const int d = ++done;
    if (progress) progress(d, tiles);
  });
  if (stats) {
    stats->rays = RayCounts{0, shadow_rays.load(), 0};
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stats->threads = thread_count(config.threads);
    stats->passes = 1;
    stats->samples = uint64_t(film.width) * uint64_t(film.height) * uint64_t(config.spp);
  }
  return film;
}

DataAovs render_raster_aovs(const Scene& scene, const Camera& camera, const RenderConfig& config) {
  CameraView cv;
  make_camera_view(camera, config.width, config.height, cv);
  const RasterPass pass = camera_raster_pass(config);
  const PixelWindow win = pass.window;
  DataAovs a = make_data_aovs(win);
  const std::vector<ProjectedSplat> splats =
      project_splats(scene, camera, config.width, config.height, win, pass.margin, config.threads);
  const SplatBins bins = bin_splats(splats, win, pass.margin);
  rasterize(scene, cv.view, pass, [&](const RasterTile& t) {
    AovPixel pixel;
    size_t i = 0;
    for (int y = t.pixels.y0; y < t.pixels.y1; ++y)
      for (int x = t.pixels.x0; x < t.pixels.x1; ++x) {
        pixel.clear();
        for (int s = 0; s < t.spp; ++s, ++i) {
          const RasterFragment* f = t.blend_begin[i] < t.blend_begin[i + 1] ? &t.blend[t.blend_begin[i]]
                                    : t.opaque[i].hit.valid()               ? &t.opaque[i]
                                                                            : nullptr;
          const Vec2f p = t.positions[i];
          const Ray ray = raster_ray(camera, cv.raster, p.x, p.y);
          // Splats in front whose transmittance falls below 1/2 stand for the surface.
          SplatCursor splat = splat_cursor(splats, bins, p);
          Vec3f sum{0, 0, 0};
          float remaining = 1;
          splat.advance(f ? f->depth : kInfinity, sum, remaining);
          if (splat.median) {
            const float depth = splat.median->depth;
            const Vec3f at = ray.org + ray.dir * (depth / std::max(dot(ray.dir, -camera.w), 1e-30f));
            const int node = scene.splat_instances[splat.median->instance].node;
            const Vec3f n = splat_normal(scene, splat.median->instance, splat.median->splat, ray.dir);
            pixel.add_splats(at, n, sum / (1 - remaining), depth, node);
            continue;
          }
          if (!f) {
            pixel.add_miss();
            continue;
          }
          const SurfaceInteraction si =
              fragment_interaction(scene, cv, *f, ray, 0);  // finest texels, as traced
          pixel.add_hit(scene, si, eval_material(scene, si), f->depth);
        }
        pixel.store(a, size_t(y - win.y0) * size_t(a.width) + size_t(x - win.x0), config.spp);
      }
  });
  return a;
}

}  // namespace penumbra
