// Tests for renderer/math: quaternions, TRS composition, inverses and normal transforms,
// checked against Eigen.
#include "renderer/core/math.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <random>

using namespace penumbra;

namespace {
Eigen::Matrix4d to_eigen(const Transform& t) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) m(i, j) = t.m[size_t(i)][size_t(j)];
  return m;
}
Quat random_quat(std::mt19937& rng) {
  std::normal_distribution<double> n;
  Quat q{n(rng), n(rng), n(rng), n(rng)};
  const double l = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return {q.x / l, q.y / l, q.z / l, q.w / l};
}
}  // namespace

TEST_CASE("quaternion rotation matrix equals Eigen's", "[math][quick]") {
  std::mt19937 rng(7);
  for (int k = 0; k < 100; ++k) {
    const Quat q = random_quat(rng);
    const Eigen::Matrix3d e = Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
    const Eigen::Matrix4d r = to_eigen(rotate(q));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) REQUIRE(r(i, j) == Approx(e(i, j)).margin(1e-12));
  }
}

TEST_CASE("quaternion product composes rotations like Eigen", "[math][quick]") {
  std::mt19937 rng(11);
  for (int k = 0; k < 100; ++k) {
    const Quat a = random_quat(rng), b = random_quat(rng);
    const Quat p = a * b;
    const Eigen::Quaterniond e =
        Eigen::Quaterniond(a.w, a.x, a.y, a.z) * Eigen::Quaterniond(b.w, b.x, b.y, b.z);
    REQUIRE(p.x == Approx(e.x()).margin(1e-12));
    REQUIRE(p.y == Approx(e.y()).margin(1e-12));
    REQUIRE(p.z == Approx(e.z()).margin(1e-12));
    REQUIRE(p.w == Approx(e.w()).margin(1e-12));
    // Rotating by a*b equals rotating by b, then by a.
    const Eigen::Matrix4d lhs = to_eigen(rotate(p)), rhs = to_eigen(rotate(a) * rotate(b));
    REQUIRE((lhs - rhs).norm() < 1e-12);
  }
}

TEST_CASE("glTF TRS composes as T * R * S like Eigen's Affine3d", "[math][quick]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5), s(0.1, 3);
  for (int k = 0; k < 100; ++k) {
    const std::array<double, 3> t{u(rng), u(rng), u(rng)}, sc{s(rng), s(rng), -s(rng)};
    const Quat q = random_quat(rng);
    Eigen::Affine3d e = Eigen::Translation3d(t[0], t[1], t[2]) * Eigen::Quaterniond(q.w, q.x, q.y, q.z) *
                        Eigen::Scaling(sc[0], sc[1], sc[2]);
    REQUIRE((to_eigen(compose_trs(t, q, sc)) - e.matrix()).norm() < 1e-12);
  }
}

TEST_CASE("column-major glTF matrices load transposed into row-major", "[math][quick]") {
  double v[16];
  for (int i = 0; i < 16; ++i) v[i] = i;
  const Transform t = from_column_major(v);
  REQUIRE(t.m[0][3] == 12);  // translation x is element 12 in glTF
  REQUIRE(t.m[1][0] == 1);
  REQUIRE(t.m[3][3] == 15);
}

TEST_CASE("inverse matches Eigen and rejects singular matrices", "[math][quick]") {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int k = 0; k < 50; ++k) {
    const Transform t = compose_trs({u(rng), u(rng), u(rng)}, random_quat(rng), {1.5, 0.5, 2.0});
    Transform inv;
    REQUIRE(inverse(t, inv));
    REQUIRE((to_eigen(inv) - to_eigen(t).inverse()).norm() < 1e-10);
  }
  Transform zero;
  zero.m = {};
  Transform out;
  REQUIRE_FALSE(inverse(zero, out));
  REQUIRE_FALSE(inverse(scale(1, 0, 1), out));
}

TEST_CASE("normals transform by the inverse transpose and stay perpendicular", "[math][quick]") {
  // Non-uniform scale breaks perpendicularity for a plain transform; M^-T keeps it.
  const Transform m = compose_trs({1, 2, 3}, Quat{0.2, 0.3, 0.1, 0.927}, {4, 0.5, 1});
  Transform inv;
  REQUIRE(inverse(m, inv));
  const Vec3f tangent{1, 1, 0}, normal{1, -1, 0.0f};  // perpendicular in object space
  REQUIRE(dot(tangent, normal) == 0);
  const Vec3f t2 = transform_vector(m, tangent);
  const Vec3f n_correct = transform_normal(inv, normal);
  const Vec3f n_wrong = transform_vector(m, normal);
  CHECK(std::fabs(dot(normalize(t2), normalize(n_correct))) < 1e-5f);
  CHECK(std::fabs(dot(normalize(t2), normalize(n_wrong))) > 0.1f);
  // And equals Eigen's inverse transpose.
  const Eigen::Matrix3d it = to_eigen(m).block<3, 3>(0, 0).inverse().transpose();
  const Eigen::Vector3d e = it * Eigen::Vector3d(normal.x, normal.y, normal.z);
  CHECK(n_correct.x == Approx(e.x()).epsilon(1e-5));
  CHECK(n_correct.y == Approx(e.y()).epsilon(1e-5));
  CHECK(n_correct.z == Approx(e.z()).epsilon(1e-5));
}

TEST_CASE("determinant sign detects mirroring", "[math][quick]") {
  REQUIRE(determinant3x3(scale(1, 1, 1)) == 1);
  REQUIRE(determinant3x3(scale(-1, 1, 1)) == -1);
  REQUIRE(determinant3x3(scale(2, 3, 4)) == 24);
}

TEST_CASE("inverse refuses maps single-precision kernels cannot invert", "[math][quick]") {
  Affine3f out;
  // A scale of 1e-12 on every axis has a determinant of 1e-36, a normal float: invertible.
  REQUIRE(inverse(to_affine(scale(1e-12, 1e-12, 1e-12)), out));
  CHECK(out.m[0][0] == Approx(1e12f));
  // 1e-13 gives 1e-39 (subnormal) and 1e-16 gives 0 in float: refused, as singular maps are.
  CHECK_FALSE(inverse(to_affine(scale(1e-13, 1e-13, 1e-13)), out));
  CHECK_FALSE(inverse(to_affine(scale(1e-16, 1e-16, 1e-16)), out));
  CHECK_FALSE(inverse(to_affine(scale(1, 1, 0)), out));
  // One tiny axis with large others is fine while the determinant stays normal.
  CHECK(inverse(to_affine(scale(1e-20, 1e10, 1e10)), out));
}

TEST_CASE("symmetric_eigen3 equals Eigen's self-adjoint solver", "[math]") {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) m(r, c) = m(c, r) = trial == 0 ? (r == c ? 2 : 0) : u(rng);
    double a[3][3], v[3][3], values[3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) a[r][c] = m(r, c);
    symmetric_eigen3(a, v, values);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(m);
    std::array<double, 3> sorted{values[0], values[1], values[2]};
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < 3; ++i) CHECK(sorted[size_t(i)] == Approx(es.eigenvalues()(i)).margin(1e-12));
    for (int i = 0; i < 3; ++i) {  // each column is a unit eigenvector of its value
      const Eigen::Vector3d x(v[0][i], v[1][i], v[2][i]);
      CHECK(x.norm() == Approx(1).epsilon(1e-12));
      CHECK((m * x - values[i] * x).norm() < 1e-11);
    }
  }
}
