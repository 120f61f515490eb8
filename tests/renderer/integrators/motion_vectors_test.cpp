// Tests for renderer/integrators/motion_vectors: the projection inverts the camera's rays, a
// shape's vector follows its instance transform (orthographic view: the displacement in pixels
// is the offset times pixels per unit), misses are 0, and frames that do not match are named.
#include "renderer/integrators/motion_vectors.h"

#include <catch2/catch.hpp>

#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

TEST_CASE("vector: project_to_raster inverts generate_camera_ray", "[vector][quick]") {
  Camera persp = look_at({1, 2, 6}, {0, 0, 0}, {0, 1, 0}, 0.9f);
  Camera ortho = persp;
  ortho.projection = Projection::Orthographic;
  ortho.ymag = 2;
  for (const Camera& cam : {persp, ortho})
    for (Vec2f px : {Vec2f{0.5f, 0.5f}, Vec2f{31.25f, 7.5f}, Vec2f{63.5f, 47.5f}}) {
      const Ray ray = generate_camera_ray(cam, 64, 48, px.x, px.y);
      Vec2f back;
      REQUIRE(project_to_raster(cam, 64, 48, ray.org + ray.dir * 4.5f, back));
      CHECK(back.x == Approx(px.x).margin(1e-3));
      CHECK(back.y == Approx(px.y).margin(1e-3));
    }
  Vec2f r;
  CHECK_FALSE(project_to_raster(persp, 64, 48, Vec3f{2, 4, 12}, r));  // behind the eye
}

TEST_CASE("vector: a shape follows its instance transform; misses are 0", "[vector][quick]") {
  // A sphere of radius 1 at the origin under an orthographic view down -z, 4 units high over 40
  // pixels: 10 pixels per unit. It was at x = -0.2 and will be at y = +0.3.
  Scene now, before, after;
  const int m = add_material(now, {0.5f, 0.5f, 0.5f}, 0, 1);
  add_shape(now, sphere_shape(1), translation({0, 0, 0}), m);
  before = now;
  after = now;
  before.instances[0] = make_shape_instance(0, translation({-0.2f, 0, 0}));
  after.instances[0] = make_shape_instance(0, translation({0, 0.3f, 0}));
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 2;
  const RenderConfig cfg = small_render_config(40, 40, 1);
  const auto accel = make_scene_accelerator("bvh", now, AccelConfig{});
  const std::vector<float> v = render_motion_vectors(now, *accel, cam, cfg, {&before, cam}, {&after, cam});
  REQUIRE(v.size() == 40 * 40 * 4);
  int hits = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 40; ++x) {
      const float px = (float(x) + 0.5f - 20) / 10, py = (20 - float(y) - 0.5f) / 10;
      const float r2 = px * px + py * py;
      if (std::abs(r2 - 1) < 0.1f) continue;  // the silhouette
      const size_t i = (size_t(y) * 40 + size_t(x)) * 4;
      INFO("pixel " << x << "," << y);
      const bool hit = r2 < 1;
      hits += hit;
      // X = previous - now = -2 px; W = now - next (y up) = -3 px.
      CHECK(v[i] == Approx(hit ? -2.0f : 0.0f).margin(1e-3));
      CHECK(v[i + 1] == Approx(0).margin(1e-3));
      CHECK(v[i + 2] == Approx(0).margin(1e-3));
      CHECK(v[i + 3] == Approx(hit ? -3.0f : 0.0f).margin(1e-3));
    }
  CHECK(hits > 200);
}

TEST_CASE("vector: check_motion_frame names what differs", "[vector][quick]") {
  Scene a;
  const int m = add_material(a, {0.5f, 0.5f, 0.5f}, 0, 1);
  add_quad_z(a, 0, 1, 0, 1, 0, m);
  Scene b = a;
  CHECK(check_motion_frame(a, b).empty());
  b.meshes[0].positions[0].x += 1;  // moved vertices are what a frame may change
  CHECK(check_motion_frame(a, b).empty());
  b.meshes[0].indices[0] = b.meshes[0].indices[1];
  CHECK(check_motion_frame(a, b).find("meshes[0]") != std::string::npos);
  b = a;
  add_quad_z(b, 0, 1, 0, 1, 1, m);
  CHECK(check_motion_frame(a, b).find("instances") != std::string::npos);
}
