// Tests for renderer/environment: the map convention, rotation, and importance sampling
// (the pdf integrates to 1, samples carry the density env_pdf reports, and the estimator of
// the environment's irradiance matches quadrature).
#include "renderer/lights/environment.h"

#include <catch2/catch.hpp>

#include "renderer/core/rng.h"
#include "support/scene_builder.h"

using namespace penumbra;
using test::check_vec;

namespace {
// A 32 x 16 sky: a dim gradient and one bright 2 x 2 "sun".
Environment test_sky(float rotation = 0) {
  const int w = 32, h = 16;
  std::vector<Vec3f> t(size_t(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t[size_t(y * w + x)] = Vec3f{0.2f, 0.3f, 0.5f} * (1.0f - float(y) / h);
  for (int y = 3; y < 5; ++y)
    for (int x = 20; x < 22; ++x) t[size_t(y * w + x)] = {200, 180, 150};
  return make_map_environment(w, h, t, 1.5f, rotation);
}

// Integral over the sphere of g(dir) by a fine (theta, phi) midpoint rule.
template <class G>
double sphere_integral(G&& g, int nt = 800, int np = 1600) {
  double sum = 0;
  for (int i = 0; i < nt; ++i) {
    const double th = (i + 0.5) * M_PI / nt;
    for (int j = 0; j < np; ++j) {
      const double ph = (j + 0.5) * 2 * M_PI / np;
      const Vec3f d{float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                    float(std::sin(th) * std::sin(ph))};
      sum += g(d) * std::sin(th);
    }
  }
  return sum * (M_PI / nt) * (2 * M_PI / np);
}
}  // namespace

TEST_CASE("environment: the map's centre is -Z, +X is to its right, the top row is +Y",
          "[environment][quick]") {
  const Environment e = test_sky();
  const Vec2f front = env_direction_to_uv(e, {0, 0, -1});
  CHECK(front.x == Approx(0.5));
  CHECK(front.y == Approx(0.5));
  CHECK(env_direction_to_uv(e, {1, 0, 0}).x == Approx(0.75));
  CHECK(env_direction_to_uv(e, {0, 1, 0}).y == Approx(0).margin(1e-6));
  // Round trips, and a 90 degree rotation turns -Z's texel to where +X was... seen from above,
  // counter-clockwise: the map's centre now lies towards -X.
  for (Vec3f d : {Vec3f{0.3f, 0.5f, -0.8f}, Vec3f{-0.9f, -0.1f, 0.2f}})
    check_vec(env_uv_to_direction(e, env_direction_to_uv(e, normalize(d))), normalize(d), 1e-5f);
  const Environment r = test_sky(kPi / 2);
  check_vec(env_uv_to_direction(r, {0.5f, 0.5f}), {-1, 0, 0}, 1e-6f);
  CHECK(env_eval(r, {-1, 0, 0}) == env_eval(e, {0, 0, -1}));
}

TEST_CASE("environment: the sampling density integrates to 1 and matches the samples",
          "[environment][quick]") {
  for (float rot : {0.0f, 1.0f}) {
    const Environment e = test_sky(rot);
    CHECK(sphere_integral([&](Vec3f d) { return env_pdf(e, d); }) == Approx(1).epsilon(0.01));
    // Each sample reports the density env_pdf gives for its direction and the radiance
    // env_eval gives; the estimator of the irradiance-like integral of luminance matches.
    double est = 0;
    const int n = 1 << 16;
    Rng rng;
    for (int i = 0; i < n; ++i) {
      Vec3f d, l;
      float pdf = 0;
      REQUIRE(env_sample(e, {rng.next_float(), rng.next_float()}, d, l, pdf));
      CHECK(length(d) == Approx(1).epsilon(1e-5));
      REQUIRE(pdf == env_pdf(e, d));
      REQUIRE(l == env_eval(e, d));
      est += luminance(l) * std::max(0.0f, d.y) / pdf;
    }
    const double ref =
        sphere_integral([&](Vec3f d) { return luminance(env_eval(e, d)) * std::max(0.0f, d.y); }, 1600, 3200);
    CHECK(est / n == Approx(ref).epsilon(0.01));
  }
  // A constant environment samples the sphere uniformly.
  const Environment c = make_constant_environment({1, 2, 3});
  CHECK(env_pdf(c, {0, 1, 0}) == Approx(1 / (4 * M_PI)));
  CHECK(env_eval(c, {0, 0, 1}) == Vec3f{1, 2, 3});
  CHECK(is_black(make_constant_environment({0, 0, 0})));
  CHECK(is_black(make_map_environment(2, 1, {{0, 0, 0}, {0, 0, 0}}, 1, 0)));
  CHECK_THROWS_AS(make_map_environment(2, 2, {{1, 1, 1}}, 1, 0), std::invalid_argument);
}

TEST_CASE(
    "environment: a cube map resampled to the map keeps each face on its axis, and turns with the "
    "rotation",
    "[env][quick]") {
  // Six flat faces, each its own colour; face k has colour e_k-ish (distinct per face).
  const Vec3f colours[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
  std::vector<Vec3f> faces[6];
  for (int f = 0; f < 6; ++f) faces[f].assign(4 * 4, colours[f]);
  const Vec3f axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const Environment env =
      make_map_environment(64, 32, equirect_from_cube(faces, 4, 64, 32, {0, 0, 0, 1}), 1, 0);
  for (int f = 0; f < 6; ++f) {
    INFO("face " << f);
    check_vec(env_eval(env, axes[f]), colours[f]);
    // Directions 30 degrees off the axis still see the same face.
    const Vec3f off = normalize(axes[f] + Vec3f{0.3f, 0.2f, 0.25f} * 0.5f);
    if (dot(off, axes[f]) > 0.9f) check_vec(env_eval(env, off), colours[f]);
  }
  // Turned by +90 degrees about +Y (which carries +X to -Z): -Z now sees the +X face.
  const float h = std::sqrt(0.5f);
  const Environment turned =
      make_map_environment(64, 32, equirect_from_cube(faces, 4, 64, 32, {0, h, 0, h}), 1, 0);
  check_vec(env_eval(turned, {0, 0, -1}), colours[0]);
  check_vec(env_eval(turned, {0, 1, 0}), colours[2]);  // the axis of the turn keeps its face
  // The OpenGL face orientation: on +X, s runs along -Z and t along -Y (row 0 is the top, +Y).
  std::vector<Vec3f> marked[6];
  for (int f = 0; f < 6; ++f) marked[f].assign(4 * 4, Vec3f{0, 0, 0});
  marked[0][0] = {1, 1, 1};  // +X face, top-left texel: towards +Y and +Z
  const Environment m =
      make_map_environment(256, 128, equirect_from_cube(marked, 4, 256, 128, {0, 0, 0, 1}), 1, 0);
  check_vec(env_eval(m, normalize(Vec3f{1, 0.8f, 0.8f})), {1, 1, 1});
  check_vec(env_eval(m, normalize(Vec3f{1, 0.8f, -0.8f})), {0, 0, 0});
}
