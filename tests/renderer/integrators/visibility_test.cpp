// Tests for renderer/integrators/visibility: alpha cut-outs, blended shadows and single-sided
// culling of camera, mirror and shadow rays, with analytic answers.
#include "renderer/integrators/visibility.h"

#include <catch2/catch.hpp>

#include "renderer/accel/factory.h"
#include "renderer/integrators/scene_accel.h"
#include "support/material_scenes.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

TEST_CASE("material: Mask cut-outs let camera and shadow rays through; cutoff decides", "[material][quick]") {
  Probe p;
  const int back = add_material(p.scene, {0, 1, 0}, 0, 1);
  const int front = add_material(p.scene, {1, 0, 0}, 0, 1);
  p.scene.materials[size_t(front)].alpha = 0.3f;
  p.scene.materials[size_t(front)].alpha_mode = AlphaMode::Mask;
  add_uv_quad(p.scene, 0, back);
  add_uv_quad(p.scene, 1, front);
  p.build();
  Hit h;
  CHECK(p.at(0, 0, &h).base_color.y == 1);  // alpha 0.3 < cutoff 0.5: the hole shows the back quad
  CHECK(h.t == Approx(10));
  Ray shadow;
  shadow.org = {0, 0, 0.5f};
  shadow.dir = {0, 0, 1};
  CHECK(shadow_transmittance(p.scene, *p.accel, shadow, true) == 1);
  p.scene.materials[size_t(front)].alpha_cutoff = 0.2f;
  CHECK(p.at(0, 0, &h).base_color.x == 1);  // now 0.3 >= 0.2: the front quad is solid
  CHECK(h.t == Approx(9));
  CHECK(shadow_transmittance(p.scene, *p.accel, shadow, true) == 0);
}

TEST_CASE("material: Blend layers attenuate shadows by (1 - alpha) each", "[material][quick]") {
  Probe p;
  const int blend = add_material(p.scene, {1, 1, 1}, 0, 1);
  p.scene.materials[size_t(blend)].alpha = 0.5f;
  p.scene.materials[size_t(blend)].alpha_mode = AlphaMode::Blend;
  add_uv_quad(p.scene, 1, blend);
  add_uv_quad(p.scene, 2, blend);
  add_uv_quad(p.scene, 3, blend, true);  // back face towards the ray: still casts
  p.build();
  Ray shadow;
  shadow.org = {0, 0, 0};
  shadow.dir = {0, 0, 1};
  CHECK(shadow_transmittance(p.scene, *p.accel, shadow, true) == Approx(0.125));
  shadow.tfar = 2.5f;
  CHECK(shadow_transmittance(p.scene, *p.accel, shadow, true) == Approx(0.25));
}

TEST_CASE("material: single-sided back faces are invisible to camera rays but cast shadows",
          "[material][quick]") {
  Probe p;
  const int single = add_material(p.scene, {1, 0, 0}, 0, 1);
  p.scene.materials[size_t(single)].double_sided = false;
  const int floor = add_material(p.scene, {0, 0, 1}, 0, 1);
  add_uv_quad(p.scene, 0, floor);
  add_uv_quad(p.scene, 1, single, true);  // faces -z: the downward camera ray sees its back
  p.build();
  Hit h;
  CHECK(p.at(0, 0, &h).base_color.z == 1);
  CHECK(h.geom_id == 0);
  Ray shadow;
  shadow.org = {0, 0, 0.1f};
  shadow.dir = {0, 0, 1};
  CHECK(shadow_transmittance(p.scene, *p.accel, shadow, true) == 0);
  p.scene.materials[size_t(single)].double_sided = true;
  CHECK(p.at(0, 0, &h).base_color.x == 1);
  CHECK(scene_needs_hit_filter(p.scene) == false);
}

TEST_CASE("material: shapes are culled, cut out and blended as meshes are, implicit ones included",
          "[material][shapes]") {
  // A sphere of radius 1 at the origin: a ray along +x from x = -5 meets it at t = 4 (entering)
  // and t = 6 (leaving); from the centre it meets only the far side at t = 1.
  for (bool implicit : {false, true}) {
    INFO((implicit ? "implicit" : "analytic"));
    Scene s;
    const int mat = add_material(s, {1, 1, 1}, 0, 1);
    add_shape(s, sphere_shape(1, implicit), Affine3f{}, mat);
    const auto accel = make_accelerator("bvh", mesh_views(s), instance_views(s));
    Material& m = s.materials[size_t(mat)];
    Hit h;
    // Single-sided: seen from outside it is its front; from inside its back is culled.
    m.double_sided = false;
    REQUIRE(intersect_visible(s, *accel, {{-5, 0, 0}, 0, {1, 0, 0}, kInfinity}, h, true));
    CHECK(h.t == Approx(4).margin(1e-3));
    CHECK_FALSE(intersect_visible(s, *accel, {{0, 0, 0}, 0, {1, 0, 0}, kInfinity}, h, true));
    m.double_sided = true;
    REQUIRE(intersect_visible(s, *accel, {{0, 0, 0}, 0, {1, 0, 0}, kInfinity}, h, true));
    CHECK(h.t == Approx(1).margin(1e-3));
    // Blend: a shadow ray through both surfaces keeps (1 - alpha)^2.
    m.alpha_mode = AlphaMode::Blend;
    m.alpha = 0.5f;
    CHECK(shadow_transmittance(s, *accel, {{-5, 0, 0}, 0, {1, 0, 0}, 10}, true) == Approx(0.25f));
    // Mask: the cutoff decides between solid and invisible.
    m.alpha_mode = AlphaMode::Mask;
    m.alpha = 0.7f;
    CHECK(shadow_transmittance(s, *accel, {{-5, 0, 0}, 0, {1, 0, 0}, 10}, true) == 0);
    m.alpha_cutoff = 0.8f;
    CHECK(shadow_transmittance(s, *accel, {{-5, 0, 0}, 0, {1, 0, 0}, 10}, true) == 1);
    CHECK_FALSE(intersect_visible(s, *accel, {{-5, 0, 0}, 0, {1, 0, 0}, kInfinity}, h, true));
  }
}
