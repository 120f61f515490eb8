// Tests for renderer/integrators/raster: MIP levels from screen-space derivatives, the local
// shading against the Whitted integrator without reflections, shadow maps against shadow rays,
// and the cross-check of the raster path's id and Z AOVs against the ray tracer's on the
// shipped scenes and every valid corpus model, away from silhouettes and depth discontinuities.
#include "renderer/integrators/raster.h"

#include <catch2/catch.hpp>
#include <mutex>
#include <sstream>

#include "io/gltf/loader.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/raster/shadow_map.h"
#include "renderer/scene/curve_size.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// Pixels whose 3 x 3 neighbourhood in the traced AOVs has one object id, one material id and
/// no depth discontinuity (neighbouring depths within 5% of each other, or all background):
/// there no sample of the pixel can lie on a silhouette or across a depth step, so both paths
/// must see the same surface.
std::vector<bool> interior_mask(const DataAovs& t) {
  std::vector<bool> m(t.depth.size(), false);
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const size_t i = size_t(y) * size_t(t.width) + size_t(x);
      bool ok = true;
      for (int dy = -1; dy <= 1 && ok; ++dy)
        for (int dx = -1; dx <= 1 && ok; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= t.width || qy >= t.height) continue;
          const size_t j = size_t(qy) * size_t(t.width) + size_t(qx);
          const float a = t.depth[i], b = t.depth[j];
          ok = t.object_id[j] == t.object_id[i] && t.material_id[j] == t.material_id[i] &&
               (std::isinf(a) ? std::isinf(b)
                              : std::isfinite(b) && std::fabs(a - b) <= 0.05f * std::min(a, b));
        }
      m[i] = ok;
    }
  return m;
}

struct CrossCheck {
  int interior = 0, interior_hit = 0, id_wrong = 0, z_wrong = 0;
  std::string first;  ///< the first disagreement, for the report
};

/// The raster path's id and Z AOVs against the ray tracer's (same camera samples).
CrossCheck cross_check(const Scene& scene, const Camera& cam, const RenderConfig& cfg, float z_tolerance) {
  const auto accel = make_scene_accelerator("embree", scene);
  const DataAovs t = render_data_aovs(scene, *accel, cam, cfg, IntegratorType::Raster);
  const DataAovs r = render_raster_aovs(scene, cam, cfg);
  const std::vector<bool> mask = interior_mask(t);
  CrossCheck c;
  for (size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    ++c.interior;
    const bool hit = std::isfinite(t.depth[i]);
    c.interior_hit += hit;
    const bool id_ok = r.object_id[i] == t.object_id[i] && r.material_id[i] == t.material_id[i];
    const bool z_ok =
        hit ? std::fabs(r.depth[i] - t.depth[i]) <= z_tolerance * t.depth[i] : std::isinf(r.depth[i]);
    c.id_wrong += !id_ok;
    c.z_wrong += !z_ok;
    if ((!id_ok || !z_ok) && c.first.empty()) {
      std::ostringstream s;
      s << "pixel " << i % size_t(t.width) << "," << i / size_t(t.width) << ": traced id " << t.object_id[i]
        << "/" << t.material_id[i] << " Z " << t.depth[i] << ", raster id " << r.object_id[i] << "/"
        << r.material_id[i] << " Z " << r.depth[i];
      c.first = s.str();
    }
  }
  return c;
}

/// The camera a render of a loaded scene uses by default: its first camera, else framing.
Camera default_camera(const Scene& s, float aspect) {
  return s.cameras.empty() ? frame_bounds(compute_bounds(s), aspect) : s.cameras[0];
}

/// A texture whose MIP level k is a flat colour (k / 8, 0, 1 - k / 8): 256 x 256, 9 levels.
Texture level_texture() {
  Texture tex;
  tex.name = "levels";
  for (int k = 0, size = 256; k < 9; ++k, size /= 2) {
    MipLevel l;
    l.width = l.height = size;
    const uint16_t r = uint16_t(std::lround(65535.0 * k / 8)), b = uint16_t(65535 - r);
    for (int i = 0; i < size * size; ++i) l.texels.insert(l.texels.end(), {r, 0, b, 65535});
    tex.levels.push_back(std::move(l));
  }
  return tex;
}

/// An unlit quad of [-2, 2]^2 at z = 0 showing level_texture() with UVs over [0, 1]^2.
Scene level_quad() {
  Scene s;
  s.textures.push_back(level_texture());
  const int m = add_material(s, {1, 1, 1}, 0, 1, true);
  s.materials[size_t(m)].base_color_tex.texture = 0;
  add_quad_z(s, -2, 2, -2, 2, 0, m);
  s.meshes[0].uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  return s;
}

}  // namespace

TEST_CASE("raster: MIP level from screen-space UV derivatives", "[raster][quick]") {
  // Orthographic, the quad filling a 64-pixel-wide image: du/dx = 1/64 per pixel, so 256 texels
  // span 4 per pixel: lod = log2(4 x step), step = the differential spacing (1 at 1 spp, 1/2
  // at 4 spp).
  const Scene s = level_quad();
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 2;
  const auto accel = make_scene_accelerator("brute", s);
  for (int spp : {1, 4, 16}) {
    RenderConfig cfg = small_render_config(64, 64, spp, 16);
    cfg.raster.shadows = RasterShadows::None;
    const float lod = std::log2(4.0f * differential_step(spp));
    const Film f = render_raster(s, accel.get(), cam, cfg);
    const float* p = f.pixel(20, 30);
    CHECK(p[0] == Approx(lod / 8).margin(1e-3));
    CHECK(p[2] == Approx(1 - lod / 8).margin(1e-3));
    // The ray tracer's ray differentials choose the same level.
    const Film w = render_whitted(s, *accel, cam, cfg);
    CHECK(w.pixel(20, 30)[0] == Approx(p[0]).margin(1e-3));
  }
  // Perspective, the quad tilted: the level grows with distance, as the ray tracer finds it.
  Scene tilted = level_quad();
  for (Vec3f& p : tilted.meshes[0].positions) p = {p.x, p.y * 0.5f, -p.y * 0.866f};
  const auto accel2 = make_scene_accelerator("brute", tilted);
  const Camera persp = look_at({0, 0.3f, 4}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  RenderConfig cfg = small_render_config(64, 64, 1, 16);
  cfg.raster.shadows = RasterShadows::None;
  const Film r = render_raster(tilted, accel2.get(), persp, cfg),
             w = render_whitted(tilted, *accel2, persp, cfg);
  const DataAovs t = render_data_aovs(tilted, *accel2, persp, cfg, IntegratorType::Raster);
  const std::vector<bool> mask = interior_mask(t);
  int compared = 0, far_above_near = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const size_t i = size_t(y * 64 + x);
      if (!mask[i] || !std::isfinite(t.depth[i])) continue;
      ++compared;
      CHECK(r.pixel(x, y)[0] == Approx(w.pixel(x, y)[0]).margin(0.01));
    }
  CHECK(compared > 500);
  for (int x = 20; x < 44; ++x) far_above_near += r.pixel(x, 22)[0] > r.pixel(x, 50)[0] + 0.05f;
  CHECK(far_above_near > 12);
}

TEST_CASE("raster: local shading equals the Whitted integrator without reflections", "[raster]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  Scene s = l.scene;
  RenderConfig cfg = small_render_config(160, 90, 1, 16);
  const Camera cam = default_camera(s, 160.0f / 90.0f);
  if (s.lights.empty()) s.lights.push_back(default_key_light(cam));
  cfg.whitted.max_depth = 0;
  const auto accel = make_scene_accelerator("embree", s);
  const Film r = render_raster(s, accel.get(), cam, cfg);
  const Film w = render_whitted(s, *accel, cam, cfg);
  const std::vector<bool> mask = interior_mask(render_data_aovs(s, *accel, cam, cfg, IntegratorType::Raster));
  int compared = 0, close = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 160; ++x) {
      if (!mask[size_t(y * 160 + x)]) continue;
      ++compared;
      bool ok = true;
      for (int c = 0; c < 4; ++c)
        ok = ok &&
             std::fabs(r.pixel(x, y)[c] - w.pixel(x, y)[c]) <= 1e-3f + 1e-3f * std::fabs(w.pixel(x, y)[c]);
      close += ok;
    }
  INFO(close << " of " << compared << " interior pixels agree");
  CHECK(compared > 160 * 90 / 2);
  // Shadow rays start from hit points a rounding apart: a pixel on a shadow's edge may differ.
  CHECK(close >= 0.995 * compared);
}

TEST_CASE("raster: shadow maps agree with shadow rays", "[raster]") {
  // A square occluder above a floor under a directional and a point light: the umbra has only
  // ambient, the open floor full light, with either method.
  Scene s;
  const int grey = add_lambert(s, {0.8f, 0.8f, 0.8f});
  add_quad_z(s, -4, 4, -4, 4, 0, grey);
  add_quad_z(s, -1, 1, -1, 1, 1.5f, grey);
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = normalize(Vec3f{0.2f, 0.1f, -1});
  sun.intensity = 3;
  s.lights.push_back(sun);
  s.lights.push_back(point_light({-0.2f, 0.1f, 4}, 20));
  const Camera cam = look_at({0, -6, 7}, {0, 0, 0}, {0, 0, 1}, 0.8f);
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig cfg = small_render_config(120, 90, 1, 16);
  cfg.raster.shadows = RasterShadows::Ray;
  const Film ray = render_raster(s, accel.get(), cam, cfg);
  cfg.raster.shadows = RasterShadows::Map;
  cfg.raster.shadow_map_size = 1024;
  const Film map = render_raster(s, accel.get(), cam, cfg);
  cfg.raster.shadows = RasterShadows::None;
  const Film none = render_raster(s, accel.get(), cam, cfg);
  int pixels = 0, agree = 0, shadowed = 0;
  for (int y = 0; y < 90; ++y)
    for (int x = 0; x < 120; ++x) {
      if (!(ray.pixel(x, y)[3] > 0)) continue;
      ++pixels;
      agree +=
          std::fabs(map.pixel(x, y)[0] - ray.pixel(x, y)[0]) <= 0.02f * std::max(ray.pixel(x, y)[0], 0.05f);
      shadowed += none.pixel(x, y)[0] > ray.pixel(x, y)[0] + 0.05f;
    }
  INFO(agree << " of " << pixels << " pixels agree, " << shadowed << " shadowed");
  CHECK(shadowed > 300);  // the shadows are there to compare
  CHECK(agree >= 0.97 * pixels);
  // The shadow_map_visibility kernel itself: under the occluder's centre, and in the open.
  const ShadowMaps maps = build_shadow_maps(s, 512, 0);
  CHECK(shadow_map_visibility(maps, 0, {0.3f, 0.15f, 0}, {0, 0, 1}) == 0);
  CHECK(shadow_map_visibility(maps, 0, {3, -3, 0}, {0, 0, 1}) == 1);
  CHECK(shadow_map_visibility(maps, 1, {0, 0, 0}, {0, 0, 1}) == 0);
  CHECK(shadow_map_visibility(maps, 1, {-3, 3, 0}, {0, 0, 1}) == 1);
  CHECK(shadow_map_visibility(maps, 1, {0, 0, 1.5f}, {0, 0, 1}) == 1);  // the occluder's top is lit
}

TEST_CASE("raster cross-check: id and Z agree with the ray tracer on the shipped scenes",
          "[raster][crosscheck]") {
  for (const char* name :
       {"default.gltf", "spheres.gltf", "csg.gltf", "procedural.gltf", "flythrough.gltf"}) {
    const LoadedScene l = load_gltf(source_dir() / "scenes" / name);
    RenderConfig cfg = small_render_config(160, 90, 1, 16);
    const CrossCheck c = cross_check(l.scene, default_camera(l.scene, 160.0f / 90.0f), cfg, 1e-3f);
    INFO(name << ": " << c.interior << " interior pixels (" << c.interior_hit << " on surfaces), "
              << c.id_wrong << " with another id, " << c.z_wrong << " with another Z; " << c.first);
    CHECK(c.interior_hit > 160 * 90 / 4);
    CHECK(c.id_wrong == 0);
    CHECK(c.z_wrong == 0);
  }
  // The near plane cutting through the scene: a floor that passes under and behind the camera,
  // and an instanced, mirrored copy of the default scene's geometry seen from inside it.
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  Scene s = l.scene;
  add_quad_z(s, -50, 50, -50, 50, -0.6f, add_lambert(s, {0.5f, 0.5f, 0.5f}));
  const Bounds3f b = compute_bounds(l.scene);
  Camera inside = look_at(b.center(), b.center() + Vec3f{1, -0.1f, -0.4f}, {0, 1, 0}, 1.4f);
  inside.znear = 0.05f * length(b.extent());
  for (const Instance& inst : l.scene.instances) {
    if (inst.shape >= 0) continue;
    Affine3f m = inst.to_world;
    for (int c = 0; c < 4; ++c) m.m[0][c] = -m.m[0][c];  // mirrored in x and moved, so that no
    m.m[0][3] += 0.137f * b.extent().x;                  // surface coincides with the original's
    m.m[2][3] += 0.071f * b.extent().z;
    s.instances.push_back(make_instance(inst.mesh, m, inst.node));
  }
  RenderConfig cfg = small_render_config(160, 90, 1, 16);
  const CrossCheck c = cross_check(s, inside, cfg, 1e-3f);
  INFO("near plane: " << c.interior << " interior pixels, " << c.id_wrong << " id, " << c.z_wrong << " Z; "
                      << c.first);
  CHECK(c.interior_hit > 160 * 90 / 4);
  CHECK(c.id_wrong == 0);
  CHECK(c.z_wrong == 0);
}

TEST_CASE("raster cross-check: id and Z agree with the ray tracer on every valid corpus model",
          "[raster][crosscheck][corpus][heavy]") {
  const auto corpus = corpus_dir();
  if (!corpus) return skip("no corpus (set PENUMBRA_CORPUS)");
  int models = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(*corpus / "valid")) {
    const auto ext = e.path().extension();
    if (!e.is_regular_file() || (ext != ".gltf" && ext != ".glb")) continue;
    const LoadedScene l = load_gltf(e.path());
    if (l.scene.instances.empty()) continue;
    RenderConfig cfg = small_render_config(96, 72, 1, 16);
    const CrossCheck c = cross_check(l.scene, default_camera(l.scene, 96.0f / 72.0f), cfg, 1e-3f);
    INFO(e.path().filename().string()
         << ": " << c.interior << " interior pixels (" << c.interior_hit << " on surfaces), " << c.id_wrong
         << " with another id, " << c.z_wrong << " with another Z; " << c.first);
    CHECK(c.id_wrong == 0);
    CHECK(c.z_wrong == 0);
    ++models;
  }
  CHECK(models >= 30);
}

// ---- Points and lines ---------------------------------------------------------------------------

namespace {

/// A world-space line set over `p` with segments (pairs[2k], pairs[2k + 1]), every radius `radius`.
Mesh line_set(std::vector<Vec3f> p, const std::vector<uint32_t>& pairs, float radius, int material) {
  Mesh m;
  m.name = "lines";
  m.lines = true;
  for (size_t k = 0; k + 1 < pairs.size(); k += 2)
    m.indices.insert(m.indices.end(), {pairs[k], pairs[k + 1], pairs[k + 1]});
  m.radii.assign(p.size(), radius);
  m.normals.assign(p.size(), Vec3f{0, 0, 1});
  m.positions = std::move(p);
  m.material = material;
  return m;
}

/// A world-space point set over `p`, every radius `radius`.
Mesh point_set(std::vector<Vec3f> p, float radius, int material) {
  Mesh m = make_point_set(std::move(p), "points");
  m.radii.assign(m.positions.size(), radius);
  m.material = material;
  return m;
}

/// Looking down -z from z = 10, orthographic with half height `ymag`.
Camera ortho_camera(float ymag) {
  Camera cam = look_at({0, 0, 10}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = ymag;
  return cam;
}

double alpha_sum(const Film& f) {
  double sum = 0;
  for (size_t i = 3; i < f.rgba.size(); i += 4) sum += f.rgba[i];
  return sum;
}

/// Among the pixels where either path sees a point or line set (instances >= `first_curve`),
/// the fraction where both see the same instance.
double curve_id_agreement(const Scene& s, const Camera& cam, const RenderConfig& cfg, float first_curve,
                          int& curve_pixels) {
  const auto accel = make_scene_accelerator("embree", s);
  const DataAovs t = render_data_aovs(s, *accel, cam, cfg, IntegratorType::Raster);
  const DataAovs r = render_raster_aovs(s, cam, cfg);
  int agree = 0;
  curve_pixels = 0;
  for (size_t i = 0; i < t.object_id.size(); ++i) {
    if (!(t.object_id[i] >= first_curve) && !(r.object_id[i] >= first_curve)) continue;
    ++curve_pixels;
    agree += t.object_id[i] == r.object_id[i];
  }
  return curve_pixels ? double(agree) / curve_pixels : 0.0;
}

}  // namespace

TEST_CASE("lines: a horizontal line w pixels wide covers exactly w rows rasterised, w on average traced",
          "[raster][curves][quick]") {
  // Orthographic, one scene unit per pixel, the line a quarter pixel above the boundary between
  // rows 15 and 16 (no pixel centre on its edges) and reaching past both sides of the image.
  const Camera cam = ortho_camera(16);
  for (float w : {1.0f, 2.0f, 3.0f, 4.0f, 2.5f}) {
    Scene s;
    const int m = add_material(s, {1, 1, 1}, 0, 1, true);
    add_world_mesh(s, line_set({{-40, 0.25f, 0}, {40, 0.25f, 0}}, {0, 1}, 0.5f * w, m));
    INFO("width " << w);
    RenderConfig cfg = small_render_config(32, 32, 1, 8);
    cfg.raster.shadows = RasterShadows::None;
    if (w == std::floor(w)) {  // rasterised at the pixel centres: whole rows
      CameraView cv;
      make_camera_view(cam, 32, 32, cv);
      RasterPass pass;
      pass.window = {0, 0, 32, 32};
      pass.tile_size = 8;
      std::vector<int> rows(32, 0);
      std::mutex lock;
      rasterize(s, cv.view, pass, [&](const RasterTile& t) {
        const std::lock_guard<std::mutex> hold(lock);
        for (int y = t.pixels.y0; y < t.pixels.y1; ++y)
          for (int x = t.pixels.x0; x < t.pixels.x1; ++x)
            rows[size_t(x)] += t.opaque[(y - t.pixels.y0) * t.pixels.width() + (x - t.pixels.x0)].hit.valid();
      });
      for (int x = 0; x < 32; ++x) CHECK(rows[size_t(x)] == int(w));
    }
    // Traced with 256 samples a pixel: each column's coverage sums to w within sampling error.
    cfg.spp = 256;
    const auto accel = make_scene_accelerator("bvh", s);
    const Film t = render_whitted(s, *accel, cam, cfg);
    CHECK(alpha_sum(t) / 32 == Approx(w).margin(0.03));
  }
}

TEST_CASE("points: a point's disc covers pi r^2 pixels, traced and rasterised", "[raster][curves][quick]") {
  const Camera cam = ortho_camera(16);  // one scene unit per pixel
  for (float r : {2.0f, 4.5f}) {
    Scene s;
    const int m = add_material(s, {1, 1, 1}, 0, 1, true);
    Mesh point = point_set({{0.3f, -0.2f, 0}}, r, m);
    point.colors = {{1, 0.25f, 0, 1}};  // COLOR_0 times the unlit white
    add_world_mesh(s, std::move(point));
    RenderConfig cfg = small_render_config(32, 32, 256, 8);
    cfg.raster.shadows = RasterShadows::None;
    const auto accel = make_scene_accelerator("kdtree", s);
    const double area = kPi * r * r;
    INFO("radius " << r);
    const Film traced = render_whitted(s, *accel, cam, cfg);
    CHECK(alpha_sum(traced) == Approx(area).epsilon(0.01));
    cfg.spp = 64;
    const Film raster = render_raster(s, nullptr, cam, cfg);
    CHECK(alpha_sum(raster) == Approx(area).epsilon(0.02));
    for (const Film* f : {&traced, &raster}) {  // the point's colour at its centre
      CHECK(f->pixel(16, 16)[0] == Approx(1).margin(1e-3));
      CHECK(f->pixel(16, 16)[1] == Approx(0.25f).margin(1e-3));
      CHECK(f->pixel(16, 16)[2] == Approx(0).margin(1e-3));
    }
  }
}

TEST_CASE("points and lines: raster and trace see the same ids on >= 99% of their pixels",
          "[raster][curves][crosscheck]") {
  // A spiral polyline and, in front of it, a grid of points, before a quad, seen in perspective,
  // 3 and 6 pixels wide at their depths. (Where a point's sphere and a segment's capsule
  // interpenetrate, the raster preview's flat stand-ins may show the other one.)
  Scene s;
  const int m = add_material(s, {0.8f, 0.8f, 0.8f}, 0, 1);
  add_quad_z(s, -3, 3, -3, 3, -1, m);
  s.instances[0].node = 0;  // object ids: the quad 1, the lines 2, the points 3
  std::vector<Vec3f> spiral;
  std::vector<uint32_t> pairs;
  for (int i = 0; i <= 40; ++i) {
    const float a = 0.45f * float(i), rad = 0.3f + 0.05f * float(i);
    spiral.push_back({rad * std::cos(a), rad * std::sin(a), 0.02f * float(i)});
    if (i) pairs.insert(pairs.end(), {uint32_t(i - 1), uint32_t(i)});
  }
  Mesh lines = line_set(spiral, pairs, 0, m);
  lines.node = 1;
  add_world_mesh(s, std::move(lines));
  std::vector<Vec3f> grid;
  for (int x = -4; x <= 4; ++x)
    for (int y = -4; y <= 4; ++y) grid.push_back({0.6f * float(x), 0.6f * float(y), 1.2f});
  Mesh points = point_set(grid, 0, m);
  points.node = 2;
  add_world_mesh(s, std::move(points));
  const Camera cam = look_at({0.5f, -1, 8}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  RenderConfig cfg = small_render_config(240, 180, 1, 16);
  set_curve_radii(s, cam, cfg.height, {6, true}, {3, true});
  REQUIRE(renders_as_curves(s.meshes[1]));
  int pixels = 0;
  const double agreement = curve_id_agreement(s, cam, cfg, 2, pixels);
  INFO(pixels << " point and line pixels, " << agreement * 100 << "% agree");
  CHECK(pixels > 1000);
  CHECK(agreement >= 0.99);
}

TEST_CASE("points and lines: raster and trace agree on the corpus' MeshPrimitiveModes",
          "[raster][curves][crosscheck][corpus]") {
  const auto corpus = corpus_dir();
  if (!corpus) return skip("no corpus (set PENUMBRA_CORPUS)");
  LoadedScene l = load_gltf(*corpus / "valid/MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf");
  const Camera cam = default_camera(l.scene, 4.0f / 3.0f);
  RenderConfig cfg = small_render_config(320, 240, 1, 16);
  set_curve_radii(l.scene, cam, cfg.height, {6, true}, {2, true});
  // Instances of point and line sets: count the pixels where either path sees one.
  int curves = 0, first = -1;
  for (size_t i = 0; i < l.scene.instances.size(); ++i)
    if (renders_as_curves(l.scene.meshes[size_t(l.scene.instances[i].mesh)])) {
      ++curves;
      if (first < 0) first = int(i);
    }
  REQUIRE(curves == 4);  // POINTS, LINES, LINE_LOOP, LINE_STRIP
  const auto accel = make_scene_accelerator("embree", l.scene);
  const DataAovs t = render_data_aovs(l.scene, *accel, cam, cfg, IntegratorType::Raster);
  const DataAovs r = render_raster_aovs(l.scene, cam, cfg);
  const auto is_curve = [&](float id) {
    for (size_t i = 0; i < l.scene.instances.size(); ++i)
      if (renders_as_curves(l.scene.meshes[size_t(l.scene.instances[i].mesh)]) &&
          id == float(l.scene.instances[i].node + 1))
        return true;
    return false;
  };
  int pixels = 0, agree = 0;
  for (size_t i = 0; i < t.object_id.size(); ++i) {
    if (!is_curve(t.object_id[i]) && !is_curve(r.object_id[i])) continue;
    ++pixels;
    agree += t.object_id[i] == r.object_id[i];
  }
  INFO(pixels << " point and line pixels, " << agree << " agree");
  CHECK(pixels > 500);
  CHECK(agree >= 0.99 * pixels);
}
