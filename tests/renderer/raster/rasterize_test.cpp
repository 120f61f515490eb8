// Tests for renderer/raster/rasterize.h: perspective-correct interpolation on a tilted quad
// against the analytic mapping, z-buffer order independence, determinism over threads and
// tiles, alpha test and Blend layers, back-face culling under mirroring, ray-cast shapes.
#include "renderer/raster/rasterize.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <mutex>
#include <random>

#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

// Every sample's opaque fragment of a pass over `scene` from `cam`, in frame order.
struct Samples {
  int width = 0, height = 0, spp = 1;
  std::vector<RasterFragment> opaque;
  std::vector<std::vector<RasterFragment>> layers;
  std::vector<Vec2f> positions;
};

Samples raster_samples(const Scene& scene, const Camera& cam, const RenderConfig& cfg) {
  CameraView cv;
  make_camera_view(cam, cfg.width, cfg.height, cv);
  const RasterPass pass = camera_raster_pass(cfg);
  Samples out;
  out.width = cfg.width;
  out.height = cfg.height;
  out.spp = cfg.spp;
  const size_t n = size_t(cfg.width) * size_t(cfg.height) * size_t(cfg.spp);
  out.opaque.resize(n);
  out.layers.resize(n);
  out.positions.resize(n);
  rasterize(scene, cv.view, pass, [&](const RasterTile& t) {
    size_t i = 0;
    for (int y = t.pixels.y0; y < t.pixels.y1; ++y)
      for (int x = t.pixels.x0; x < t.pixels.x1; ++x)
        for (int s = 0; s < t.spp; ++s, ++i) {
          const size_t k = (size_t(y) * size_t(cfg.width) + size_t(x)) * size_t(cfg.spp) + size_t(s);
          out.opaque[k] = t.opaque[i];
          out.positions[k] = t.positions[i];
          out.layers[k].assign(t.blend + t.blend_begin[i], t.blend + t.blend_begin[i + 1]);
        }
  });
  return out;
}

bool same_film(const Film& a, const Film& b) {
  return a.rgba.size() == b.rgba.size() && std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * 4) == 0;
}

RenderConfig unshadowed(int w, int h, int spp) {
  RenderConfig c = small_render_config(w, h, spp, 8);
  c.raster.shadows = RasterShadows::None;
  return c;
}

}  // namespace

TEST_CASE("raster: perspective-correct UVs on a tilted quad match the analytic mapping", "[raster][quick]") {
  // A 4 x 4 quad in the plane through the origin tilted 60 degrees away from the camera, with
  // UV = its local coordinates / 4; the camera looks at it from z = 3.
  Scene s;
  const int m = add_material(s, {1, 1, 1}, 0, 1);
  const float c = std::cos(kPi / 3), sn = std::sin(kPi / 3);
  const Vec3f e1{1, 0, 0}, e2{0, c, -sn};  // the quad's axes
  Mesh q;
  q.name = "tilted";
  for (Vec2f uv : {Vec2f{0, 0}, Vec2f{1, 0}, Vec2f{1, 1}, Vec2f{0, 1}}) {
    q.positions.push_back(e1 * (4 * uv.x - 2) + e2 * (4 * uv.y - 2));
    q.uvs.push_back(uv);
  }
  q.indices = {0, 1, 2, 0, 2, 3};
  q.normals = compute_smooth_normals(q.positions, q.indices);
  q.material = m;
  add_world_mesh(s, std::move(q));
  const Camera cam = look_at({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 1.0f);
  const RenderConfig cfg = unshadowed(64, 64, 2);
  const Samples r = raster_samples(s, cam, cfg);
  const Vec3f n = cross(e1, e2);
  const Mesh& mesh = s.meshes[0];
  double worst = 0, worst_affine = 0;
  int covered = 0;
  for (size_t k = 0; k < r.opaque.size(); ++k) {
    const RasterFragment& f = r.opaque[k];
    if (!f.hit.valid()) continue;
    ++covered;
    // Analytic: the camera ray through the sample meets the plane at p; uv = local coords / 4.
    const Ray ray = generate_camera_ray(cam, cfg.width, cfg.height, r.positions[k].x, r.positions[k].y);
    const float t = -dot(ray.org, n) / dot(ray.dir, n);
    const Vec3f p = ray.org + ray.dir * t;
    const Vec2f want{(dot(p, e1) + 2) / 4, (dot(p, e2) + 2) / 4};
    const uint32_t* idx = &mesh.indices[size_t(f.hit.prim_id) * 3];
    const float w = 1 - f.hit.u - f.hit.v;
    const Vec2f got{mesh.uvs[idx[0]].x * w + mesh.uvs[idx[1]].x * f.hit.u + mesh.uvs[idx[2]].x * f.hit.v,
                    mesh.uvs[idx[0]].y * w + mesh.uvs[idx[1]].y * f.hit.u + mesh.uvs[idx[2]].y * f.hit.v};
    worst = std::max(worst, double(std::max(std::fabs(got.x - want.x), std::fabs(got.y - want.y))));
    // The depth is the analytic one too.
    CHECK(f.depth == Approx(dot(p - cam.eye, -cam.w)).epsilon(1e-5));
    // Screen-linear (affine) interpolation, for contrast: project the quad's corners and
    // interpolate uv linearly in screen space along v (the tilted axis).
    const auto screen_y = [&](Vec3f q3) { return 32.0 * (1 - q3.y / (-(q3.z - 3) * std::tan(0.5))); };
    const double y0 = screen_y(e2 * -2), y1 = screen_y(e2 * 2);
    const double affine_v = (r.positions[k].y - y0) / (y1 - y0);
    worst_affine = std::max(worst_affine, std::fabs(affine_v - want.y));
  }
  CHECK(covered > 1000);
  CHECK(worst < 1e-4);
  CHECK(worst_affine > 0.02);  // the check above would catch affine interpolation
}

TEST_CASE("raster: the z-buffer does not depend on triangle order", "[raster][quick]") {
  // Interpenetrating random triangles with per-vertex colours, shuffled.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  Scene s;
  const int m = add_material(s, {1, 1, 1}, 0, 1, true);
  Mesh mesh;
  mesh.name = "soup";
  for (int t = 0; t < 300; ++t) {
    const Vec3f c{u(rng), u(rng), u(rng)};
    for (int k = 0; k < 3; ++k) {
      mesh.positions.push_back(c + Vec3f{u(rng), u(rng), u(rng)} * 0.6f);
      mesh.colors.push_back({0.5f + 0.5f * u(rng), 0.5f + 0.5f * u(rng), 0.5f + 0.5f * u(rng), 1});
      mesh.indices.push_back(uint32_t(mesh.indices.size()));
    }
  }
  mesh.normals = compute_smooth_normals(mesh.positions, mesh.indices);
  mesh.material = m;
  Scene shuffled = s;
  add_world_mesh(s, mesh);
  std::vector<size_t> order(300);
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  Mesh permuted = mesh;
  for (size_t i = 0; i < order.size(); ++i)
    for (int k = 0; k < 3; ++k) permuted.indices[i * 3 + size_t(k)] = mesh.indices[order[i] * 3 + size_t(k)];
  add_world_mesh(shuffled, permuted);
  const Camera cam = look_at({0.3f, 0.2f, 4}, {0, 0, 0}, {0, 1, 0}, 0.9f);
  const RenderConfig cfg = unshadowed(96, 80, 4);
  const auto accel = make_scene_accelerator("brute", s);
  const auto accel2 = make_scene_accelerator("brute", shuffled);
  const Film a = render_raster(s, accel.get(), cam, cfg), b = render_raster(shuffled, accel2.get(), cam, cfg);
  CHECK(same_film(a, b));
  const DataAovs za = render_raster_aovs(s, cam, cfg), zb = render_raster_aovs(shuffled, cam, cfg);
  CHECK(za.depth == zb.depth);
  // The soup covers much of the frame, with many overlaps resolved by depth.
  int covered = 0;
  for (size_t i = 3; i < a.rgba.size(); i += 4) covered += a.rgba[i] > 0;
  CHECK(covered > 96 * 80 / 3);
}

TEST_CASE("raster: the same image for any thread count and tile size", "[raster][quick]") {
  Scene s;
  const int red = add_lambert(s, {0.8f, 0.2f, 0.1f});
  const int blend = add_material(s, {0.1f, 0.3f, 0.9f}, 0, 0.5f);
  s.materials[size_t(blend)].alpha_mode = AlphaMode::Blend;
  s.materials[size_t(blend)].alpha = 0.4f;
  add_quad_z(s, -3, 3, -3, 3, -1, red);
  add_quad_z(s, -1, 1.5f, -1, 1.5f, 0.2f, blend);
  add_sphere(s, {0.5f, 0, 0}, 0.7f, 3, red);
  add_shape(s, sphere_shape(0.4f), translation({-1, -0.5f, 0.5f}), red);
  s.lights.push_back(point_light({2, 3, 4}, 40));
  const Camera cam = look_at({0, 0.5f, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig cfg = small_render_config(70, 50, 4, 8);
  cfg.filter = make_filter(FilterType::Gaussian, 3);
  cfg.threads = 1;
  const Film one = render_raster(s, accel.get(), cam, cfg);
  cfg.threads = 2;
  cfg.tile_size = 13;
  const Film two = render_raster(s, accel.get(), cam, cfg);
  CHECK(same_film(one, two));
  cfg.tile_size = 64;
  CHECK(same_film(one, render_raster(s, accel.get(), cam, cfg)));
  // A crop is the same pixels as the whole frame.
  cfg.window = {10, 5, 41, 33};
  const Film crop = render_raster(s, accel.get(), cam, cfg);
  bool same = true;
  for (int y = 5; y < 33; ++y)
    for (int x = 10; x < 41; ++x)
      same = same && std::memcmp(crop.pixel(x - 10, y - 5), one.pixel(x, y), 16) == 0;
  CHECK(same);
}

TEST_CASE("raster: Mask is alpha-tested, Blend composited front to back, as the ray tracer",
          "[raster][quick]") {
  Scene s;
  const int blue = add_material(s, {0, 0, 1}, 0, 1, true);
  const int red = add_material(s, {1, 0, 0}, 0, 1, true);
  const int green = add_material(s, {0, 1, 0}, 0, 1, true);
  s.materials[size_t(red)].alpha_mode = AlphaMode::Blend;
  s.materials[size_t(red)].alpha = 0.25f;
  s.materials[size_t(green)].alpha_mode = AlphaMode::Mask;
  s.materials[size_t(green)].alpha = 0.3f;  // below the 0.5 cut-off: a hole everywhere
  add_quad_z(s, -4, 4, -4, 4, -1, blue);
  add_quad_z(s, -4, 0, -4, 4, 0, red);
  add_quad_z(s, -4, 4, -4, 0, 0.5f, green);
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 2;
  const RenderConfig cfg = unshadowed(16, 16, 1);
  const auto accel = make_scene_accelerator("brute", s);
  const Film r = render_raster(s, accel.get(), cam, cfg);
  const Film w = render_whitted(s, *accel, cam, cfg);
  // Left half: a quarter red over blue; right half: blue; the Mask quad is invisible.
  const float* left = r.pixel(3, 12);
  CHECK(left[0] == Approx(0.25f));
  CHECK(left[2] == Approx(0.75f));
  CHECK(left[3] == Approx(1));
  CHECK(r.pixel(12, 3)[2] == Approx(1));
  CHECK(r.pixel(12, 3)[1] == 0);
  for (size_t i = 0; i < r.rgba.size(); ++i) CHECK(r.rgba[i] == Approx(w.rgba[i]).margin(1e-6));
  // Layers beyond the limit: the first one past it counts as opaque.
  RenderConfig one_layer = cfg;
  one_layer.whitted.max_blend_layers = 0;
  CHECK(render_raster(s, accel.get(), cam, one_layer).pixel(3, 12)[0] == Approx(1));
}

TEST_CASE("raster: back faces of single-sided materials are culled, also under mirroring",
          "[raster][quick]") {
  Scene s;
  const int one_sided = add_material(s, {1, 1, 1}, 0, 1, true);
  s.materials[size_t(one_sided)].double_sided = false;
  const int two_sided = add_material(s, {0.5f, 0.5f, 0.5f}, 0, 1, true);
  add_quad_z(s, -4, 0, -4, 4, 0, one_sided, true);  // faces -z: its back is seen from +z
  add_quad_z(s, 0, 4, -4, 4, 0, two_sided, true);
  // A mirrored instance of a front-facing quad (scale x by -1): still front-facing in world space.
  Mesh q = s.meshes[0];
  std::swap(q.indices[1], q.indices[2]);
  std::swap(q.indices[4], q.indices[5]);
  for (Vec3f& p : q.positions) p.z = 1, p.y *= 0.25f;
  s.meshes.push_back(q);
  Affine3f mirror;
  mirror.m[0][0] = -1;
  s.instances.push_back(make_instance(int(s.meshes.size()) - 1, mirror));
  REQUIRE(s.instances.back().mirrored);
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 4;
  const RenderConfig cfg = unshadowed(32, 32, 1);
  const Samples r = raster_samples(s, cam, cfg);
  const auto at = [&](int x, int y) { return r.opaque[size_t(y * 32 + x)]; };
  CHECK_FALSE(at(4, 4).hit.valid());   // one-sided, back face
  CHECK(at(28, 4).hit.valid());        // two-sided
  CHECK(at(28, 16).hit.geom_id == 2);  // the mirrored quad in front, at x in [0, 4]
  const auto accel = make_scene_accelerator("brute", s);
  const Film w = render_whitted(s, *accel, cam, cfg), f = render_raster(s, accel.get(), cam, cfg);
  for (size_t i = 0; i < w.rgba.size(); ++i) CHECK(f.rgba[i] == Approx(w.rgba[i]).margin(1e-6));
}

TEST_CASE("raster: shapes are ray-cast in the fragment stage and depth-tested with triangles",
          "[raster][quick]") {
  Scene s;
  const int m = add_material(s, {1, 1, 1}, 0, 1, true);
  add_quad_z(s, -3, 3, -3, 3, 0, m);
  add_shape(s, sphere_shape(1), translation({0, 0, 0}), m, 3);  // half in front of the quad
  const Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  const RenderConfig cfg = unshadowed(48, 48, 1);
  const Samples r = raster_samples(s, cam, cfg);
  const auto accel = make_scene_accelerator("embree", s);
  int sphere = 0;
  for (size_t k = 0; k < r.opaque.size(); ++k) {
    const Ray ray = generate_camera_ray(cam, 48, 48, r.positions[k].x, r.positions[k].y);
    Hit hit;
    const bool traced = accel->intersect(ray, hit);
    REQUIRE(r.opaque[k].hit.valid() == traced);
    if (!traced) continue;
    CHECK(r.opaque[k].hit.geom_id == hit.geom_id);
    if (hit.geom_id == 1) {
      ++sphere;
      CHECK(r.opaque[k].hit.t == Approx(hit.t).epsilon(1e-5));
      CHECK(r.opaque[k].depth == Approx(hit.t * dot(ray.dir, -cam.w)).epsilon(1e-5));
    }
  }
  CHECK(sphere > 100);
}
