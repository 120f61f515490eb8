// Tests for renderer/animation: STEP, LINEAR (slerp for rotations) and CUBICSPLINE keyframe
// interpolation against hand-computed values.
#include "renderer/scene/animation.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

using namespace penumbra;

namespace {
constexpr double kPi_d = 3.14159265358979323846;
}

TEST_CASE("animation: STEP holds, LINEAR interpolates, both clamp outside the keys", "[animation][quick]") {
  const std::vector<float> times = {1, 2, 4};
  const std::vector<float> values = {0, 0, 0, 10, 20, 30, 30, 20, 10};
  double v[3];
  sample_track(times, values, 3, Interpolation::Linear, false, 1.5, v);
  CHECK(v[0] == Approx(5));
  CHECK(v[1] == Approx(10));
  sample_track(times, values, 3, Interpolation::Linear, false, 3, v);  // midway 2..4
  CHECK(v[0] == Approx(20));
  CHECK(v[2] == Approx(20));
  sample_track(times, values, 3, Interpolation::Step, false, 3.9, v);
  CHECK(v[0] == 10);
  sample_track(times, values, 3, Interpolation::Step, false, 4, v);  // exactly on the last key
  CHECK(v[0] == 30);
  sample_track(times, values, 3, Interpolation::Linear, false, 0, v);  // before the first key
  CHECK(v[0] == 0);
  sample_track(times, values, 3, Interpolation::Linear, false, 99, v);  // after the last
  CHECK(v[0] == 30);
  sample_track(times, values, 3, Interpolation::Linear, false, std::nan(""), v);
  CHECK(v[0] == 0);
}

TEST_CASE("animation: LINEAR rotations slerp along the shorter arc", "[animation][quick]") {
  // Identity to 90 degrees about z; the midpoint is 45 degrees: (0, 0, sin 22.5, cos 22.5).
  const float s45 = float(std::sin(kPi_d / 4)), c45 = float(std::cos(kPi_d / 4));
  const std::vector<float> times = {0, 1};
  std::vector<float> q = {0, 0, 0, 1, 0, 0, s45, c45};
  double v[4];
  sample_track(times, q, 4, Interpolation::Linear, true, 0.5, v);
  CHECK(v[2] == Approx(std::sin(kPi_d / 8)));
  CHECK(v[3] == Approx(std::cos(kPi_d / 8)));
  // The same end rotation written as -q: still the short way, same midpoint.
  q = {0, 0, 0, 1, 0, 0, -s45, -c45};
  sample_track(times, q, 4, Interpolation::Linear, true, 0.5, v);
  CHECK(std::fabs(v[2]) == Approx(std::sin(kPi_d / 8)));
  CHECK(std::fabs(v[3]) == Approx(std::cos(kPi_d / 8)));
  CHECK(v[2] * v[3] > 0);
  // A quarter of the way: 22.5 degrees.
  sample_track(times, q, 4, Interpolation::Linear, true, 0.25, v);
  CHECK(std::fabs(v[2]) == Approx(std::sin(kPi_d / 16)));
}

TEST_CASE("animation: CUBICSPLINE is the Hermite spline of values and scaled tangents",
          "[animation][quick]") {
  // Keys at t = 0 and 2 (td = 2): v0 = 1 with out-tangent b0 = 3; v1 = 5 with in-tangent a1 = -1.
  // p(s) = (2s^3 - 3s^2 + 1) v0 + (s^3 - 2s^2 + s) td b0 + (-2s^3 + 3s^2) v1 + (s^3 - s^2) td a1.
  const std::vector<float> times = {0, 2};
  const std::vector<float> values = {/*a0*/ 7, /*v0*/ 1, /*b0*/ 3, /*a1*/ -1, /*v1*/ 5, /*b1*/ 9};
  double v;
  sample_track(times, values, 1, Interpolation::CubicSpline, false, 1.0, &v);  // s = 0.5
  const double s = 0.5, expected = (2 * s * s * s - 3 * s * s + 1) * 1 + (s * s * s - 2 * s * s + s) * 2 * 3 +
                                   (-2 * s * s * s + 3 * s * s) * 5 + (s * s * s - s * s) * 2 * -1;
  CHECK(v == Approx(expected));  // 3.5
  sample_track(times, values, 1, Interpolation::CubicSpline, false, 0.0, &v);
  CHECK(v == 1);  // on a key: its value, not a tangent
  sample_track(times, values, 1, Interpolation::CubicSpline, false, 2.0, &v);
  CHECK(v == 5);
}
