// Tests for renderer/aov (first-hit data layers) and the path tracer's light groups: exact ids,
// depths, normals and positions on a known scene, background conventions, determinism, and
// beauty = the sum of the light groups with physically known splits.
#include "renderer/integrators/aov.h"

#include <catch2/catch.hpp>

#include "io/gltf/loader.h"
#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
RenderConfig config(int w, int h, int spp) {
  return small_render_config(w, h, spp, 4);
}
}  // namespace

TEST_CASE("aov: ids, depth, normal, position and albedo are exact on a known scene", "[aov][quick]") {
  // Orthographic view straight down -z over x in [-2, 2]: a near quad (node 4) covers x < 0 at
  // z = 0, a far one (node 7) covers 0 < x < 1 at z = -1, nothing beyond x = 1.
  Scene s;
  const int red = add_material(s, {0.8f, 0.1f, 0.1f}, 0, 1);
  const int blue = add_material(s, {0.1f, 0.2f, 0.9f}, 0, 1);
  s.instances[size_t(add_quad_z(s, -3, 0, -3, 3, 0, red))].node = 4;
  s.instances[size_t(add_quad_z(s, 0, 1, -3, 3, -1, blue))].node = 7;
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 1;
  const auto accel = make_scene_accelerator("embree", s);
  for (IntegratorType it : {IntegratorType::Whitted, IntegratorType::Path}) {
    const DataAovs a = render_data_aovs(s, *accel, cam, config(16, 8, 16), it);
    // Pixel columns: x = -2 + 4 (i + 0.5) / 16; columns 0..7 near, 8..11 far, 12..15 empty.
    for (int y : {0, 3, 7}) {
      const size_t near = size_t(y * 16 + 2), far = size_t(y * 16 + 9), empty = size_t(y * 16 + 14);
      CHECK(a.object_id[near] == 5);
      CHECK(a.material_id[near] == 1);
      CHECK(a.object_id[far] == 8);
      CHECK(a.material_id[far] == 2);
      CHECK(a.object_id[empty] == 0);
      CHECK(a.material_id[empty] == 0);
      CHECK(a.depth[near] == 5);
      CHECK(a.depth[far] == 6);
      CHECK(std::isinf(a.depth[empty]));
      CHECK(a.normal[near * 3 + 2] == 1);
      CHECK(a.position[far * 3 + 2] == -1);
      CHECK(a.albedo[near * 3] == Approx(0.8f));
      CHECK(a.albedo[far * 3 + 2] == Approx(0.9f));
      CHECK(a.albedo[empty * 3] == 0);
      CHECK(a.normal[empty * 3 + 2] == 0);
    }
    // P is the mean of the samples' hit points: the pixel centre's x within the filter's spread.
    CHECK(a.position[size_t(3 * 16 + 2) * 3] == Approx(-2 + 4 * 2.5 / 16).margin(0.05));
    // The edge column between near and far: the near quad's depth (the nearest), ids by majority.
    const size_t edge = size_t(2 * 16 + 7);
    CHECK(a.depth[edge] == 5);
  }
}

TEST_CASE("aov: depth, normal, position and ids on analytic and implicit spheres", "[aov][shapes]") {
  // Orthographic view down -z from z = 5 onto a unit sphere at the origin: at (x, y) the depth is
  // 5 - sqrt(1 - x^2 - y^2), the normal and the position (x, y, sqrt(1 - x^2 - y^2)).
  for (bool implicit : {false, true}) {
    Scene s;
    const int mat = add_material(s, {0.8f, 0.1f, 0.1f}, 0, 1);
    add_shape(s, sphere_shape(1, implicit), Affine3f{}, mat, /*node=*/3);
    Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
    cam.projection = Projection::Orthographic;
    cam.ymag = 1.6f;
    const auto accel = make_scene_accelerator("bvh", s);
    const DataAovs a = render_data_aovs(s, *accel, cam, config(32, 32, 4), IntegratorType::Whitted);
    INFO((implicit ? "implicit" : "analytic"));
    for (int y : {10, 13, 16, 20}) {
      for (int x : {10, 14, 16, 20}) {
        const size_t i = size_t(y * 32 + x);
        const float px = -1.6f + 3.2f * (float(x) + 0.5f) / 32, py = 1.6f - 3.2f * (float(y) + 0.5f) / 32;
        const float z = std::sqrt(1 - px * px - py * py);
        // Within the pixel's footprint (0.1 wide) and the filter's spread.
        CHECK(a.depth[i] == Approx(5 - z).margin(0.08));
        CHECK(a.normal[i * 3 + 2] == Approx(z).margin(0.06));
        CHECK(a.position[i * 3] == Approx(px).margin(0.06));
        CHECK(a.object_id[i] == 4);
        CHECK(a.material_id[i] == 1);
        CHECK(a.albedo[i * 3] == Approx(0.8f));
      }
    }
    // UV: spherical coordinates, analytic spheres only. At (x, y, z) on the sphere u = phi / 2 pi
    // with phi = atan2(-z, x) in [0, 2 pi), v = acos(y) / pi: (0.75, 0.5) facing the camera.
    const size_t centre = size_t(16 * 32 + 16);
    if (!implicit) {
      CHECK(a.uv[centre * 2] == Approx(0.75f).margin(0.02));
      CHECK(a.uv[centre * 2 + 1] == Approx(0.5f).margin(0.02));
    } else {
      CHECK(a.uv[centre * 2] == 0);  // implicit shapes have no UVs
    }
    CHECK(std::isinf(a.depth[0]));  // the corner is outside the sphere
    CHECK(a.object_id[0] == 0);
  }
}

TEST_CASE("aov: depth is camera-space distance along the view axis, not along the ray", "[aov][quick]") {
  Scene s;
  add_quad_z(s, -50, 50, -50, 50, -3, add_material(s, {1, 1, 1}, 0, 1));
  const Camera cam = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1.2f);
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig cfg = config(12, 8, 4);
  const DataAovs a = render_data_aovs(s, *accel, cam, cfg, IntegratorType::Whitted);
  for (float z : a.depth) CHECK(z == Approx(4).epsilon(1e-5));
  // And the same for any thread count.
  cfg.threads = 1;
  const DataAovs b = render_data_aovs(s, *accel, cam, cfg, IntegratorType::Path);
  cfg.threads = 3;
  const DataAovs c = render_data_aovs(s, *accel, cam, cfg, IntegratorType::Path);
  CHECK(b.position == c.position);
  CHECK(b.object_id == c.object_id);
}

TEST_CASE("light groups: the beauty is their sum, split as physics says", "[aov][path]") {
  // The default scene with an environment: every pixel's beauty = the sum of the five groups.
  LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  const auto accel = make_scene_accelerator("embree", loaded.scene);
  const AreaLights al = build_area_lights(loaded.scene);
  const Environment env = make_constant_environment({0.2f, 0.2f, 0.25f});
  RenderConfig cfg = config(32, 18, 8);
  cfg.light_groups = true;
  const PathImage img =
      render_path(loaded.scene, *accel, PathLights{&al, &env}, loaded.scene.cameras.at(0), cfg);
  REQUIRE(img.groups.size() == size_t(32 * 18 * 15));
  double diffuse = 0, specular = 0, indirect = 0;
  for (size_t i = 0; i < size_t(32 * 18); ++i)
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (int g = 0; g < 5; ++g) sum += img.groups[i * 15 + size_t(g * 3 + c)];
      REQUIRE(sum == Approx(img.film.rgba[i * 4 + size_t(c)]).epsilon(1e-4).margin(1e-6));
      diffuse += img.groups[i * 15 + 3 + size_t(c)];
      specular += img.groups[i * 15 + 9 + size_t(c)];
      indirect += img.groups[i * 15 + 6 + size_t(c)] + img.groups[i * 15 + 12 + size_t(c)];
    }
  CHECK(diffuse > 0);
  CHECK(specular > 0);
  CHECK(indirect > 0);

  // Inside a closed Lambertian sphere of albedo 0.5 emitting 1: emission 1, direct 0.5,
  // indirect 0.25 + 0.125 + ... = 0.5, no specular.
  Scene s;
  add_sphere(s, {0, 0, 0}, 3, 2, add_lambert(s, {0.5f, 0.5f, 0.5f}, {1, 1, 1}));
  const auto accel2 = make_scene_accelerator("embree", s);
  const AreaLights al2 = build_area_lights(s);
  const Environment black = make_constant_environment({0, 0, 0});
  RenderConfig c2 = config(4, 4, 1024);
  c2.light_groups = true;
  c2.path.max_depth = 40;
  const PathImage e =
      render_path(s, *accel2, PathLights{&al2, &black}, look_at({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1), c2);
  auto mean = [&](int group) {
    double m = 0;
    for (size_t i = 0; i < 16; ++i) m += e.groups[i * 15 + size_t(group * 3)];
    return m / 16;
  };
  CHECK(mean(0) == Approx(1).epsilon(1e-6));
  CHECK(mean(1) == Approx(0.5).epsilon(0.01));
  CHECK(mean(2) == Approx(0.5).epsilon(0.02));
  CHECK(mean(3) == 0);
  CHECK(mean(4) == 0);
}
