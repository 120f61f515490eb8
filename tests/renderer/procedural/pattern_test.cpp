// Tests for renderer/procedural/pattern: the colour ramp's three interpolations, the mapping's
// Euler order, the wave profiles against their closed forms, every pattern's gradient against
// central differences, and the footprint filter's effect on the pattern's variance.
#include "renderer/procedural/pattern.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

using namespace penumbra;

namespace {

ProceduralTexture pattern(PatternKind kind) {
  ProceduralTexture t;
  t.kind = kind;
  t.seed = 7;
  t.table = make_perlin_table(t.seed);
  return t;
}

bool near(Vec3f a, Vec3f b, float eps = 1e-5f) {
  return length(a - b) <= eps;
}

// Central differences of t at q with step h.
Vec3f numeric_gradient(const ProceduralTexture& t, Vec3f q, float h) {
  Vec3f g;
  for (int a = 0; a < 3; ++a) {
    Vec3f lo = q, hi = q;
    lo[a] -= h;
    hi[a] += h;
    g[a] = (eval_pattern(t, hi, 0).t - eval_pattern(t, lo, 0).t) / (2 * h);
  }
  return g;
}

}  // namespace

TEST_CASE("pattern: the colour ramp interpolates linearly, constantly or smoothly and clamps",
          "[procedural][pattern][quick]") {
  ColorRamp r;
  r.stops = {{0.2f, {0, 0, 0}}, {0.6f, {1, 0.5f, 0}}, {0.6f, {0, 0, 1}}, {1, {1, 1, 1}}};
  CHECK(eval_ramp(r, -1) == Vec3f{0, 0, 0});
  CHECK(eval_ramp(r, 0.2f) == Vec3f{0, 0, 0});
  CHECK(eval_ramp(r, 2) == Vec3f{1, 1, 1});
  CHECK(near(eval_ramp(r, 0.3f), {0.25f, 0.125f, 0}));
  CHECK(near(eval_ramp(r, 0.8f), {0.5f, 0.5f, 1}));  // past the coincident stops: the second one
  r.interpolation = RampInterpolation::Constant;
  CHECK(near(eval_ramp(r, 0.59f), {0, 0, 0}));
  CHECK(near(eval_ramp(r, 0.61f), {0, 0, 1}));
  r.interpolation = RampInterpolation::Smoothstep;
  // s = 0.25 -> 3 s^2 - 2 s^3 = 0.15625.
  CHECK(near(eval_ramp(r, 0.3f), {0.15625f, 0.078125f, 0}));
  CHECK(near(eval_ramp(r, 0.4f), {0.5f, 0.25f, 0}));  // the midpoint is the same for all
  ColorRamp one;
  one.stops = {{0.5f, {0.1f, 0.2f, 0.3f}}};
  CHECK(eval_ramp(one, 0) == Vec3f{0.1f, 0.2f, 0.3f});
  CHECK(eval_ramp(one, 1) == Vec3f{0.1f, 0.2f, 0.3f});
}

TEST_CASE("pattern: the mapping scales, then rotates about X, Y, Z, then translates",
          "[procedural][pattern][quick]") {
  CHECK(near(apply_point(procedural_mapping({}, {90, 0, 0}, {1, 1, 1}), {0, 1, 0}), {0, 0, 1}));
  CHECK(near(apply_point(procedural_mapping({}, {0, 90, 0}, {1, 1, 1}), {0, 0, 1}), {1, 0, 0}));
  CHECK(near(apply_point(procedural_mapping({}, {0, 0, 90}, {1, 1, 1}), {1, 0, 0}), {0, 1, 0}));
  // X first: y -> z (X), then z stays (Z). Z second: x -> y.
  const Affine3f m = procedural_mapping({1, 2, 3}, {90, 0, 90}, {2, 2, 2});
  CHECK(near(apply_point(m, {0, 1, 0}), {1, 2, 3 + 2}));
  CHECK(near(apply_point(m, {1, 0, 0}), {1, 2 + 2, 3}));
}

TEST_CASE("pattern: wave bands and rings follow their closed forms", "[procedural][pattern][quick]") {
  ProceduralTexture t = pattern(PatternKind::Wave);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-3, 3);
  for (int i = 0; i < 200; ++i) {
    const Vec3f q{u(rng), u(rng), u(rng)};
    t.wave = {WaveType::Bands, 1, WaveProfile::Sine, 0};
    CHECK(eval_pattern(t, q, 0).t == Approx(0.5f + 0.5f * std::sin(2 * kPi * q.y)).margin(1e-5));
    t.wave = {WaveType::Rings, 2, WaveProfile::Saw, 0};
    const float r = std::hypot(q.x, q.y);
    CHECK(eval_pattern(t, q, 0).t == Approx(r - std::floor(r)).margin(1e-5));
    t.wave = {WaveType::Bands, 0, WaveProfile::Triangle, 0};
    const float f = q.x - std::floor(q.x);
    CHECK(eval_pattern(t, q, 0).t == Approx(1 - std::fabs(2 * f - 1)).margin(1e-5));
  }
}

TEST_CASE("pattern: every pattern's gradient matches central differences", "[procedural][pattern][quick]") {
  std::vector<ProceduralTexture> cases;
  for (FractalKind k : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged}) {
    ProceduralTexture t = pattern(PatternKind::Noise);
    t.fractal.kind = k;
    t.fractal.detail = 2.5f;
    t.fractal.distortion = k == FractalKind::Fbm ? 0.3f : 0;
    cases.push_back(t);
  }
  ProceduralTexture wave = pattern(PatternKind::Wave);
  wave.wave = {WaveType::Rings, 1, WaveProfile::Sine, 0.4f};
  wave.fractal.detail = 2;
  cases.push_back(wave);
  ProceduralTexture cells = pattern(PatternKind::Voronoi);
  cells.voronoi.feature = WorleyFeature::F2MinusF1;
  cases.push_back(cells);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-4, 4);
  for (size_t c = 0; c < cases.size(); ++c) {
    int checked = 0;
    for (int i = 0; i < 300; ++i) {
      const Vec3f q{u(rng), u(rng), u(rng)};
      const PatternSample s = eval_pattern(cases[c], q, 0);
      const Vec3f fine = numeric_gradient(cases[c], q, 2.5e-4f),
                  coarse = numeric_gradient(cases[c], q, 4e-3f);
      // Skip points next to a kink (|noise| = 0, a ridge weight's clamp, a Voronoi edge): there
      // steps of different size disagree.
      if (length(fine - coarse) > 0.01f * (1 + length(fine))) continue;
      ++checked;
      INFO("case " << c << " at " << q.x << " " << q.y << " " << q.z);
      CHECK(length(s.grad - fine) <= 0.02f * (1 + length(fine)));
    }
    CHECK(checked > 200);
  }
}

TEST_CASE("pattern: a wider footprint drops octaves and lowers the variance towards the mean",
          "[procedural][pattern][quick]") {
  ProceduralTexture t = pattern(PatternKind::Noise);
  t.fractal.detail = 8;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-50, 50);
  std::vector<Vec3f> points(4000);
  for (Vec3f& p : points) p = {u(rng), u(rng), u(rng)};
  auto variance = [&](float footprint) {
    double s = 0, s2 = 0;
    for (Vec3f p : points) {
      const double v = eval_pattern(t, p, footprint).t;
      s += v;
      s2 += v * v;
    }
    const double mean = s / double(points.size());
    return s2 / double(points.size()) - mean * mean;
  };
  double previous = variance(0);
  for (float w : {0.01f, 0.1f, 0.4f}) {
    const double v = variance(w);
    INFO("footprint " << w);
    CHECK(v < previous);
    previous = v;
  }
  // Wider than the first octave's half period: the mean itself.
  CHECK(eval_pattern(t, {0.3f, 0.2f, 0.1f}, 10).t == Approx(0.5f).margin(1e-6));
  t.filter = false;
  CHECK(variance(10) == Approx(variance(0)));
}
