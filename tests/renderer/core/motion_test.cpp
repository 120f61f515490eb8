// Transform motion: decomposition round trips (rotations, non-uniform scales, shears, mirrors),
// interpolation along arcs (slerp) rather than chords, and bounds that hold every sampled pose.
#include "renderer/core/motion.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/core/quaternion.h"

using namespace penumbra;

namespace {

Affine3f trs(Vec3f t, const Quat& r, Vec3f s) {
  Affine3f m;
  for (int c = 0; c < 3; ++c) {
    const auto col = rotate_vector(r, {c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0});
    for (int row = 0; row < 3; ++row) m.m[row][c] = float(col[size_t(row)]) * s[c];
  }
  m.m[0][3] = t.x;
  m.m[1][3] = t.y;
  m.m[2][3] = t.z;
  return m;
}

void check_close(const Affine3f& a, const Affine3f& b, float tol) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) CHECK(a.m[r][c] == Approx(b.m[r][c]).margin(tol));
}

}  // namespace

TEST_CASE("motion: decompose then compose gives the map back", "[motion][quick]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-2, 2);
  for (int i = 0; i < 200; ++i) {
    Affine3f m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) m.m[r][c] = u(rng);  // a general map: shear, mirror, scale
    Affine3f inv;
    if (!inverse(m, inv)) continue;
    const MotionKey k = decompose_motion(m);
    CHECK(std::fabs(dot(k.rotation, k.rotation) - 1) < 1e-6);
    check_close(compose_motion(k), m, 1e-4f);
  }
  // A mirroring map keeps a proper rotation and puts the sign in U22.
  const Affine3f mirror = trs({1, 2, 3}, quat_axis_angle(0, 0, 1, 0.3), {2, 1, -1});
  const MotionKey k = decompose_motion(mirror);
  CHECK(k.u[5] < 0);
  check_close(compose_motion(k), mirror, 1e-5f);
}

TEST_CASE("motion: rotation is slerped along the arc, translation and scale are linear", "[motion][quick]") {
  // A quarter turn about +Z over the shutter, from x = 0 to x = 4, scale 1 to 3.
  const Affine3f a = trs({0, 0, 0}, Quat{}, {1, 1, 1});
  const Affine3f b = trs({4, 0, 0}, quat_axis_angle(0, 0, 1, M_PI / 2), {3, 3, 3});
  const Affine3f maps[] = {a, b};
  const std::vector<MotionKey> keys = make_motion_keys(maps);
  for (float t : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
    const Affine3f m = interpolate_motion(keys, t);
    const float angle = t * float(M_PI) / 2, scale = 1 + 2 * t;
    check_close(m, trs({4 * t, 0, 0}, quat_axis_angle(0, 0, 1, angle), {scale, scale, scale}), 1e-5f);
    // The unit +X arm stays on the circle of radius `scale` about the moving origin (an arc; a
    // blend of the two matrices would cut the chord, 0.707 of the way at t = 0.5).
    const Vec3f arm = apply_vector(m, {1, 0, 0});
    CHECK(length(arm) == Approx(scale).epsilon(1e-5));
  }
  // Keys whose quaternions lie on opposite hemispheres still turn the short way.
  const Affine3f c = trs({0, 0, 0}, quat_axis_angle(0, 0, 1, 0.99 * M_PI), {1, 1, 1});
  const Affine3f d = trs({0, 0, 0}, quat_axis_angle(0, 0, 1, -0.99 * M_PI), {1, 1, 1});
  const Affine3f turn[] = {c, d};
  const std::vector<MotionKey> wrap = make_motion_keys(turn);
  CHECK(dot(wrap[0].rotation, wrap[1].rotation) >= 0);
  const Vec3f mid = apply_vector(interpolate_motion(wrap, 0.5f), {1, 0, 0});
  CHECK(mid.x == Approx(-1).margin(1e-5));  // through 180 degrees, not through 0
}

TEST_CASE("motion: bounds hold the box at every time", "[motion][quick]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  const Bounds3f box{{-0.5f, -0.2f, 0.1f}, {1.5f, 0.3f, 0.9f}};
  for (int i = 0; i < 50; ++i) {
    std::vector<Affine3f> maps;
    for (int k = 0; k < 3; ++k)
      maps.push_back(trs({4 * u(rng), 4 * u(rng), 4 * u(rng)},
                         quat_axis_angle(u(rng), u(rng), u(rng) + 1.5, 3 * u(rng)),
                         {1.5f + u(rng), 1.5f + u(rng), 1.5f + u(rng)}));
    const std::vector<MotionKey> keys = make_motion_keys(maps);
    const Bounds3f b = motion_bounds(keys, box);
    for (int s = 0; s <= 1000; ++s) {
      const Affine3f m = interpolate_motion(keys, float(s) / 1000);
      for (int c = 0; c < 8; ++c) {
        const Vec3f p = apply_point(
            m, {c & 1 ? box.hi.x : box.lo.x, c & 2 ? box.hi.y : box.lo.y, c & 4 ? box.hi.z : box.lo.z});
        CHECK((p.x >= b.lo.x && p.y >= b.lo.y && p.z >= b.lo.z && p.x <= b.hi.x && p.y <= b.hi.y &&
               p.z <= b.hi.z));
      }
    }
  }
}
