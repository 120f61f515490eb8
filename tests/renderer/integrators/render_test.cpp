// Tests for renderer/render: bitwise determinism across thread counts, coverage alpha,
// stratified sampling.
#include "renderer/integrators/render.h"

#include <catch2/catch.hpp>
#include <cstring>

#include "io/gltf/loader.h"
#include "renderer/accel/factory.h"
#include "renderer/core/rng.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;

TEST_CASE("the image is bit-identical for 1, 2 and 3 threads", "[render]") {
  LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  const auto accel = make_scene_accelerator("embree", loaded.scene);
  RenderConfig cfg;
  cfg.width = 96;
  cfg.height = 54;
  cfg.spp = 3;  // not a square: exercises the unstratified remainder too
  cfg.tile_size = 8;
  std::vector<Film> films;
  for (int threads : {1, 2, 3}) {
    cfg.threads = threads;
    RenderStats stats;
    films.push_back(render_whitted(loaded.scene, *accel, loaded.scene.cameras.at(0), cfg, &stats));
    CHECK(stats.threads == threads);
    CHECK(stats.rays.camera == uint64_t(96 * 54 * 3));
  }
  REQUIRE(films[0].rgba.size() == size_t(96 * 54 * 4));
  CHECK(std::memcmp(films[0].rgba.data(), films[1].rgba.data(), films[0].rgba.size() * sizeof(float)) == 0);
  CHECK(std::memcmp(films[0].rgba.data(), films[2].rgba.data(), films[0].rgba.size() * sizeof(float)) == 0);
  // And not trivially so: the image has structure.
  float lo = 1e9f, hi = -1e9f;
  for (size_t i = 0; i < films[0].rgba.size(); i += 4) {
    lo = std::min(lo, films[0].rgba[i]);
    hi = std::max(hi, films[0].rgba[i]);
  }
  CHECK(hi - lo > 0.1f);
  // A different seed changes the jitter, hence some pixels.
  cfg.seed = 1;
  const Film other = render_whitted(loaded.scene, *accel, loaded.scene.cameras.at(0), cfg);
  CHECK(std::memcmp(films[0].rgba.data(), other.rgba.data(), other.rgba.size() * sizeof(float)) != 0);
}

TEST_CASE("alpha is pixel coverage and colour is premultiplied", "[render][quick]") {
  // An orthographic camera sees a white unlit quad covering x < 0.25 of a [-1, 1] view:
  // 20 px wide image, quad edge at raster x = 12.5 -> pixels 0..11 full, 12 half, 13.. empty.
  Scene s;
  const int mat = test::add_material(s, {1, 1, 1}, 0, 1, /*unlit=*/true);
  test::add_quad_z(s, -5, 0.25f, -5, 5, 0, mat);
  Camera cam = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 1;
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig cfg;
  cfg.width = 20;
  cfg.height = 20;
  cfg.spp = 64;
  const Film f = render_whitted(s, *accel, cam, cfg);
  CHECK(f.pixel(5, 10)[3] == 1.0f);
  CHECK(f.pixel(5, 10)[0] == 1.0f);
  CHECK(f.pixel(15, 10)[3] == 0.0f);
  CHECK(f.pixel(15, 10)[0] == 0.0f);
  const float a = f.pixel(12, 10)[3];
  CHECK(a == Approx(0.5).margin(0.13));  // 64 stratified samples over a half-covered pixel
  CHECK(f.pixel(12, 10)[0] == a);        // premultiplied: colour 1 x coverage
}

TEST_CASE("stratified samples cover every stratum once and stay in the pixel", "[render][quick]") {
  for (uint32_t n : {1u, 4u, 9u, 16u, 5u, 12u}) {
    uint32_t cols = 1;
    while ((cols + 1) * (cols + 1) <= n) ++cols;
    const uint32_t rows = n / cols;
    std::vector<int> hits(cols * rows, 0);
    for (uint32_t s = 0; s < n; ++s) {
      Rng rng = make_pixel_rng(3, 4, s, 0);
      const Vec2f p = stratified_sample(s, n, rng);
      REQUIRE(p.x >= 0);
      REQUIRE(p.x < 1);
      REQUIRE(p.y >= 0);
      REQUIRE(p.y < 1);
      if (s < cols * rows) ++hits[size_t(int(p.y * rows) * cols + int(p.x * cols))];
    }
    for (int h : hits) CHECK(h == 1);
  }
}

TEST_CASE("pixel RNG streams depend only on (pixel, sample, seed)", "[render][quick]") {
  Rng a = make_pixel_rng(10, 20, 3, 42), b = make_pixel_rng(10, 20, 3, 42);
  Rng c = make_pixel_rng(20, 10, 3, 42), d = make_pixel_rng(10, 20, 4, 42);
  const uint32_t va = a.next_u32();
  CHECK(va == b.next_u32());
  CHECK(va != c.next_u32());
  CHECK(va != d.next_u32());
  // Mean of uniform floats is 1/2 (loose bound: 4 sigma for 10^5 samples).
  double sum = 0;
  for (int i = 0; i < 100000; ++i) sum += a.next_float();
  CHECK(std::fabs(sum / 100000 - 0.5) < 4 * std::sqrt(1.0 / 12 / 100000));
}

namespace {

/// Renders `s` through `cam` (128 x 128) with Whitted or the path tracer, `spp` samples.
Film render_lens_scene(const Scene& s, const Camera& cam, bool path, int spp) {
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig cfg;
  cfg.width = 128;
  cfg.height = 128;
  cfg.spp = spp;
  if (!path) return render_whitted(s, *accel, cam, cfg);
  const AreaLights al = build_area_lights(s);
  const Environment black;
  return render_path(s, *accel, PathLights{&al, &black}, cam, cfg).film;
}

/// The area in pixels of the blur kernel an image of a small bright patch shows: its energy over
/// its plateau (the mean of the pixels within `plateau_px` of the centre), which is exactly the
/// kernel's area while the patch fits inside the kernel.
double kernel_area(const Film& f, float plateau_px) {
  double total = 0, plateau = 0;
  int plateau_n = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const float v = f.pixel(x, y)[0];
      total += v;
      if (std::hypot(float(x) + 0.5f - 64, float(y) + 0.5f - 64) < plateau_px) plateau += v, ++plateau_n;
    }
  return total / (plateau / plateau_n);
}

/// Pixels of row 64 that are neither background nor surface (an edge's width).
int edge_width(const Film& f) {
  int n = 0;
  for (int x = 0; x < f.width; ++x) n += f.pixel(x, 64)[0] > 0.02f && f.pixel(x, 64)[0] < 0.98f;
  return n;
}

}  // namespace

TEST_CASE("depth of field: a small patch off the focal plane images as the thin lens' disc or polygon",
          "[render][dof]") {
  // A 0.02-wide unlit white square at depth 2, in focus at depth 4, aperture radius 0.2: the
  // circle of confusion has radius R |1/F - 1/z| = 0.05 at depth 1, 12.8 px for tan(yfov/2) =
  // 0.25 over 64 px.
  Scene s;
  const int mat = test::add_material(s, {1, 1, 1}, 0, 1, /*unlit=*/true);
  test::add_quad_z(s, -0.01f, 0.01f, -0.01f, 0.01f, -2, mat);
  Camera cam;
  cam.yfov = 2 * std::atan(0.25f);
  cam.lens.radius = 0.2f;
  cam.lens.focus_distance = 4;
  const double r = 0.2 * (1.0 / 2 - 1.0 / 4) / 0.25 * 64;
  for (bool path : {false, true}) {
    INFO((path ? "path" : "whitted"));
    Camera round = cam;
    const double disc = kernel_area(render_lens_scene(s, round, path, 256), 8);
    CHECK(std::sqrt(disc / kPi) == Approx(r).margin(1.0));
    Camera hex = cam;
    hex.lens.blades = 6;
    const double polygon = kernel_area(render_lens_scene(s, hex, path, 256), 8);
    CHECK(std::sqrt(polygon / (1.5 * std::sqrt(3.0))) == Approx(r).margin(1.0));
    // Through a pinhole the patch covers about its own 2.56 x 2.56 px.
    Camera pinhole = cam;
    pinhole.lens.radius = 0;
    const Film sharp = render_lens_scene(s, pinhole, path, 64);
    double energy = 0;
    for (size_t i = 0; i < sharp.rgba.size(); i += 4) energy += sharp.rgba[i];
    CHECK(energy == Approx(2.56 * 2.56).epsilon(0.1));
  }
}

TEST_CASE("depth of field: the plane in focus stays as sharp as through a pinhole", "[render][dof]") {
  // A half-plane's edge at depth 4 (x = 0.05, raster x = 64 + 3.2).
  Scene s;
  const int mat = test::add_material(s, {1, 1, 1}, 0, 1, /*unlit=*/true);
  test::add_quad_z(s, -10, 0.05f, -10, 10, -4, mat);
  Camera cam;
  cam.yfov = 2 * std::atan(0.25f);
  for (bool path : {false, true}) {
    INFO((path ? "path" : "whitted"));
    const int pinhole = edge_width(render_lens_scene(s, cam, path, 64));
    Camera focused = cam;
    focused.lens.radius = 0.2f;
    focused.lens.focus_distance = 4;
    CHECK(edge_width(render_lens_scene(s, focused, path, 64)) <= pinhole);
    // Focused elsewhere the same edge spreads over the circle of confusion (R |1/F - 1/z| =
    // 0.05 at depth 1: 12.8 px each side).
    Camera defocused = focused;
    defocused.lens.focus_distance = 2;
    CHECK(edge_width(render_lens_scene(s, defocused, path, 64)) >= 20);
  }
}
