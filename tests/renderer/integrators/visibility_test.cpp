// Tests for renderer/integrators/visibility: alpha cut-outs, blended shadows and single-sided
// culling of camera, mirror and shadow rays, with analytic answers; and every back end's
// filtered queries against re-shooting the plain query past each rejected hit.
#include "renderer/integrators/visibility.h"

#include <catch2/catch.hpp>
#include <random>

#include "io/gltf/loader.h"
#include "renderer/accel/factory.h"
#include "renderer/integrators/scene_accel.h"
#include "support/cross_check.h"
#include "support/material_scenes.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

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

// ---- Filtered queries against re-shooting past each rejected hit ---------------------------------

namespace {

/// The definition of intersect_visible: the plain closest hit, re-shot just past each hit that a
/// single-sided back face or a Mask hole rejects.
bool reshoot_visible(const Scene& scene, const Accelerator& accel, const Ray& ray, Hit& hit) {
  Ray r = ray;
  for (int layer = 0; layer < 100000; ++layer) {
    hit = Hit{};
    if (!accel.intersect(r, hit)) return false;
    const Material& m = material_of(scene, instance_material(scene, scene.instances[hit.geom_id]));
    bool skip = !m.double_sided && dot(hit_front_normal(scene, r, hit), r.dir) > 0;
    if (!skip && m.alpha_mode == AlphaMode::Mask)
      skip = eval_alpha(scene, hit.geom_id, hit.prim_id, hit.u, hit.v) < 1;
    if (!skip) return true;
    r.tnear = std::nextafter(std::max(hit.t, ray.tnear), kInfinity);
  }
  FAIL("re-shooting did not end");
  return false;
}

/// The definition of shadow_transmittance: the product of (1 - alpha) over every hit.
float reshoot_transmittance(const Scene& scene, const Accelerator& accel, const Ray& ray) {
  float transmittance = 1;
  Ray r = ray;
  for (int layer = 0; layer < 100000; ++layer) {
    Hit hit;
    if (!accel.intersect(r, hit)) return transmittance;
    transmittance *= 1 - eval_alpha(scene, hit.geom_id, hit.prim_id, hit.u, hit.v);
    if (!(transmittance > 0)) return 0;
    r.tnear = std::nextafter(std::max(hit.t, ray.tnear), kInfinity);
  }
  FAIL("re-shooting did not end");
  return 0;
}

/// Every back end: intersect_visible and shadow_transmittance against the re-shooting loops
/// over the same structure, per ray (same hit ids, t within 1e-5 relative, transmittance within
/// 1e-6). Returns how many rays the filter changed (their plain hit was rejected).
size_t check_against_reshooting(const Scene& scene, const std::vector<Ray>& rays) {
  size_t changed = 0;
  for (const auto& name : accelerator_names()) {
    INFO(name);
    const auto accel = make_scene_accelerator(name, scene);
    size_t closest = 0, shadow = 0, rejected = 0;
    for (const Ray& r : rays) {
      Hit h, e, plain;
      const bool found = intersect_visible(scene, *accel, r, h, true);
      const bool expected = reshoot_visible(scene, *accel, r, e);
      rejected += accel->intersect(r, plain) && !(expected && e.t == plain.t);
      bool same = found == expected;
      if (same && found)
        same = h.geom_id == e.geom_id && h.prim_id == e.prim_id &&
               std::fabs(h.t - e.t) <= 1e-5f * std::max(1.0f, e.t);
      if (!same)
        UNSCOPED_INFO("visible: ray " << describe(r) << ": " << describe(h) << " vs " << describe(e));
      closest += !same;
      const float t = shadow_transmittance(scene, *accel, r, true);
      const float te = reshoot_transmittance(scene, *accel, r);
      if (std::fabs(t - te) > 1e-6f)
        UNSCOPED_INFO("shadow: ray " << describe(r) << ": " << t << " vs " << te);
      shadow += std::fabs(t - te) > 1e-6f;
    }
    CHECK(closest == 0);
    CHECK(shadow == 0);
    changed = std::max(changed, rejected);
  }
  return changed;
}

/// Rays from a box around `b` towards random points of it (camera-like and shadow-like alike).
std::vector<Ray> rays_through(const Bounds3f& b, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  const Vec3f c = b.center(), e = b.extent();
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const Vec3f target{b.lo.x + u(rng) * e.x, b.lo.y + u(rng) * e.y, b.lo.z + u(rng) * e.z};
    const Vec3f from = c + random_direction(rng) * (length(e) * (0.2f + u(rng)));
    Ray r{from, 0, normalize(target - from), kInfinity};
    if (i % 3 == 2) r.tfar = length(target - from);  // a segment ending inside
    rays.push_back(r);
  }
  return rays;
}

}  // namespace

TEST_CASE("visibility: Mask cut-outs and single-sided faces filtered in traversal equal re-shooting",
          "[material][filter]") {
  // A stack of textured quads (the quadrant texture's alpha-0.25 corner a hole under Mask, other
  // corners solid), single-sided quads facing either way, a Blend layer, and single-sided and
  // Mask spheres (shapes, analytic and implicit) through the stack.
  Scene s;
  const int tex = add_quadrant_texture(s);
  const int mask = add_material(s, {1, 1, 1}, 0, 1);
  s.materials[size_t(mask)].alpha_mode = AlphaMode::Mask;
  s.materials[size_t(mask)].base_color_tex.texture = tex;
  const int mask_single = add_material(s, {1, 1, 1}, 0, 1);
  s.materials[size_t(mask_single)] = s.materials[size_t(mask)];
  s.materials[size_t(mask_single)].double_sided = false;
  const int single = add_material(s, {1, 0, 0}, 0, 1);
  s.materials[size_t(single)].double_sided = false;
  const int blend = add_material(s, {0, 1, 0}, 0, 1);
  s.materials[size_t(blend)].alpha_mode = AlphaMode::Blend;
  s.materials[size_t(blend)].alpha = 0.4f;
  const int hollow = add_material(s, {1, 1, 1}, 0, 1);  // a Mask shape below its cut-off
  s.materials[size_t(hollow)].alpha_mode = AlphaMode::Mask;
  s.materials[size_t(hollow)].alpha = 0.3f;
  const int opaque = add_material(s, {0, 0, 1}, 0, 1);
  const int layers[] = {mask, single, mask_single, blend, mask, single, mask_single, mask};
  for (int i = 0; i < 8; ++i) add_uv_quad(s, 0.5f * float(i), layers[i], i % 2 == 1);
  add_uv_quad(s, -1, opaque);
  add_shape(s, sphere_shape(0.4f), translation({0.5f, 0.5f, 1.3f}), single);
  add_shape(s, sphere_shape(0.4f, true), translation({-0.5f, -0.4f, 2.1f}), single);
  add_shape(s, sphere_shape(0.3f), translation({-0.4f, 0.5f, 0.7f}), hollow);
  add_shape(s, sphere_shape(0.3f), translation({0.4f, -0.5f, 2.9f}), mask);
  const std::vector<Ray> rays = rays_through({{-1, -1, -1}, {1, 1, 3.5f}}, 3000, 17);
  CHECK(check_against_reshooting(s, rays) > rays.size() / 5);
}

TEST_CASE("visibility: AlphaBlendModeTest filtered in traversal equals re-shooting",
          "[material][filter][corpus]") {
  const auto corpus = corpus_dir();
  if (!corpus) return skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const LoadedScene ls = load_gltf(*corpus / "valid/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb");
  const std::vector<Ray> rays = rays_through(compute_bounds(ls.scene), 3000, 23);
  CHECK(check_against_reshooting(ls.scene, rays) > rays.size() / 50);
}
