// Tests for renderer/lights: KHR_lights_punctual falloff, range window and spot cones.
#include "renderer/lights/punctual.h"

#include <catch2/catch.hpp>

using namespace penumbra;

TEST_CASE("point light: inverse-square irradiance in candela", "[lights][quick]") {
  Light l;
  l.type = LightType::Point;
  l.intensity = 8;
  l.color = {1, 0.5f, 0.25f};
  l.position = {0, 2, 0};
  LightSample s;
  REQUIRE(sample_light(l, {0, 0, 0}, s));
  CHECK(s.distance == Approx(2));
  CHECK(s.wi.y == Approx(1));
  CHECK(s.irradiance.x == Approx(2));  // 8 / 2^2
  CHECK(s.irradiance.y == Approx(1));
  CHECK(s.irradiance.z == Approx(0.5));
}

TEST_CASE("point light: the spec's smooth range window", "[lights][quick]") {
  Light l;
  l.intensity = 1;
  l.position = {0, 0, 0};
  l.range = 4;
  LightSample s;
  REQUIRE(sample_light(l, {2, 0, 0}, s));
  // max(min(1 - (2/4)^4, 1), 0) / 2^2
  CHECK(s.irradiance.x == Approx((1 - 1.0 / 16) / 4));
  CHECK_FALSE(sample_light(l, {5, 0, 0}, s));  // beyond range: nothing
}

TEST_CASE("spot light: full inside the inner cone, zero outside the outer cone", "[lights][quick]") {
  Light l;
  l.type = LightType::Spot;
  l.intensity = 1;
  l.position = {0, 0, 0};
  l.direction = {0, 0, -1};
  l.inner_cone = 0.2f;
  l.outer_cone = 0.6f;
  LightSample s;
  REQUIRE(sample_light(l, {0, 0, -1}, s));
  CHECK(s.irradiance.x == Approx(1));
  const float mid = 0.4f;  // between the cones: the squared linear ramp in cos angle
  REQUIRE(sample_light(l, {std::sin(mid), 0, -std::cos(mid)}, s));
  const float lin = (std::cos(mid) - std::cos(0.6f)) / (std::cos(0.2f) - std::cos(0.6f));
  CHECK(s.irradiance.x == Approx(lin * lin).epsilon(1e-4));
  CHECK_FALSE(sample_light(l, {std::sin(0.7f), 0, -std::cos(0.7f)}, s));
}

TEST_CASE("directional light: constant illuminance along -direction", "[lights][quick]") {
  Light l;
  l.type = LightType::Directional;
  l.intensity = 3;
  l.direction = normalize(Vec3f{1, -1, 0});
  LightSample s;
  REQUIRE(sample_light(l, {100, 5, -7}, s));
  CHECK(s.irradiance.x == Approx(3));
  CHECK(std::isinf(s.distance));
  CHECK(dot(s.wi, l.direction) == Approx(-1));
}
