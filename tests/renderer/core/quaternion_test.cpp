// Tests for renderer/core/quaternion: axis-angle and rotate_vector against Rodrigues' matrix,
// Euler angles against Ry(yaw) Rx(pitch) Rz(roll) built from explicit axis matrices, Shepperd's
// matrix-to-quaternion conversion on random rotations and on 180-degree turns (all four of its
// branches), the gimbal-lock cases, and slerp's unit length, endpoints, constant angular speed
// and shorter arc. Eigen is the independent reference for matrices.
#include "renderer/core/quaternion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "support/camera_checks.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr double kDeg = M_PI / 180;

Eigen::Matrix3d rot_x(double a) {
  Eigen::Matrix3d m;
  m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return m;
}
Eigen::Matrix3d rot_y(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return m;
}
Eigen::Matrix3d rot_z(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return m;
}

/// The upper-left 3x3 of a Transform.
Eigen::Matrix3d mat3(const Transform& t) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = t.m[size_t(r)][size_t(c)];
  return m;
}
Transform transform_of(const Eigen::Matrix3d& m) {
  Transform t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) t.m[size_t(r)][size_t(c)] = m(r, c);
  return t;
}
Eigen::Matrix3d mat3(const Quat& q) {
  return mat3(rotate(q));
}

double max_abs_diff(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

/// The same rotation: |a.b| = 1 for unit quaternions (q and -q are one rotation).
bool same_rotation(const Quat& a, const Quat& b, double tol) {
  return angle_between(a, b) <= tol;
}

/// A uniformly distributed unit quaternion (a normalised 4D Gaussian).
Quat random_quat(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return normalize(Quat{g(rng), g(rng), g(rng), g(rng)});
}

Quat negated(const Quat& q) {
  return {-q.x, -q.y, -q.z, -q.w};
}

}  // namespace

TEST_CASE("quaternion: axis-angle, rotate_vector and normalize", "[quaternion][quick]") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI), coord(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d axis = Eigen::Vector3d(coord(rng), coord(rng), coord(rng)).normalized();
    const double a = angle(rng);
    const Quat q = quat_axis_angle(axis.x(), axis.y(), axis.z(), a);
    const Eigen::Matrix3d r = Eigen::AngleAxisd(a, axis).toRotationMatrix();
    CHECK(norm(q) == Approx(1).margin(1e-15));
    CHECK(max_abs_diff(mat3(q), r) < 1e-12);
    const Eigen::Vector3d v(coord(rng), coord(rng), coord(rng));
    const auto rv = rotate_vector(q, {v.x(), v.y(), v.z()});
    const Eigen::Vector3d expected = r * v;
    for (int k = 0; k < 3; ++k) CHECK(rv[size_t(k)] == Approx(expected[k]).margin(1e-12));
  }
  // A quarter turn about +Z takes +X to +Y (right-handed).
  const auto y = rotate_vector(quat_axis_angle(0, 0, 1, 0.5 * M_PI), {1, 0, 0});
  CHECK(y[0] == Approx(0).margin(1e-15));
  CHECK(y[1] == Approx(1));
  // normalize: unit length; zero and non-finite quaternions become the identity.
  const Quat n = normalize(Quat{1, 2, -2, 4});
  CHECK(n.x == Approx(0.2));
  CHECK(n.z == Approx(-0.4));
  CHECK(n.w == Approx(0.8));
  for (const Quat& bad : {Quat{0, 0, 0, 0}, Quat{NAN, 0, 0, 1}, Quat{INFINITY, 0, 0, 1}}) {
    const Quat i = normalize(bad);
    CHECK((i.x == 0 && i.y == 0 && i.z == 0 && i.w == 1));
  }
  CHECK(dot(Quat{1, 2, 3, 4}, Quat{-1, 0.5, 2, -0.25}) == Approx(-1 + 1 + 6 - 1));
}

TEST_CASE("quaternion: Euler angles are Ry(yaw) Rx(pitch) Rz(roll)", "[quaternion][quick]") {
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  for (int i = 0; i < 500; ++i) {
    const EulerAngles e{angle(rng), angle(rng), angle(rng)};
    CAPTURE(e.yaw, e.pitch, e.roll);
    const Quat q = quat_from_euler(e);
    CHECK(norm(q) == Approx(1).margin(1e-14));
    CHECK(max_abs_diff(mat3(q), rot_y(e.yaw) * rot_x(e.pitch) * rot_z(e.roll)) < 1e-12);
  }
  // The banner's camera reading (camera looking down -Z, +Y up).
  const auto view = [](const EulerAngles& e) { return rotate_vector(quat_from_euler(e), {0, 0, -1}); };
  CHECK(view({0.3, 0, 0})[0] < 0);  // positive yaw turns the view towards -X
  CHECK(view({0, 0.3, 0})[1] > 0);  // positive pitch tilts it up
  // Positive roll turns the image counter-clockwise: the camera's +X towards its +Y.
  const auto u = rotate_vector(quat_from_euler({0, 0, 0.3}), {1, 0, 0});
  CHECK(u[1] == Approx(std::sin(0.3)));
}

TEST_CASE("quaternion: matrix -> quaternion -> matrix, all four branches of Shepperd's method",
          "[quaternion][quick]") {
  std::vector<Eigen::Matrix3d> rotations;
  // Random rotations (uniform over SO(3)).
  std::mt19937_64 rng(13);
  for (int i = 0; i < 1000; ++i) {
    const Quat q = random_quat(rng);
    rotations.push_back(Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix());
  }
  // Half turns (trace -1) and turns close to them about the axes, the diagonals and random axes:
  // w is (near) 0, so one of x, y, z must carry the conversion.
  std::vector<Eigen::Vector3d> axes = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1},  {1, 1, 0},  {1, 0, 1},
                                       {0, 1, 1}, {1, 1, 1}, {1, -1, 1}, {-1, 1, 1}, {1, 1, -1},
                                       {3, 1, 0}, {0, 1, 5}, {-2, 0, 1}};
  std::uniform_real_distribution<double> coord(-1, 1);
  for (int i = 0; i < 30; ++i) axes.emplace_back(coord(rng), coord(rng), coord(rng));
  for (const Eigen::Vector3d& axis : axes)
    for (double a : {M_PI, M_PI - 1e-9, M_PI - 1e-3, M_PI - 0.2, -M_PI + 1e-6, 0.5, 1e-8, 0.0})
      rotations.push_back(Eigen::AngleAxisd(a, axis.normalized()).toRotationMatrix());
  // The formula Shepperd's method picks: the largest of trace, m00, m11, m22.
  int branch_count[4] = {0, 0, 0, 0};
  for (const Eigen::Matrix3d& r : rotations) {
    CAPTURE(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
    const double candidates[4] = {r.trace(), r(0, 0), r(1, 1), r(2, 2)};
    ++branch_count[std::max_element(candidates, candidates + 4) - candidates];
    const Quat q = quat_from_matrix(transform_of(r));
    CHECK(norm(q) == Approx(1).margin(1e-14));
    CHECK(q.w >= 0);
    CHECK(max_abs_diff(mat3(q), r) < 1e-12);
    // The same rotation as Eigen's own conversion (up to sign).
    const Eigen::Quaterniond e(r);
    CHECK(same_rotation(q, Quat{e.x(), e.y(), e.z(), e.w()}, 1e-9));
  }
  CAPTURE(branch_count[0], branch_count[1], branch_count[2], branch_count[3]);
  for (int b : branch_count) CHECK(b >= 20);
  // Exact half turns: the quaternion is the axis itself.
  const Quat hx = quat_from_matrix(transform_of(rot_x(M_PI)));
  CHECK(std::fabs(hx.x) == Approx(1));
  const Quat hd = quat_from_matrix(
      transform_of(Eigen::AngleAxisd(M_PI, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix()));
  CHECK(std::fabs(hd.y) == Approx(std::sqrt(0.5)));
  CHECK(hd.y * hd.z > 0);
  CHECK(hd.x == Approx(0).margin(1e-12));
}

TEST_CASE("quaternion: Euler -> quaternion -> Euler away from gimbal lock", "[quaternion][quick]") {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> angle(-M_PI + 1e-9, M_PI), pitch(-89 * kDeg, 89 * kDeg);
  for (int i = 0; i < 2000; ++i) {
    const EulerAngles e{angle(rng), pitch(rng), angle(rng)};
    CAPTURE(e.yaw, e.pitch, e.roll);
    const EulerAngles back = euler_from_quat(quat_from_euler(e));
    CHECK(back.yaw == Approx(e.yaw).margin(1e-9));
    CHECK(back.pitch == Approx(e.pitch).margin(1e-9));
    CHECK(back.roll == Approx(e.roll).margin(1e-9));
  }
  // Ranges: angles outside (-pi, pi] come back wrapped, pitch beyond 90 degrees is folded.
  const EulerAngles wrapped = euler_from_quat(quat_from_euler({1.5 * M_PI, 0.2, -1.25 * M_PI}));
  CHECK(wrapped.yaw == Approx(-0.5 * M_PI));
  CHECK(wrapped.pitch == Approx(0.2));
  CHECK(wrapped.roll == Approx(0.75 * M_PI));
  const EulerAngles folded = euler_from_quat(quat_from_euler({0.3, 100 * kDeg, 0.1}));
  CHECK(folded.pitch == Approx(80 * kDeg));
  CHECK(max_abs_diff(mat3(quat_from_euler(folded)), mat3(quat_from_euler({0.3, 100 * kDeg, 0.1}))) < 1e-12);
}

TEST_CASE("quaternion: gimbal lock at pitch +-90 degrees", "[quaternion][quick]") {
  for (double pitch : {90 * kDeg, -90 * kDeg})
    for (double yaw : {0.0, 0.4, -1.2, 2.5, M_PI})
      for (double roll : {0.0, 0.7, -2.0, 3.0}) {
        CAPTURE(pitch, yaw, roll);
        const Quat q = quat_from_euler({yaw, pitch, roll});
        const Eigen::Matrix3d r = mat3(q);
        // A rotation: orthonormal with determinant 1, and Ry Rx Rz.
        CHECK(max_abs_diff(r.transpose() * r, Eigen::Matrix3d::Identity()) < 1e-12);
        CHECK(r.determinant() == Approx(1).margin(1e-12));
        CHECK(max_abs_diff(r, rot_y(yaw) * rot_x(pitch) * rot_z(roll)) < 1e-12);
        // The camera's view direction -w = -(R z) is straight up (pitch +90) or down (-90).
        const Eigen::Vector3d view = -r.col(2);
        CHECK(view.y() == Approx(pitch > 0 ? 1 : -1).margin(1e-12));
        CHECK(std::hypot(view.x(), view.z()) < 1e-12);
        // Back to Euler angles: pitch +-90, roll 0 and yaw carrying the whole turn.
        const EulerAngles e = euler_from_quat(q);
        CHECK(e.pitch == Approx(pitch).margin(1e-12));
        CHECK(e.roll == 0);
        CHECK(e.yaw > -M_PI);
        CHECK(e.yaw <= M_PI);
        CHECK(max_abs_diff(mat3(quat_from_euler(e)), r) < 1e-9);
        CHECK(same_rotation(quat_from_euler(e), q, 1e-9));
      }
}

TEST_CASE("quaternion: Euler angles next to gimbal lock give back the rotation", "[quaternion][quick]") {
  // cos(pitch) from 1e-2 down to 1e-10: the general formula, then the gimbal-lock one.
  for (double gap : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10})
    for (double sign : {1.0, -1.0})
      for (double yaw : {0.0, 0.9, -2.8})
        for (double roll : {0.5, -1.7, 3.1}) {
          const EulerAngles e{yaw, sign * (0.5 * M_PI - gap), roll};
          CAPTURE(gap, e.yaw, e.pitch, e.roll);
          const Quat q = quat_from_euler(e);
          const EulerAngles back = euler_from_quat(q);
          CHECK(std::fabs(back.pitch) <= 0.5 * M_PI);
          CHECK(back.pitch * sign > 0);
          CHECK(angle_between(quat_from_euler(back), q) < 1e-7);
        }
}

TEST_CASE("quaternion: slerp is unit length, hits both ends and turns at constant speed",
          "[quaternion][quick]") {
  std::mt19937_64 rng(15);
  int shorter_arc_cases = 0;
  for (int i = 0; i < 300; ++i) {
    const Quat a = random_quat(rng), b = random_quat(rng);
    const double total = angle_between(a, b);  // the shorter arc, <= pi
    if (total < 0.1) continue;                 // nearly equal pairs: the next test
    if (dot(a, b) < 0) ++shorter_arc_cases;
    CAPTURE(a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w);
    CHECK(same_rotation(slerp(a, b, 0), a, 1e-12));
    CHECK(same_rotation(slerp(a, b, 1), b, 1e-12));
    for (int k = 0; k <= 20; ++k) {
      const double t = k / 20.0;
      const Quat s = slerp(a, b, t);
      CHECK(norm(s) == Approx(1).margin(1e-14));
      // Constant angular speed along the shorter arc: t of the way from a, 1 - t from b.
      CHECK(angle_between(a, s) == Approx(t * total).margin(1e-9));
      CHECK(angle_between(s, b) == Approx((1 - t) * total).margin(1e-9));
      // The shorter arc is the same for b and -b (the same rotation).
      CHECK(same_rotation(slerp(a, negated(b), t), s, 1e-12));
    }
  }
  CHECK(shorter_arc_cases > 50);
  // Half turns about +Y (yaw 0 to 270 degrees, dot < 0): the shorter way is back through 315.
  const Quat a = quat_axis_angle(0, 1, 0, 0), b = quat_axis_angle(0, 1, 0, 1.5 * M_PI);
  REQUIRE(dot(a, b) < 0);
  CHECK(same_rotation(slerp(a, b, 0.5), quat_axis_angle(0, 1, 0, -0.25 * M_PI), 1e-12));
  // Inputs are normalised first.
  const Quat scaled{3 * b.x, 3 * b.y, 3 * b.z, 3 * b.w};
  CHECK(same_rotation(slerp(a, scaled, 0.3), slerp(a, b, 0.3), 1e-12));
}

TEST_CASE("quaternion: slerp of nearly equal orientations", "[quaternion][quick]") {
  std::mt19937_64 rng(16);
  // Pairs from 0 to 0.2 radians apart: across the switch to normalised linear interpolation.
  for (double total : {0.0, 1e-12, 1e-8, 1e-5, 1e-3, 0.01, 0.03, 0.06, 0.063, 0.064, 0.07, 0.2}) {
    for (int i = 0; i < 20; ++i) {
      const Quat a = random_quat(rng);
      std::normal_distribution<double> g;
      const Quat axis = normalize(Quat{g(rng), g(rng), g(rng), 0});
      const Quat b = a * quat_axis_angle(axis.x, axis.y, axis.z, total);
      CAPTURE(total, a.x, a.y, a.z, a.w);
      REQUIRE(angle_between(a, b) == Approx(total).margin(1e-12));
      for (double t : {0.0, 0.1, 0.25, 0.5, 0.7, 1.0}) {
        const Quat s = slerp(a, b, t);
        CHECK(norm(s) == Approx(1).margin(1e-14));
        CHECK(std::isfinite(s.x));
        // Within 1.1e-6 radians of the slerp path (normalised linear interpolation's error at
        // the switch, 0.063 radians apart, is 1.01e-6).
        CHECK(angle_between(a, s) == Approx(t * total).margin(1.1e-6));
        CHECK(angle_between(s, b) == Approx((1 - t) * total).margin(1.1e-6));
      }
    }
  }
}

// slerp's contract bounds the error of its normalised-linear-interpolation fallback by 1e-7
// radians: across the range where a fallback at a coarser threshold (a.b >= 0.9995) would err by
// 1e-6, the result follows the exact arc.
TEST_CASE("quaternion: slerp's fallback within its documented 1e-7 radians", "[quaternion][quick]") {
  const Quat a{}, b = quat_axis_angle(0, 0, 1, 0.063);
  double worst = 0;
  for (int k = 0; k <= 100; ++k) {
    const double t = k / 100.0;
    worst = std::max(worst, std::fabs(angle_between(a, slerp(a, b, t)) - t * 0.063));
  }
  CHECK(worst < 1e-7);
}
