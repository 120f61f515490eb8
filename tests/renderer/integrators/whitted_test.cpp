// Tests for renderer/whitted: the material mapping and closed-form shading of simple scenes.
#include "renderer/integrators/whitted.h"

#include <catch2/catch.hpp>

#include "renderer/accel/factory.h"
#include "renderer/core/geometry.h"
#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
Vec3f shade(const Scene& s, const WhittedConfig& cfg, const Ray& r, float& coverage, RayCounts& counts) {
  const auto accel = make_scene_accelerator("embree", s);
  return whitted_radiance(s, *accel, cfg, r, RayDifferential{}, coverage, counts);
}
}  // namespace

TEST_CASE("whitted_params follows the documented glTF mapping", "[whitted][quick]") {
  Material m;
  m.base_color = {0.8f, 0.6f, 0.4f};
  m.metallic = 0.25f;
  m.roughness = 0.5f;
  const WhittedParams w = whitted_params(m);
  CHECK(w.kd.x == Approx(0.8 * 0.75));
  CHECK(w.ka.y == Approx(0.6 * 0.75));
  const double f0x = 0.04 * 0.75 + 0.8 * 0.25;
  CHECK(w.ks.x == Approx(f0x));
  CHECK(w.kr.x == Approx(f0x * 0.25));              // (1 - roughness)^2
  CHECK(w.exponent == Approx(2.0 / 0.0625 - 2.0));  // alpha = roughness^2 = 0.25
  // A perfect mirror: no diffuse, full reflectance, the maximum exponent.
  m = {};
  m.base_color = {1, 1, 1};
  m.metallic = 1;
  m.roughness = 0;
  const WhittedParams mirror = whitted_params(m);
  CHECK(mirror.kd == Vec3f{0, 0, 0});
  CHECK(mirror.kr == Vec3f{1, 1, 1});
  CHECK(mirror.exponent == 10000.0f);
}

TEST_CASE("a single lit quad matches the closed-form Blinn-Phong value", "[whitted][quick]") {
  Scene s;
  const Vec3f base{0.8f, 0.6f, 0.4f};
  const int mat = add_material(s, base, 0.0f, 0.5f);
  add_quad_z(s, -10, 10, -10, 10, 0, mat);
  s.lights.push_back(point_light({1, 0, 1}, 2.0f));
  WhittedConfig cfg;
  cfg.ambient = {0.05f, 0.05f, 0.05f};
  const Ray r{{0, 0, 1}, 0, {0, 0, -1}, kInfinity};
  float coverage = 0;
  RayCounts counts;
  const Vec3f L = shade(s, cfg, r, coverage, counts);

  // Closed form at p = 0, n = v = +z, light at (1, 0, 1): d^2 = 2, E = 2 / 2 = 1.
  const double ndotl = 1 / std::sqrt(2.0);
  const double ndoth = std::cos(M_PI / 8);     // h halfway between v (0 deg) and l (45 deg)
  const double p = 2 / std::pow(0.25, 2) - 2;  // 30
  const double spec = 0.04 * (p + 8) / (8 * M_PI) * std::pow(ndoth, p) * ndotl;
  for (int c = 0; c < 3; ++c) {
    const double expected = base[c] * 0.05 + 1.0 * (base[c] / M_PI * ndotl + spec);
    CHECK(L[c] == Approx(expected).epsilon(1e-4));
  }
  CHECK(coverage == 1);
  CHECK(counts.camera == 1);
  CHECK(counts.shadow == 1);
}

TEST_CASE("a point in shadow gets ambient only, counted once for all lights", "[whitted][quick]") {
  Scene s;
  const Vec3f base{0.5f, 0.5f, 0.5f};
  const int mat = add_material(s, base, 0.0f, 1.0f);
  add_quad_z(s, -10, 10, -10, 10, 0, mat);
  add_quad_z(s, -0.5f, 0.5f, -0.5f, 0.5f, 0.5f, mat);  // occluder over the shaded point
  s.lights.push_back(point_light({0.2f, 0, 2}, 5.0f));
  s.lights.push_back(point_light({-0.2f, 0.1f, 3}, 7.0f));
  WhittedConfig cfg;
  cfg.ambient = {0.1f, 0.2f, 0.3f};
  // Camera ray grazing under the occluder towards the origin.
  const Ray r{{-2, 0, 0.25f}, 0, normalize(Vec3f{2, 0, -0.25f}), kInfinity};
  float coverage = 0;
  RayCounts counts;
  const Vec3f L = shade(s, cfg, r, coverage, counts);
  CHECK(L.x == Approx(0.5 * 0.1));
  CHECK(L.y == Approx(0.5 * 0.2));
  CHECK(L.z == Approx(0.5 * 0.3));
  CHECK(counts.shadow == 2);
  // Remove the occluder: now the lights add to the same ambient.
  s.meshes.pop_back();
  s.instances.pop_back();
  const Vec3f lit = shade(s, cfg, r, coverage, counts);
  CHECK(lit.x > L.x + 0.1f);
}

TEST_CASE("a mirror reflects a known colour, limited by max depth", "[whitted][quick]") {
  Scene s;
  const int mirror = add_material(s, {0.9f, 0.9f, 0.9f}, 1.0f, 0.0f);
  const Vec3f wall_colour{0.2f, 0.4f, 0.6f};
  const int wall = add_material(s, wall_colour, 0, 1, /*unlit=*/true);
  add_quad_z(s, -10, 10, -10, 10, 0, mirror);
  add_quad_x(s, 3, -10, 10, -10, 10, wall);
  WhittedConfig cfg;
  cfg.ambient = {0, 0, 0};
  const Ray r{{0, 0, 1}, 0, normalize(Vec3f{1, 0, -1}), kInfinity};
  float coverage = 0;
  RayCounts counts;
  const Vec3f L = shade(s, cfg, r, coverage, counts);
  CHECK(L.x == Approx(0.9 * 0.2));
  CHECK(L.y == Approx(0.9 * 0.4));
  CHECK(L.z == Approx(0.9 * 0.6));
  CHECK(counts.reflection == 1);
  cfg.max_depth = 0;
  const Vec3f none = shade(s, cfg, r, coverage, counts);
  CHECK(none == Vec3f{0, 0, 0});
}

TEST_CASE("escaping rays see the background with zero coverage", "[whitted][quick]") {
  Scene s;
  WhittedConfig cfg;
  cfg.background = {0.25f, 0.5f, 1};
  float coverage = 1;
  RayCounts counts;
  const Vec3f L = shade(s, cfg, {{0, 0, 0}, 0, {0, 0, -1}, kInfinity}, coverage, counts);
  CHECK(L == cfg.background);
  CHECK(coverage == 0);
}

TEST_CASE("analytic and implicit spheres shade with the closed-form Lambert term in every back end",
          "[whitted][shapes]") {
  // A unit sphere centred at (0, 0, -3) seen from the origin: the hit is (0, 0, -2) with n = +z,
  // lit by a point light at the eye, d = 2, n.l = n.h = 1 (roughness 1: Blinn-Phong exponent 0).
  const Vec3f base{0.8f, 0.6f, 0.4f};
  for (bool implicit : {false, true}) {
    Scene s;
    const int mat = add_material(s, base, 0.0f, 1.0f);
    add_shape(s, sphere_shape(1, implicit), translation({0, 0, -3}), mat);
    s.lights.push_back(point_light({0, 0, 0}, 4.0f));
    WhittedConfig cfg;
    cfg.ambient = {0.05f, 0.05f, 0.05f};
    for (const auto& name : accelerator_names()) {
      INFO((implicit ? "implicit" : "analytic") << " sphere, " << name);
      const auto accel = make_scene_accelerator(name, s);
      float coverage = 0;
      RayCounts counts;
      const Vec3f L = whitted_radiance(s, *accel, cfg, {{0, 0, 0}, 0, {0, 0, -1}, kInfinity},
                                       RayDifferential{}, coverage, counts);
      const WhittedParams w = whitted_params(s.materials[size_t(mat)]);
      const double norm = (w.exponent + 8) / (8 * M_PI);  // Blinn-Phong normalisation, n.h = 1
      for (int c = 0; c < 3; ++c) {
        const double expected = w.ka[c] * 0.05 + 1.0 * (w.kd[c] / M_PI + w.ks[c] * norm);
        CHECK(L[c] == Approx(expected).epsilon(implicit ? 1e-3 : 1e-5));
      }
      CHECK(coverage == 1);
      // Off-centre: n.l = cos of the angle at the hit (light at the eye: l = v), from the quadratic.
      const Vec3f d = normalize(Vec3f{0.2f, 0.1f, -3});
      const Vec3f L2 =
          whitted_radiance(s, *accel, cfg, {{0, 0, 0}, 0, d, kInfinity}, RayDifferential{}, coverage, counts);
      float t = 0;
      REQUIRE(intersect_sphere({{0, 0, 0}, 0, d, kInfinity}, {0, 0, -3}, 1, t));
      const Vec3f p = d * t, n = normalize(p - Vec3f{0, 0, -3});
      const double ndotl = dot(n, -d), E = 4.0 / double(t * t);
      const double spec = w.ks.x * norm * std::pow(ndotl, w.exponent) * ndotl;  // h = l = v: n.h = n.l
      CHECK(L2.x ==
            Approx(w.ka.x * 0.05 + E * (w.kd.x / M_PI * ndotl + spec)).epsilon(implicit ? 2e-3 : 1e-4));
    }
  }
}

TEST_CASE("a shape casts shadows and shows in a mirror, with no self-shadowing", "[whitted][shapes][quick]") {
  Scene s;
  const Vec3f base{0.5f, 0.5f, 0.5f};
  const int mat = add_material(s, base, 0.0f, 1.0f);
  add_quad_z(s, -10, 10, -10, 10, 0, mat);
  add_shape(s, sphere_shape(0.25f, true), translation({0, 0, 0.75f}), mat);  // over the origin
  s.lights.push_back(point_light({0, 0, 3}, 5.0f));
  WhittedConfig cfg;
  cfg.ambient = {0.1f, 0.1f, 0.1f};
  const auto accel = make_scene_accelerator("bvh", s);
  float coverage = 0;
  RayCounts counts;
  // The floor point under the sphere is in its shadow: ambient only.
  const Vec3f under =
      whitted_radiance(s, *accel, cfg, {{-2, 0, 0.1f}, 0, normalize(Vec3f{2, 0, -0.1f}), kInfinity},
                       RayDifferential{}, coverage, counts);
  CHECK(under.x == Approx(0.5 * 0.1));
  // The sphere's top faces the light: lit, not shadowed by itself.
  const Vec3f top = whitted_radiance(s, *accel, cfg, {{0, 0, 2}, 0, {0, 0, -1}, kInfinity}, RayDifferential{},
                                     coverage, counts);
  CHECK(top.x > 0.5 * 0.1 + 0.1);
  // A mirror sphere reflects the unlit wall behind the camera.
  Scene m;
  const int mirror = add_material(m, {0.9f, 0.9f, 0.9f}, 1.0f, 0.0f);
  const int wall = add_material(m, {0.2f, 0.4f, 0.6f}, 0, 1, /*unlit=*/true);
  add_shape(m, sphere_shape(1), translation({0, 0, -3}), mirror);
  add_quad_z(m, -10, 10, -10, 10, 1, wall);
  cfg.ambient = {0, 0, 0};
  const auto maccel = make_scene_accelerator("kdtree", m);
  const Vec3f refl = whitted_radiance(m, *maccel, cfg, {{0, 0, 0}, 0, {0, 0, -1}, kInfinity},
                                      RayDifferential{}, coverage, counts);
  CHECK(refl.z == Approx(0.9 * 0.6));
}
