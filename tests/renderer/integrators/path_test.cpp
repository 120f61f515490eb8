// Validation of the path tracer (renderer/path, render_path) against analytic answers:
// furnaces (a closed emitting enclosure gives the geometric series; a convex white object in a
// uniform environment vanishes; a rough metal keeps all energy with compensation and loses exactly its
// single-scattering albedo without), MIS against the single techniques, the Whitted diffuse term, a square
// area light's form factor with one- and two-sided emission, thin transmission, stochastic alpha, the
// 1/sqrt(spp) convergence rate, determinism across threads, and the time limit and adaptive sampling.
#include "renderer/integrators/path.h"

#include <atomic>
#include <catch2/catch.hpp>
#include <cstring>

#include "io/gltf/loader.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/materials/bsdf.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct Rendered {
  PathImage image;
  RenderStats stats;
};

Rendered render(const Scene& s, const Environment& env, const Camera& cam, const RenderConfig& cfg) {
  const auto accel = make_scene_accelerator("embree", s);
  const AreaLights al = build_area_lights(s);
  Rendered r;
  r.image = render_path(s, *accel, PathLights{&al, &env}, cam, cfg, &r.stats);
  return r;
}

RenderConfig small_config(int w, int h, int spp) {
  return small_render_config(w, h, spp);
}

double channel_mean(const Film& f, int c) {
  double sum = 0;
  for (size_t i = 0; i < f.rgba.size(); i += 4) sum += f.rgba[i + size_t(c)];
  return sum / double(f.rgba.size() / 4);
}

// Mean luminance of the image and its standard error (from each pixel's sample variance).
std::pair<double, double> mean_and_error(const PathImage& img) {
  double sum = 0, var = 0;
  const size_t n = img.samples.size();
  for (size_t i = 0; i < n; ++i) {
    sum += luminance({img.film.rgba[i * 4], img.film.rgba[i * 4 + 1], img.film.rgba[i * 4 + 2]});
    var += img.variance[i];
  }
  return {sum / double(n), std::sqrt(var) / double(n)};
}

// The image's mean and standard error with MIS, BSDF sampling alone and light sampling alone.
std::vector<std::pair<double, double>> strategy_means(const Scene& s, const Environment& env,
                                                      const Camera& cam, RenderConfig cfg) {
  std::vector<std::pair<double, double>> results;
  for (LightStrategy st : {LightStrategy::Mis, LightStrategy::Bsdf, LightStrategy::Light}) {
    cfg.path.strategy = st;
    results.push_back(mean_and_error(render(s, env, cam, cfg).image));
  }
  return results;
}

// The three estimators of strategy_means() agree within 4 standard errors, the comparison is
// tight (within 5% of the mean), and MIS is no noisier than either single technique.
void check_strategies_agree(const std::vector<std::pair<double, double>>& results) {
  const auto [mis, mis_err] = results[0];
  INFO("mis " << mis << " +- " << mis_err << ", bsdf " << results[1].first << " +- " << results[1].second
              << ", light " << results[2].first << " +- " << results[2].second);
  for (int k : {1, 2}) {
    const double tolerance =
        4 * std::sqrt(mis_err * mis_err + results[size_t(k)].second * results[size_t(k)].second);
    CHECK(std::fabs(results[size_t(k)].first - mis) < tolerance);
    CHECK(tolerance < 0.05 * mis);
    CHECK(mis_err <= results[size_t(k)].second * 1.05);
  }
}

// The mean of `n` samples of one camera ray's radiance.
Vec3f ray_mean(const Scene& s, const Environment& env, const PathConfig& pc, const Ray& ray, int n) {
  const auto accel = make_scene_accelerator("embree", s);
  const AreaLights al = build_area_lights(s);
  Vec3f sum{0, 0, 0};
  RayCounts counts;
  for (int i = 0; i < n; ++i) {
    SampleStream st = make_sample_stream(SamplerType::Sobol, 0, 0, uint32_t(i), 7);
    float coverage = 0;
    sum += path_radiance(s, *accel, PathLights{&al, &env}, pc, ray, RayDifferential{}, st, coverage, counts);
  }
  return sum / float(n);
}

// Form factor from a point to a parallel rectangle [0, a] x [0, b] at height h whose corner
// lies straight above it (Siegel & Howell), used by quadrants.
double corner_form_factor(double a, double b, double h) {
  const double x = a / h, y = b / h;
  return (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
          y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y))) /
         (2 * M_PI);
}

}  // namespace

TEST_CASE("path: a closed emitting enclosure converges to the geometric series", "[path][heavy]") {
  // Camera inside a closed sphere of albedo a emitting Le: L = Le (1 + a + ... + a^(D+1)) for
  // max depth D (light reaching hits 0..D), i.e. Le / (1 - a) as D grows.
  const Camera cam = look_at({0.1f, 0.2f, 0}, {1, 0.3f, 0.2f}, {0, 1, 0}, 1.2f);
  struct Case {
    float albedo;
    int depth;
    double expected;
  };
  for (const Case& c : {Case{0.0f, 12, 1.0}, Case{0.5f, 40, 2.0}, Case{0.5f, 2, 1 + 0.5 + 0.25 + 0.125},
                        Case{1.0f, 3, 5.0}}) {
    INFO("albedo " << c.albedo << ", max depth " << c.depth);
    Scene s;
    add_sphere(s, {0, 0, 0}, 3, 3, add_lambert(s, {c.albedo, c.albedo, c.albedo}, {1, 1, 1}));
    RenderConfig cfg = small_config(4, 4, 4096);
    cfg.path.max_depth = c.depth;
    cfg.path.rr_depth = 64;  // exact depth accounting; roulette is tested below
    const Rendered r = render(s, make_constant_environment({0, 0, 0}), cam, cfg);
    CHECK(channel_mean(r.image.film, 0) == Approx(c.expected).epsilon(0.005));
    CHECK(channel_mean(r.image.film, 3) == 1.0);
    // Every pixel converges: within 1% at 4096 spp.
    for (size_t i = 0; i < r.image.film.rgba.size(); i += 4)
      REQUIRE(r.image.film.rgba[i] == Approx(c.expected).epsilon(0.01));
  }
  // Russian roulette keeps the estimate unbiased.
  Scene s;
  add_sphere(s, {0, 0, 0}, 3, 3, add_lambert(s, {0.5f, 0.5f, 0.5f}, {1, 1, 1}));
  RenderConfig cfg = small_config(8, 8, 256);
  cfg.path.max_depth = 40;
  cfg.path.rr_depth = 1;
  CHECK(channel_mean(render(s, make_constant_environment({0, 0, 0}), cam, cfg).image.film, 1) ==
        Approx(2.0).epsilon(0.01));
}

TEST_CASE("path: white furnace: a convex white object in a uniform environment vanishes", "[path]") {
  Scene s;
  add_sphere(s, {0, 0, 0}, 1, 3, add_lambert(s, {1, 1, 1}));
  const Camera cam = look_at({0, 0.5f, 4}, {0, 0, 0}, {0, 1, 0}, 0.6f);
  const Rendered r = render(s, make_constant_environment({1, 1, 1}), cam, small_config(6, 6, 4096));
  CHECK(channel_mean(r.image.film, 3) > 0.5);  // the sphere covers most of the image
  CHECK(channel_mean(r.image.film, 0) == Approx(1).epsilon(0.002));
  for (size_t i = 0; i < r.image.film.rgba.size(); i += 4)
    REQUIRE(r.image.film.rgba[i + 1] == Approx(1).epsilon(0.01));
}

TEST_CASE("path: furnace: analytic and implicit spheres of albedo 1/2 in a uniform environment",
          "[path][shapes]") {
  // A convex object never sees itself, so under environment 1 a Lambertian of albedo 1/2
  // reflects exactly 1/2 (KHR_materials_specular factor 0 leaves the diffuse lobe alone, and
  // cosine sampling makes the BSDF samples exact; light samples add noise): a self-intersection or a leak
  // shows as a darker or brighter pixel. Checked with every back end.
  for (bool implicit : {false, true})
    for (const auto& name : accelerator_names()) {
      INFO((implicit ? "implicit" : "analytic") << " sphere, " << name);
      Scene s;
      Affine3f place = translation({0.1f, -0.1f, 0});
      place.m[0][0] = place.m[1][1] = place.m[2][2] = 1.5f;  // scaled by the instance
      const int mat = add_lambert(s, {0.5f, 0.5f, 0.5f});
      s.materials[size_t(mat)].specular = 0;
      add_shape(s, sphere_shape(0.8f, implicit), place, mat);
      const Camera cam = look_at({0, 0.5f, 4}, {0, 0, 0}, {0, 1, 0}, 0.6f);
      const auto accel = make_scene_accelerator(name, s);
      const AreaLights al = build_area_lights(s);
      const Environment env = make_constant_environment({1, 1, 1});
      const PathImage img =
          render_path(s, *accel, PathLights{&al, &env}, cam, small_config(8, 8, 1024), nullptr);
      size_t covered = 0;
      for (size_t i = 0; i < img.film.rgba.size(); i += 4) {
        const float a = img.film.rgba[i + 3], g = img.film.rgba[i + 1];
        if (a == 1) {
          ++covered;
          REQUIRE(g == Approx(0.5f).epsilon(0.02));
        } else if (a == 0) {
          REQUIRE(g == Approx(1.0f).epsilon(1e-6));
        }
      }
      CHECK(covered >= 16);
    }
}

TEST_CASE("path: GGX furnace: a rough metal keeps all energy compensated, single scattering's without",
          "[path]") {
  // Looking straight down at a white rough metal plane under environment 1, every pixel is the
  // BRDF's directional albedo at normal incidence (by quadrature here): 1 with energy
  // compensation, the single-scattering albedo without it.
  for (float roughness : {0.5f, 0.75f, 1.0f})
    for (const bool compensate : {false, true}) {
      INFO("roughness " << roughness << (compensate ? ", compensated" : ", single scattering"));
      Scene s;
      add_quad_z(s, -100, 100, -100, 100, 0, add_material(s, {1, 1, 1}, 1, roughness));
      GltfBsdf b;
      b.metallic = 1;
      b.roughness = roughness;
      b.energy_compensation = compensate;
      double albedo = 0;
      const int nm = 4000, np = 64;
      for (int i = 0; i < nm; ++i) {
        const double mu = (i + 0.5) / nm;
        for (int j = 0; j < np; ++j) {
          const double phi = (j + 0.5) * 2 * M_PI / np, st = std::sqrt(1 - mu * mu);
          albedo +=
              bsdf_eval(b, {0, 0, 1}, {float(st * std::cos(phi)), float(st * std::sin(phi)), float(mu)}).x *
              mu;
        }
      }
      albedo *= (1.0 / nm) * (2 * M_PI / np);
      if (compensate)
        CHECK(albedo == Approx(1).epsilon(0.005));
      else
        CHECK(albedo < 0.99);  // some energy is lost: the test can tell
      Camera cam = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1);
      cam.projection = Projection::Orthographic;
      cam.ymag = 0.5f;
      RenderConfig cfg = small_config(8, 8, 512);
      cfg.path.energy_compensation = compensate;
      const Rendered r = render(s, make_constant_environment({1, 1, 1}), cam, cfg);
      CHECK(channel_mean(r.image.film, 0) == Approx(albedo).epsilon(0.02));
    }
}

TEST_CASE("path: MIS, BSDF sampling alone and light sampling alone agree in the mean", "[path]") {
  // A rough floor, a glossy metal block, a one-sided emissive quad and a sky map with a sun.
  Scene s;
  add_quad_z(s, -4, 4, -4, 4, 0, add_material(s, {0.7f, 0.6f, 0.5f}, 0, 0.4f));
  const int metal = add_material(s, {0.9f, 0.7f, 0.4f}, 1, 0.35f);
  add_quad_x(s, 0.5f, -1, 1, 0, 1.5f, metal);
  add_quad_z(s, -1.5f, -0.5f, -0.5f, 0.5f, 2, add_lambert(s, {0, 0, 0}, {6, 5, 4}, false), /*flip=*/true);
  const int w = 32, h = 16;
  std::vector<Vec3f> sky(size_t(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) sky[size_t(y * w + x)] = Vec3f{0.3f, 0.4f, 0.6f} * (y < h / 2 ? 1.0f : 0.2f);
  for (int y = 2; y < 4; ++y)
    for (int x = 10; x < 13; ++x) sky[size_t(y * w + x)] = {30, 28, 24};
  const Environment env = make_map_environment(w, h, sky, 1, 0.3f);
  const Camera cam = look_at({0.5f, -4, 3}, {0, 0, 0.5f}, {0, 0, 1}, 0.9f);
  RenderConfig cfg = small_config(24, 24, 512);
  cfg.sampler = SamplerType::Independent;  // independent samples: the error estimate is honest
  cfg.path.max_depth = 3;
  const auto results = strategy_means(s, env, cam, cfg);
  CHECK(results[0].first > 0.1);
  check_strategies_agree(results);
}

TEST_CASE(
    "path: emissive shapes: MIS, BSDF or light sampling alone, and every light sampler agree in the mean",
    "[path][shapes]") {
  // A rough floor lit only by emissive shapes: a sphere placed by a similarity (sampled by its
  // cone), a sphere stretched into an ellipsoid, a one-sided disk facing down, a sheared box and
  // a capsule (sampled by area, densities through the placement's area scale).
  Scene s;
  add_quad_z(s, -4, 4, -4, 4, 0, add_material(s, {0.7f, 0.6f, 0.5f}, 0, 0.5f));
  const auto emitter = [&](Vec3f le, bool two_sided) { return add_lambert(s, {0, 0, 0}, le, two_sided); };
  add_shape(s, sphere_shape(0.3f), translation({-1.2f, 0.5f, 0.8f}), emitter({8, 6, 4}, false));
  Affine3f stretched = translation({1.0f, 1.0f, 0.6f});
  stretched.m[0][0] = 0.6f, stretched.m[1][1] = 0.2f, stretched.m[2][2] = 0.3f, stretched.m[0][1] = 0.15f;
  add_shape(s, sphere_shape(1), stretched, emitter({3, 5, 8}, false));
  Shape disk;
  disk.kind = ShapeKind::Disk;
  disk.radius = 0.5f;
  Affine3f down = translation({0.2f, -1.0f, 2.0f});  // +Y (the disk's front) to -Z
  down.m[1][1] = 0, down.m[1][2] = 1, down.m[2][1] = -1, down.m[2][2] = 0;
  add_shape(s, disk, down, emitter({6, 6, 6}, false));
  Shape box;
  box.kind = ShapeKind::Box;
  box.half_size = {0.2f, 0.1f, 0.15f};
  Affine3f sheared = translation({0.8f, -1.2f, 0.4f});
  sheared.m[0][1] = 0.5f, sheared.m[2][0] = 0.3f;
  add_shape(s, box, sheared, emitter({4, 2, 1}, true));
  Shape capsule;
  capsule.kind = ShapeKind::Capsule;
  capsule.radius = 0.1f;
  capsule.half_height = 0.4f;
  add_shape(s, capsule, translation({-0.5f, -0.8f, 0.5f}), emitter({2, 6, 3}, false));
  REQUIRE(build_area_lights(s).shapes.size() == 5);
  const Environment env = make_constant_environment({0, 0, 0});
  const Camera cam = look_at({0.3f, -4, 3}, {0, 0, 0.5f}, {0, 0, 1}, 0.9f);
  RenderConfig cfg = small_config(24, 24, 256);
  cfg.sampler = SamplerType::Independent;
  cfg.path.max_depth = 2;
  cfg.path.light_sampler = LightSampler::Tree;
  const auto results = strategy_means(s, env, cam, cfg);
  const auto [mis, mis_err] = results[0];
  CHECK(mis > 0.05);
  check_strategies_agree(results);
  // Light sampling through the tree finds the small shapes that BSDF sampling rarely hits:
  // less noise.
  CHECK(results[2].second < results[1].second);
  // The light tree (above), the power table and uniform choice agree.
  cfg.path.strategy = LightStrategy::Mis;
  for (LightSampler sampler : {LightSampler::Power, LightSampler::Uniform}) {
    cfg.path.light_sampler = sampler;
    const auto [m, err] = mean_and_error(render(s, env, cam, cfg).image);
    INFO("sampler " << int(sampler) << ": " << m << " +- " << err);
    CHECK(std::fabs(m - mis) < 4 * std::sqrt(mis_err * mis_err + err * err));
  }
  // Four light samples a vertex, weighted as one technique of four samples against the BSDF's:
  // the same mean as one; light sampling alone too.
  cfg.path.light_sampler = LightSampler::Tree;
  cfg.path.light_samples = 4;
  for (LightStrategy st : {LightStrategy::Mis, LightStrategy::Light}) {
    cfg.path.strategy = st;
    const auto [m, err] = mean_and_error(render(s, env, cam, cfg).image);
    INFO("strategy " << int(st) << ", 4 light samples: " << m << " +- " << err);
    CHECK(std::fabs(m - mis) < 4 * std::sqrt(mis_err * mis_err + err * err));
  }
}

TEST_CASE("path: a Lambertian plane under a point light equals the Whitted diffuse term", "[path][quick]") {
  Scene s;
  const Vec3f albedo{0.8f, 0.6f, 0.4f};
  add_quad_z(s, -10, 10, -10, 10, 0, add_lambert(s, albedo));
  s.lights.push_back(point_light({1, 0, 1}, 2.0f));
  const Ray ray{{0, 0, 1}, 0, {0, 0, -1}, kInfinity};
  PathConfig pc;
  const Vec3f path = ray_mean(s, make_constant_environment({0, 0, 0}), pc, ray, 4);
  WhittedConfig wc;
  wc.ambient = {0, 0, 0};
  const auto accel = make_scene_accelerator("embree", s);
  float coverage = 0;
  RayCounts counts;
  const Vec3f whitted = whitted_radiance(s, *accel, wc, ray, RayDifferential{}, coverage, counts);
  // Both: albedo / pi x cos 45 deg x E, with E = 2 / d^2 = 1.
  const Vec3f expected = albedo * float(1 / (M_PI * std::sqrt(2.0)));
  check_vec(path, expected, 1e-6f);
  check_vec(whitted, expected, 1e-6f);
}

TEST_CASE("path: many point and spot lights chosen among the lights equal all of them evaluated", "[path]") {
  // Twelve lights over a grey floor and a box: past the evaluated limit they are chosen one per
  // vertex (tree, power table or uniformly) and divided by their probability; the image's mean
  // equals that of evaluating each at every vertex.
  Scene s;
  add_quad_z(s, -10, 10, -10, 10, 0, add_lambert(s, {0.5f, 0.5f, 0.5f}));
  add_shape(s, sphere_shape(0.5f), translation({0, 0, 0.5f}), add_lambert(s, {0.8f, 0.3f, 0.2f}));
  for (int i = 0; i < 12; ++i) {
    const float a = float(i) * 0.52f;
    Light l = point_light({3 * std::cos(a), 3 * std::sin(a), 1.0f + 0.2f * float(i % 4)}, 1.0f + float(i));
    if (i % 3 == 0) {
      l.type = LightType::Spot;
      l.direction = normalize(Vec3f{-std::cos(a), -std::sin(a), -1});
      l.outer_cone = 0.6f;
      l.inner_cone = 0.3f;
    }
    s.lights.push_back(l);
  }
  const Camera cam = look_at({0, -6, 4}, {0, 0, 0}, {0, 0, 1}, 0.8f);
  RenderConfig cfg = small_config(24, 16, 64);
  cfg.path.max_depth = 3;
  const Environment env = make_constant_environment({0, 0, 0});
  const auto accel = make_scene_accelerator("embree", s);
  const AreaLights all = build_area_lights(s, 12), chosen = build_area_lights(s);
  REQUIRE(all.pmf.empty());
  REQUIRE(chosen.punctual.size() == 12);
  const auto [exact, exact_err] = mean_and_error(render_path(s, *accel, PathLights{&all, &env}, cam, cfg));
  for (LightSampler sampler : {LightSampler::Tree, LightSampler::Power, LightSampler::Uniform}) {
    cfg.path.light_sampler = sampler;
    const auto [m, err] = mean_and_error(render_path(s, *accel, PathLights{&chosen, &env}, cam, cfg));
    INFO("sampler " << int(sampler) << ": " << m << " +- " << err << ", every light " << exact << " +- "
                    << exact_err);
    CHECK(std::fabs(m - exact) < 4 * std::sqrt(exact_err * exact_err + err * err));
    CHECK(err < 0.02 * exact);
    // Four lights chosen at each vertex: the same mean, less noise.
    cfg.path.light_samples = 4;
    const auto [m4, err4] = mean_and_error(render_path(s, *accel, PathLights{&chosen, &env}, cam, cfg));
    cfg.path.light_samples = 1;
    INFO("4 light samples: " << m4 << " +- " << err4);
    CHECK(std::fabs(m4 - exact) < 4 * std::sqrt(exact_err * exact_err + err4 * err4));
    CHECK(err4 < 0.7 * err);
  }
}

TEST_CASE("path: a square area light gives its form factor; one-sided lights emit forward only", "[path]") {
  // A 2 x 2 light at height 1 straight above a Lambertian point of albedo rho: L = rho Le F,
  // F = 4 F_corner(1, 1, 1).
  const double rho = 0.5, le = 2, f = 4 * corner_form_factor(1, 1, 1);
  const Ray ray{{0, 0, 5}, 0, {0, 0, -1}, kInfinity};  // through the light's culled back face
  PathConfig pc;
  pc.max_depth = 0;  // direct light only
  struct Case {
    bool facing_down, double_sided;
    double expected;
  };
  for (const Case& c : {Case{true, false, rho * le * f}, Case{false, false, 0.0},
                        Case{false, true, rho * le * f}, Case{true, true, rho * le * f}}) {
    INFO("facing down " << c.facing_down << ", double-sided " << c.double_sided);
    Scene s;
    add_quad_z(s, -10, 10, -10, 10, 0, add_lambert(s, {float(rho), float(rho), float(rho)}));
    add_quad_z(s, -1, 1, -1, 1, 1,
               add_lambert(s, {0, 0, 0}, {float(le), float(le), float(le)}, c.double_sided),
               /*flip=*/c.facing_down);
    Ray r = ray;
    if (c.double_sided || !c.facing_down) r.org = {0, 0, 0.5f};  // start below a light that faces the view
    for (LightStrategy st : {LightStrategy::Mis, LightStrategy::Light, LightStrategy::Bsdf}) {
      pc.strategy = st;
      const Vec3f l = ray_mean(s, make_constant_environment({0, 0, 0}), pc, r, 4096);
      CHECK(l.x == Approx(c.expected).margin(0.01 * rho * le * f));
    }
  }
}

TEST_CASE("path: thin transmission passes the background through, tinted", "[path][quick]") {
  // A transmissive plane with no specular layer: all light passes straight on, times base.
  Scene s;
  const int glass = add_material(s, {1, 0.5f, 0.25f}, 0, 0.2f);
  s.materials[size_t(glass)].transmission = 1;
  s.materials[size_t(glass)].specular = 0;
  add_quad_z(s, -10, 10, -10, 10, 0, glass);
  const Ray ray{{0.3f, 0.1f, 1}, 0, {0, 0, -1}, kInfinity};
  check_vec(ray_mean(s, make_constant_environment({2, 2, 2}), PathConfig{}, ray, 16), {2, 1, 0.5f}, 1e-5f);
  CHECK(ior_to_f0(1.5f) == Approx(0.04));
  CHECK(ior_to_f0(0) == 1);
}

TEST_CASE("path: Blend alpha is the hit probability", "[path][quick]") {
  Scene s;
  const int m = add_material(s, {1, 1, 1}, 0, 1, /*unlit=*/true);
  s.materials[size_t(m)].alpha_mode = AlphaMode::Blend;
  s.materials[size_t(m)].alpha = 0.25f;
  add_quad_z(s, -1, 1, -1, 1, 0, m);
  Camera cam = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 0.5f;
  const Rendered r = render(s, make_constant_environment({0, 0, 0}), cam, small_config(4, 4, 256));
  CHECK(channel_mean(r.image.film, 0) == Approx(0.25).epsilon(0.02));
  CHECK(channel_mean(r.image.film, 3) == Approx(0.25).epsilon(0.02));
}

TEST_CASE("path: the error falls as 1/sqrt(spp)", "[path][heavy]") {
  // RMSE against a 16384-spp reference at 16, 64 and 256 spp: log-log slope -1/2 for
  // independent samples; the Owen-scrambled Sobol sampler converges at least as fast.
  Scene s;
  add_quad_z(s, -10, 10, -10, 10, 0, add_lambert(s, {0.5f, 0.5f, 0.5f}));
  add_quad_z(s, -1, 1, -1, 1, 1, add_lambert(s, {0, 0, 0}, {2, 2, 2}, false), true);
  add_quad_x(s, 0.6f, -3, 0.2f, 0, 0.6f, add_lambert(s, {0.8f, 0.8f, 0.8f}));  // casts a soft shadow
  Camera cam = look_at({0.5f, -2, 0.8f}, {0, 0, 0}, {0, 0, 1}, 1.0f);
  RenderConfig cfg = small_config(12, 12, 16384);
  cfg.path.max_depth = 1;
  for (SamplerType type : {SamplerType::Independent, SamplerType::Sobol}) {
    cfg.sampler = type;
    cfg.spp = 16384;
    cfg.seed = 99;
    const Film ref = render(s, make_constant_environment({0, 0, 0}), cam, cfg).image.film;
    std::vector<double> xs, ys;
    for (int spp : {16, 64, 256}) {
      cfg.spp = spp;
      double mse = 0;
      const int trials = 4;
      for (int t = 0; t < trials; ++t) {
        cfg.seed = uint64_t(t);
        const Film f = render(s, make_constant_environment({0, 0, 0}), cam, cfg).image.film;
        for (size_t i = 0; i < f.rgba.size(); i += 4) mse += std::pow(double(f.rgba[i]) - ref.rgba[i], 2);
      }
      xs.push_back(std::log(double(spp)));
      ys.push_back(0.5 * std::log(mse / (trials * 144.0)));
    }
    const double mx = (xs[0] + xs[1] + xs[2]) / 3, my = (ys[0] + ys[1] + ys[2]) / 3;
    double sxy = 0, sxx = 0;
    for (int k = 0; k < 3; ++k) {
      sxy += (xs[size_t(k)] - mx) * (ys[size_t(k)] - my);
      sxx += (xs[size_t(k)] - mx) * (xs[size_t(k)] - mx);
    }
    const double slope = sxy / sxx;
    INFO((type == SamplerType::Sobol ? "sobol" : "independent") << " slope " << slope);
    if (type == SamplerType::Independent)
      CHECK(slope == Approx(-0.5).margin(0.08));
    else
      CHECK(slope < -0.45);
  }
}

TEST_CASE("path: the image is bit-identical for any thread count, tile size and time limit", "[path]") {
  LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  const Scene& s = loaded.scene;
  const Environment env = make_constant_environment({0.1f, 0.1f, 0.12f});
  RenderConfig cfg = small_config(48, 27, 8);
  cfg.filter = make_filter(FilterType::BlackmanHarris, 1.5f);
  cfg.adaptive_threshold = 0.05f;
  cfg.adaptive_min_spp = 4;
  std::vector<Rendered> runs;
  for (int threads : {1, 2, 3}) {
    cfg.threads = threads;
    cfg.tile_size = 5 + threads * 4;
    runs.push_back(render(s, env, s.cameras.at(0), cfg));
    CHECK(runs.back().stats.threads == threads);
  }
  for (int k : {1, 2}) {
    CHECK(std::memcmp(runs[0].image.film.rgba.data(), runs[size_t(k)].image.film.rgba.data(),
                      runs[0].image.film.rgba.size() * sizeof(float)) == 0);
    CHECK(runs[0].image.samples == runs[size_t(k)].image.samples);
  }
  // Adaptive sampling stopped some pixels early, but not all.
  const auto [lo, hi] = std::minmax_element(runs[0].image.samples.begin(), runs[0].image.samples.end());
  CHECK(*lo == 4);
  CHECK(*hi == 8);
  // A time limit that ends the render after the first pass gives exactly the 1-spp image.
  cfg.adaptive_threshold = 0;
  cfg.time_limit = 1e-9;
  const Rendered limited = render(s, env, s.cameras.at(0), cfg);
  CHECK(limited.stats.passes == 1);
  CHECK(limited.stats.time_limited);
  cfg.time_limit = 0;
  cfg.spp = 1;
  const Rendered one = render(s, env, s.cameras.at(0), cfg);
  CHECK(std::memcmp(limited.image.film.rgba.data(), one.image.film.rgba.data(),
                    one.image.film.rgba.size() * sizeof(float)) == 0);
  CHECK(path_pass_ends(40) == std::vector<int>{1, 2, 4, 8, 16, 32, 40});
}

TEST_CASE("path: adaptive sampling spends samples where the noise is", "[path]") {
  // Left half: an unlit black quad (no variance); right half: a noisy soft-lit floor.
  Scene s;
  add_quad_z(s, -10, 0, -10, 10, 0, add_material(s, {0, 0, 0}, 0, 1, /*unlit=*/true));
  add_quad_z(s, 0, 10, -10, 10, 0, add_lambert(s, {0.5f, 0.5f, 0.5f}));
  add_quad_z(s, -1, 3, -1, 1, 2, add_lambert(s, {0, 0, 0}, {3, 3, 3}, false), true);
  Camera cam = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 1;
  RenderConfig cfg = small_config(16, 16, 256);
  cfg.adaptive_threshold = 0.02f;
  cfg.adaptive_min_spp = 8;
  const Rendered adaptive = render(s, make_constant_environment({0, 0, 0}), cam, cfg);
  cfg.adaptive_threshold = 0;
  const Rendered full = render(s, make_constant_environment({0, 0, 0}), cam, cfg);
  CHECK(adaptive.image.samples[size_t(8 * 16 + 2)] == 8);   // black: stops at the minimum
  CHECK(adaptive.image.samples[size_t(8 * 16 + 12)] > 64);  // lit: keeps sampling
  CHECK(adaptive.stats.samples < full.stats.samples);
  CHECK(channel_mean(adaptive.image.film, 0) == Approx(channel_mean(full.image.film, 0)).epsilon(0.02));
}

TEST_CASE("path: clamping indirect light bounds each indirect sample", "[path][quick]") {
  // In the emitting enclosure every indirect sample carries <= the clamp.
  Scene s;
  add_sphere(s, {0, 0, 0}, 3, 2, add_lambert(s, {0.9f, 0.9f, 0.9f}, {1, 1, 1}));
  const Camera cam = look_at({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 1.0f);
  RenderConfig cfg = small_config(4, 4, 64);
  const double unclamped =
      channel_mean(render(s, make_constant_environment({0, 0, 0}), cam, cfg).image.film, 0);
  cfg.path.clamp_indirect = 0.01f;
  const double clamped =
      channel_mean(render(s, make_constant_environment({0, 0, 0}), cam, cfg).image.film, 0);
  CHECK(unclamped == Approx((1 - std::pow(0.9, 14)) / 0.1).epsilon(0.03));  // max depth 12
  // Emission seen directly (1) and direct light at the first hit (0.9) are kept; each of at most
  // max_depth = 12 indirect contributions adds at most 0.01.
  CHECK(clamped >= 1.9 * 0.98);
  CHECK(clamped <= 1.9 + 12 * 0.01 + 0.02);
}

TEST_CASE("path: a render stopped between passes and resumed equals the uninterrupted render",
          "[path][resume]") {
  LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  const Scene& s = loaded.scene;
  const auto accel = make_scene_accelerator("embree", s);
  const AreaLights al = build_area_lights(s);
  const Environment env = make_constant_environment({0.1f, 0.1f, 0.12f});
  const PathLights lights{&al, &env};
  RenderConfig cfg = small_config(24, 14, 40);
  cfg.adaptive_threshold = 0.05f;
  cfg.adaptive_min_spp = 4;
  cfg.light_groups = true;
  const PathImage whole = render_path(s, *accel, lights, s.cameras.at(0), cfg);

  // Stop after the third pass (4 spp), as a signal handler would.
  std::atomic<bool> stop{false};
  cfg.stop = &stop;
  PathAccumulators state;
  RenderStats first;
  render_path(s, *accel, lights, s.cameras.at(0), cfg, &first, {}, &state, [&](const PathAccumulators& st) {
    if (st.passes == 3) stop = true;
  });
  CHECK(first.passes == 3);
  CHECK(state.reached == 4);
  CHECK_FALSE(state.complete);
  // Resume (a copy, as if read back from disk) to the same spp.
  cfg.stop = nullptr;
  PathAccumulators copy = state;
  RenderStats second;
  const PathImage resumed = render_path(s, *accel, lights, s.cameras.at(0), cfg, &second, {}, &copy);
  CHECK(copy.complete);
  CHECK(second.passes == int(path_pass_ends(40).size()) - 3);
  CHECK(second.image_passes == int(path_pass_ends(40).size()));  // the image's, the first run's included
  CHECK(std::memcmp(whole.film.rgba.data(), resumed.film.rgba.data(),
                    whole.film.rgba.size() * sizeof(float)) == 0);
  CHECK(whole.samples == resumed.samples);
  CHECK(whole.groups == resumed.groups);
  CHECK(whole.variance == resumed.variance);
}

namespace {
// A slab between z = 0 (facing +z) and z = -depth (facing -z) of a volume material.
int add_volume_slab(Scene& s, float depth, float ior, float roughness, Vec3f attenuation, float distance) {
  const int glass = add_material(s, {1, 1, 1}, 0, roughness);
  Material& m = s.materials[size_t(glass)];
  m.transmission = 1;
  m.ior = ior;
  m.volume = true;
  m.attenuation_color = attenuation;
  m.attenuation_distance = distance;
  add_quad_z(s, -50, 50, -50, 50, 0, glass);
  add_quad_z(s, -50, 50, -50, 50, -depth, glass, true);
  return glass;
}
}  // namespace

TEST_CASE("path: Beer-Lambert: a clear-index volume slab transmits attenuation^(depth / distance)",
          "[path][quick]") {
  Scene s;
  add_volume_slab(s, 0.5f, 1.0f, 0.0f, {0.8f, 0.5f, 0.2f}, 0.25f);
  const Ray ray{{0.3f, 0.1f, 1}, 0, {0, 0, -1}, kInfinity};
  // depth / distance = 2: the colour squared.
  check_vec(ray_mean(s, make_constant_environment({1, 1, 1}), PathConfig{}, ray, 16), {0.64f, 0.25f, 0.04f},
            1e-4f);
}

TEST_CASE("path: a smooth absorbing glass slab at normal incidence gives the Fresnel-Airy sum", "[path]") {
  // Reflectance F = 0.04 at each face, one pass through transmits a; every path ends in the uniform
  // environment, so the pixel is R + T with
  //   R = F + (1-F)^2 F a^2 / (1 - F^2 a^2),   T = (1-F)^2 a / (1 - F^2 a^2).
  Scene s;
  const float depth = 0.3f, distance = 0.6f;
  add_volume_slab(s, depth, 1.5f, 0.0f, {0.5f, 0.5f, 0.5f}, distance);
  const double F = 0.04, a = std::pow(0.5, depth / distance);
  const double expect = F + ((1 - F) * (1 - F) * (F * a * a + a)) / (1 - F * F * a * a);
  PathConfig pc;
  pc.max_depth = 64;
  pc.rr_depth = 64;
  const Ray ray{{0.3f, 0.1f, 1}, 0, {0, 0, -1}, kInfinity};
  const Vec3f got = ray_mean(s, make_constant_environment({1, 1, 1}), pc, ray, 20000);
  CHECK(got.x == Approx(expect).epsilon(0.01));
  CHECK(got.x < 0.9);  // the absorption shows (a clear slab would give 1)
}

TEST_CASE("path: white furnace: a closed smooth glass sphere in a uniform environment vanishes", "[path]") {
  // The analytic sphere: its shading normal is the geometric one, so no path is lost where a
  // mesh's interpolated normals disagree with its facets.
  Scene s;
  const int glass = add_material(s, {1, 1, 1}, 0, 0.0f);
  s.materials[size_t(glass)].transmission = 1;
  s.materials[size_t(glass)].volume = true;
  add_shape(s, sphere_shape(1), translation({0, 0, 0}), glass);
  PathConfig pc;
  pc.max_depth = 64;
  for (float x : {0.0f, 0.5f, 0.9f}) {
    const Ray ray{{x, 0.05f, 5}, 0, {0, 0, -1}, kInfinity};
    INFO("offset " << x);
    const Vec3f got = ray_mean(s, make_constant_environment({1, 1, 1}), pc, ray, 4000);
    CHECK(got.x == Approx(1).epsilon(0.02));
  }
}

TEST_CASE("path: diffuse transmission lights a thin sheet from behind: E c / pi", "[path][quick]") {
  Scene s;
  const int leaf = add_material(s, {0, 0, 0}, 0, 1.0f);
  Material& m = s.materials[size_t(leaf)];
  m.specular = 0;  // no Fresnel layer: f = c / pi on the far side
  m.diffuse_transmission = 1;
  m.diffuse_transmission_color = {0.6f, 0.3f, 0.9f};
  add_quad_z(s, -10, 10, -10, 10, 0, leaf);
  s.lights.push_back(point_light({0, 0, -2}, 8));
  const Ray ray{{0, 0, 1}, 0, {0, 0, -1}, kInfinity};
  PathConfig pc;
  pc.max_depth = 0;
  const float e = 8.0f / 4;  // I / d^2 at normal incidence
  check_vec(ray_mean(s, make_constant_environment({0, 0, 0}), pc, ray, 4),
            Vec3f{0.6f, 0.3f, 0.9f} * (e / kPi), 1e-4f);
}

TEST_CASE("path: thin transmission under a clear coat and sheen sends on no more than arrives", "[path]") {
  // A uniform white environment seen through a thin clear-coated, sheened glass plane: every
  // path ends in the environment, so the pixel is the plane's total reflectance + transmittance,
  // at most 1 (the coat and sheen attenuate what the thin lobe passes).
  Scene s;
  const int glass = add_material(s, {1, 1, 1}, 0, 0.3f);
  Material& m = s.materials[size_t(glass)];
  m.transmission = 1;
  m.clearcoat = 1;
  m.clearcoat_roughness = 0.1f;
  m.sheen_color = {1, 1, 1};
  m.sheen_roughness = 0.5f;
  add_quad_z(s, -50, 50, -50, 50, 0, glass);
  PathConfig pc;
  pc.max_depth = 32;
  for (float angle : {0.0f, 0.6f, 1.2f}) {
    const Ray ray{{0, 0, 1}, 0, {std::sin(angle), 0, -std::cos(angle)}, kInfinity};
    INFO("angle " << angle);
    const Vec3f got = ray_mean(s, make_constant_environment({1, 1, 1}), pc, ray, 20000);
    CHECK(got.x <= 1.01f);
    CHECK(got.x > 0.5f);
  }
}
