// Gaussian splats ray traced: one Gaussian against its closed form (the distance of the ray from
// its centre), overlapping splats blended in depth order whatever the build order, structure,
// thread count or tiles, a sphere of opaque splats against a sphere (depth and id AOVs), a
// mirror reflecting splats, splats shadowing a mesh, the path tracer seeing the same, and
// Cryptomatte coverage split between a splat and the surface behind it.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/accel/factory.h"
#include "renderer/film/cryptomatte.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/path.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/integrators/whitted.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// Adds a cloud of isotropic splats (linear colours, degree 0) placed by `to_world`.
void add_splats(Scene& s, const std::vector<Vec3f>& centres, const std::vector<float>& sigma,
                const std::vector<float>& opacity, const std::vector<Vec3f>& colour,
                const Affine3f& to_world = {}, int node = -1) {
  SplatCloud c;
  c.color_space = SplatColorSpace::LinRec709Display;
  for (size_t i = 0; i < centres.size(); ++i) {
    c.positions.push_back(centres[i]);
    c.rotations.push_back({0, 0, 0, 1});
    c.scales.push_back({sigma[i], sigma[i], sigma[i]});
    c.opacities.push_back(opacity[i]);
    c.sh.push_back((colour[i] - Vec3f{0.5f, 0.5f, 0.5f}) / 0.2820947917738781f);
  }
  s.splat_clouds.push_back(c);
  s.splat_instances.push_back({int(s.splat_clouds.size()) - 1, to_world, node});
}

Vec3f whitted(const Scene& s, const Accelerator& accel, const Ray& r, float& coverage) {
  WhittedConfig cfg;
  cfg.ambient = {0, 0, 0};
  RayCounts counts;
  return whitted_radiance(s, accel, cfg, r, RayDifferential{}, coverage, counts);
}

}  // namespace

TEST_CASE("splats: one Gaussian seen along a ray is opacity exp(-d^2 / 2 sigma^2) in every structure",
          "[splats][trace][quick]") {
  // Opacity 0.8: cut at 3 sigma (the last two rays pass 3.07 and 3.4 sigma from the centre);
  // opacity 0.02: cut where 0.02 exp(-u^2 / 2) < 1/255, beyond u = 1.805.
  const Vec3f colour{0.9f, 0.5f, 0.1f};
  for (float opacity : {0.8f, 0.02f}) {
    Scene s;
    add_splats(s, {{0, 0, -3}}, {0.5f}, {opacity}, {colour});
    int cut = 0, seen = 0;
    for (const std::string& name : accelerator_names()) {
      INFO(name << " opacity " << opacity);
      const auto accel = make_scene_accelerator(name, s);
      REQUIRE(splat_accelerator(*accel) != nullptr);
      for (float x : {0.0f, 0.1f, 0.3f, 0.7f, 0.95f, 1.2f, 1.49f, 1.6f, 1.75f, 1.95f}) {
        const Ray r{{0, 0, 0}, 0, normalize(Vec3f{x, 0.2f * x, -3}), kInfinity};
        // The distance of the ray's line from the centre, by the cross product.
        const float d = length(cross(r.dir, Vec3f{0, 0, -3}));
        const float u = d / 0.5f;
        const float peak = opacity * std::exp(-0.5f * u * u);
        const float alpha = u <= 3 && peak >= 1.0f / 255 ? peak : 0.0f;
        cut += alpha == 0;
        seen += alpha > 0;
        float coverage = 0;
        const Vec3f L = whitted(s, *accel, r, coverage);
        CHECK(coverage == Approx(alpha).margin(1e-5));
        check_vec(L, colour * alpha, 1e-5f);
      }
    }
    CHECK(cut > 0);
    CHECK(seen > 0);
  }
}

TEST_CASE("splats: overlapping splats blend front to back in depth order, in chunks, in every structure",
          "[splats][trace][quick]") {
  // 60 splats along the view axis (more than the k-buffer holds), added in a shuffled order,
  // against the compositing of the closed-form responses sorted by depth here.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u01(0, 1);
  std::vector<Vec3f> centres, colours;
  std::vector<float> sigma, opacity;
  for (int i = 0; i < 60; ++i) {
    centres.push_back({0.05f * (u01(rng) - 0.5f), 0.05f * (u01(rng) - 0.5f), -2 - 6 * u01(rng)});
    sigma.push_back(0.1f + 0.2f * u01(rng));
    opacity.push_back(0.02f + 0.1f * u01(rng));
    colours.push_back({u01(rng), u01(rng), u01(rng)});
  }
  const Ray r{{0, 0, 0}, 0, {0, 0, -1}, kInfinity};
  struct Entry {
    float t, alpha;
    Vec3f c;
  };
  std::vector<Entry> sorted;
  for (size_t i = 0; i < centres.size(); ++i) {  // isotropic: t* is the centre's projection
    const float t = -centres[i].z;
    const float d2 = centres[i].x * centres[i].x + centres[i].y * centres[i].y;
    sorted.push_back({t, opacity[i] * std::exp(-0.5f * d2 / (sigma[i] * sigma[i])), colours[i]});
  }
  std::sort(sorted.begin(), sorted.end(), [](const Entry& a, const Entry& b) { return a.t < b.t; });
  Vec3f want{0, 0, 0};
  float T = 1;
  for (const Entry& e : sorted) {
    want += e.c * (T * e.alpha);
    T *= 1 - e.alpha;
  }
  REQUIRE(T > kSplatMinTransmittance);
  for (int order = 0; order < 3; ++order) {
    std::vector<size_t> perm(centres.size());
    for (size_t i = 0; i < perm.size(); ++i) perm[i] = i;
    if (order == 1) std::reverse(perm.begin(), perm.end());
    if (order == 2) std::shuffle(perm.begin(), perm.end(), rng);
    Scene s;
    std::vector<Vec3f> c2, k2;
    std::vector<float> s2, o2;
    for (size_t i : perm)
      c2.push_back(centres[i]), k2.push_back(colours[i]), s2.push_back(sigma[i]), o2.push_back(opacity[i]);
    // Split over two clouds, the second placed by a translation that puts it back.
    const size_t half = c2.size() / 2;
    add_splats(s, {c2.begin(), c2.begin() + long(half)}, {s2.begin(), s2.begin() + long(half)},
               {o2.begin(), o2.begin() + long(half)}, {k2.begin(), k2.begin() + long(half)});
    std::vector<Vec3f> moved(c2.begin() + long(half), c2.end());
    for (Vec3f& p : moved) p = p - Vec3f{1, 2, 3};
    add_splats(s, moved, {s2.begin() + long(half), s2.end()}, {o2.begin() + long(half), o2.end()},
               {k2.begin() + long(half), k2.end()}, translation({1, 2, 3}));
    for (const std::string& name : accelerator_names()) {
      INFO(name << " order " << order);
      const auto accel = make_scene_accelerator(name, s);
      const SplatLayer layer = blend_splats(s, *splat_accelerator(*accel), r, kInfinity);
      CHECK(layer.count == 60);
      check_vec(layer.radiance, want, 2e-5f);
      CHECK(layer.transmittance == Approx(T).margin(2e-6));
      // Splats beyond tend are left for what lies behind the surface there.
      const SplatLayer front = blend_splats(s, *splat_accelerator(*accel), r, 5);
      int n = 0;
      for (const Entry& e : sorted) n += e.t <= 5;
      CHECK(front.count == n);
    }
  }
}

TEST_CASE("splats: a dense layer stops at the transmittance threshold and hides what is behind",
          "[splats][trace][quick]") {
  Scene s;
  const int red = add_material(s, {1, 0, 0}, 0, 1, /*unlit=*/true);
  add_quad_z(s, -5, 5, -5, 5, -10, red);
  add_splats(s, {{0, 0, -3}, {0, 0, -3.2f}, {0, 0, -3.4f}}, {0.5f, 0.5f, 0.5f}, {0.99f, 0.99f, 0.99f},
             {{0, 1, 0}, {0, 0, 1}, {1, 1, 1}});
  const auto accel = make_scene_accelerator("bvh", s);
  float coverage = 0;
  const Vec3f L = whitted(s, *accel, {{0, 0, 0}, 0, {0, 0, -1}, kInfinity}, coverage);
  // 0.99 then 0.01 x 0.99 leaves 1e-4 < 1e-3: the layer stops there; the third splat and the
  // red wall behind are hidden.
  check_vec(L, Vec3f{0, 0.99f, 0.01f * 0.99f}, 1e-5f);
  CHECK(coverage == 1);
}

TEST_CASE("splats: a mirror reflects them and they shadow a mesh through their opacity",
          "[splats][trace][quick]") {
  Scene s;
  const int mirror = add_material(s, {1, 1, 1}, 1.0f, 0.0f);
  add_quad_z(s, -10, 10, -10, 10, 0, mirror);
  // A splat the camera ray (0, 0, 1) -> (1, 0, -1) meets only after the mirror, at (3, 0, 2).
  const Vec3f colour{0.2f, 0.7f, 0.4f};
  add_splats(s, {{3, 0, 2}}, {0.3f}, {0.9f}, {colour});
  const auto accel = make_scene_accelerator("embree", s);
  float coverage = 0;
  const Vec3f L = whitted(s, *accel, {{0, 0, 1}, 0, normalize(Vec3f{1, 0, -1}), kInfinity}, coverage);
  check_vec(L, colour * 0.9f, 1e-4f);

  // Shadows: a point light above a Lambertian floor, a splat on the shadow ray of the floor's
  // point below it: the light there is scaled by 1 - its opacity.
  Scene f;
  const int grey = add_lambert(f, {0.5f, 0.5f, 0.5f});
  add_quad_z(f, -10, 10, -10, 10, 0, grey);
  f.lights.push_back(point_light({0, 0, 4}, 10));
  const Ray down{{0, 0, 2}, 0, {0, 0, -1}, kInfinity};
  float c0 = 0, c1 = 0;
  const Vec3f lit = whitted(f, *make_scene_accelerator("embree", f), down, c0);
  add_splats(f, {{0, 0, 3}}, {0.2f}, {0.7f}, {{1, 1, 1}});
  const auto shadowed_accel = make_scene_accelerator("embree", f);
  const Vec3f shadowed = whitted(f, *shadowed_accel, down, c1);
  REQUIRE(lit.x > 0);
  CHECK(shadowed.x == Approx(lit.x * 0.3f).epsilon(1e-4));
  CHECK(shadow_transmittance(f, *shadowed_accel, Ray{{0, 0, 0.01f}, 0, {0, 0, 1}, 3.9f}, true) ==
        Approx(0.3f));
}

TEST_CASE("splats: the path tracer sees their baked radiance over what lies behind",
          "[splats][trace][quick]") {
  Scene s;
  const Vec3f colour{0.3f, 0.6f, 0.9f};
  add_splats(s, {{0, 0, -3}}, {0.5f}, {0.6f}, {colour});
  const auto accel = make_scene_accelerator("embree", s);
  const AreaLights al = build_area_lights(s);
  const Environment env = make_constant_environment({0.5f, 0.5f, 0.5f});
  PathConfig pc;
  SampleStream st = make_sample_stream(SamplerType::Sobol, 0, 0, 0, 7);
  float coverage = 0;
  RayCounts counts;
  const Ray r{{0, 0, 0}, 0, {0, 0, -1}, kInfinity};
  const Vec3f L =
      path_radiance(s, *accel, PathLights{&al, &env}, pc, r, RayDifferential{}, st, coverage, counts);
  check_vec(L, colour * 0.6f + Vec3f{0.5f, 0.5f, 0.5f} * 0.4f, 1e-5f);
  CHECK(coverage == Approx(0.6f));
}

TEST_CASE("splats: a sphere of opaque splats occludes like a sphere (depth and id AOVs)", "[splats][trace]") {
  const float R = 1, scale = 0.02f;
  Scene splats, sphere;
  SplatSphereConfig sc;
  sc.radius = R;
  sc.count = 40000;
  sc.tangent_scale = scale;
  splats.splat_clouds.push_back(make_splat_sphere(sc));
  splats.splat_instances.push_back({0, Affine3f{}, 4});
  const int white = add_lambert(sphere, {1, 1, 1});
  add_shape(sphere, sphere_shape(R), Affine3f{}, white, 4);
  const Camera cam = look_at({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 0.6f);
  const RenderConfig cfg = small_render_config(48, 48, 1);
  const DataAovs a =
      render_data_aovs(splats, *make_scene_accelerator("bvh", splats), cam, cfg, IntegratorType::Whitted);
  const DataAovs b =
      render_data_aovs(sphere, *make_scene_accelerator("bvh", sphere), cam, cfg, IntegratorType::Whitted);
  int both = 0, differ = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      const size_t i = size_t(y) * 48 + size_t(x);
      const Ray ray = camera_sample_ray(cam, cfg, IntegratorType::Whitted, x, y, 0);
      const float d = length(cross(normalize(ray.dir), ray.org));  // ray's distance from the centre
      if (a.object_id[i] != b.object_id[i]) {
        ++differ;  // only along the silhouette, within the splats' reach
        CHECK(std::abs(d - R) <= kSplatSigmas * scale);
        continue;
      }
      if (b.object_id[i] == 0) continue;
      CHECK(a.object_id[i] == 5);
      ++both;
      // The median splat lies within its spread of the sphere, seen at a grazing angle up to
      // the footprint of one splat across its own plane.
      const float cos_view = std::sqrt(std::max(0.0f, 1 - (d / R) * (d / R)));
      const float tol = kSplatSigmas * scale / std::max(cos_view, 0.2f);
      CHECK(a.depth[i] == Approx(b.depth[i]).margin(tol));
      const Vec3f na{a.normal[i * 3], a.normal[i * 3 + 1], a.normal[i * 3 + 2]};
      const Vec3f nb{b.normal[i * 3], b.normal[i * 3 + 1], b.normal[i * 3 + 2]};
      if (cos_view > 0.3f) CHECK(dot(na, nb) > 0.95f);
    }
  CHECK(both > 500);
  CHECK(differ < both / 10);
}

TEST_CASE("splats: the same image for any thread count, tile size and structure", "[splats][trace]") {
  Scene s;
  SplatSphereConfig sc;
  sc.count = 3000;
  sc.opacity = 0.6f;
  s.splat_clouds.push_back(make_splat_sphere(sc));
  s.splat_instances.push_back({0, Affine3f{}, -1});
  const int grey = add_lambert(s, {0.5f, 0.5f, 0.5f});
  add_quad_z(s, -3, 3, -3, 3, -1.5f, grey);
  s.lights.push_back(point_light({0, 0, 5}, 20));
  const Camera cam = look_at({0.3f, 0.2f, 4}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  RenderConfig base = small_render_config(40, 32, 2, 8);
  base.threads = 1;
  const auto bvh = make_scene_accelerator("bvh", s);
  const Film ref = render_whitted(s, *bvh, cam, base);
  RenderConfig other = base;
  other.threads = 2;
  other.tile_size = 5;
  CHECK(render_whitted(s, *bvh, cam, other).rgba == ref.rgba);
  for (const char* name : {"kdtree", "grid", "octree", "bsp", "brute", "embree"}) {
    INFO(name);
    const Film f = render_whitted(s, *make_scene_accelerator(name, s), cam, other);
    double worst = 0;
    for (size_t i = 0; i < f.rgba.size(); ++i)
      worst = std::max(worst, double(std::abs(f.rgba[i] - ref.rgba[i])));
    CHECK(worst < 1e-4);
  }
}

TEST_CASE("splats: Cryptomatte gives a splat layer its opacity of a sample, the surface behind the rest",
          "[splats][trace][quick]") {
  // A wide splat of opacity 0.6 (sigma 20 pixels) over an opaque quad: at the splat's centre
  // the splat's cloud takes 0.6 of the pixel, the quad 0.4 (in eighths of a sample).
  Scene s;
  s.instances[size_t(add_quad_z(s, -5, 5, -5, 5, -1, add_lambert(s, {0.5f, 0.5f, 0.5f})))].node = 0;
  add_splats(s, {{0, 0, 0}}, {1}, {0.6f}, {{1, 1, 1}}, Affine3f{}, 1);
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 2);
  cam.projection = Projection::Orthographic;
  cam.ymag = 0.2f;
  const auto accel = make_scene_accelerator("bvh", s);
  const float quad = crypto_id("quad"), cloud = crypto_id("cloud");
  const std::vector<CryptoLayerIds> layers = {{"CryptoObject", {quad, cloud}}};
  const CryptoImage img = render_cryptomatte(s, *accel, cam, small_render_config(4, 4, 16, 4),
                                             IntegratorType::Whitted, layers, 2);
  const float* p = &img.layers[0][size_t(1 * 4 + 1) * size_t(img.channels)];
  CHECK(p[0] == cloud);
  CHECK(p[1] == Approx(0.6f).margin(0.07f));
  CHECK(p[2] == quad);
  CHECK(p[3] == Approx(0.4f).margin(0.07f));
  CHECK(p[1] + p[3] == Approx(1));
}
