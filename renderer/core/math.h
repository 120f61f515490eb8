// Penumbra core maths: small value types (Vec2f, Vec3f, Bounds3f) for kernels and a
// double-precision affine Transform (4x4, row-major) for scene assembly.
// Not a general linear-algebra library: tests check it against Eigen.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace penumbra {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Vec2f {
  float x = 0, y = 0;
};

struct Vec4f {
  float x = 0, y = 0, z = 0, w = 0;
};

struct Vec3f {
  float x = 0, y = 0, z = 0;
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
};

constexpr Vec3f operator+(Vec3f a, Vec3f b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
constexpr Vec3f operator-(Vec3f a, Vec3f b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
constexpr Vec3f operator-(Vec3f a) {
  return {-a.x, -a.y, -a.z};
}
constexpr Vec3f operator*(Vec3f a, Vec3f b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
constexpr Vec3f operator*(Vec3f a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
constexpr Vec3f operator*(float s, Vec3f a) {
  return {a.x * s, a.y * s, a.z * s};
}
constexpr Vec3f operator/(Vec3f a, float s) {
  return {a.x / s, a.y / s, a.z / s};
}
constexpr Vec3f& operator+=(Vec3f& a, Vec3f b) {
  return a = a + b;
}
constexpr Vec3f& operator*=(Vec3f& a, Vec3f b) {
  return a = a * b;
}
constexpr Vec3f& operator*=(Vec3f& a, float s) {
  return a = a * s;
}
constexpr bool operator==(Vec3f a, Vec3f b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}

constexpr float dot(Vec3f a, Vec3f b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3f cross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3f a) {
  return std::sqrt(dot(a, a));
}
/// Unit vector along a; a zero vector stays zero (never NaN).
inline Vec3f normalize(Vec3f a) {
  const float l = length(a);
  return l > 0 ? a / l : Vec3f{};
}
constexpr Vec3f min(Vec3f a, Vec3f b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3f max(Vec3f a, Vec3f b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline Vec3f abs(Vec3f a) {
  return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)};
}
constexpr float max_component(Vec3f a) {
  return std::max(a.x, std::max(a.y, a.z));
}
inline bool is_finite(Vec3f a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
/// Ideal mirror direction of d about unit normal n: r = d - 2 (d.n) n.
constexpr Vec3f reflect(Vec3f d, Vec3f n) {
  return d - 2.0f * dot(d, n) * n;
}
constexpr float luminance(Vec3f c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

/// Axis-aligned box; the default box is empty (min > max) and absorbs any point.
struct Bounds3f {
  Vec3f lo{kInfinity, kInfinity, kInfinity};
  Vec3f hi{-kInfinity, -kInfinity, -kInfinity};
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  Vec3f center() const { return (lo + hi) * 0.5f; }
  Vec3f extent() const { return hi - lo; }
};
inline Bounds3f merge(Bounds3f b, Vec3f p) {
  return {min(b.lo, p), max(b.hi, p)};
}
inline Bounds3f merge(Bounds3f a, Bounds3f b) {
  return {min(a.lo, b.lo), max(a.hi, b.hi)};
}
/// The common part of two boxes; empty() if they do not overlap.
inline Bounds3f intersect(Bounds3f a, Bounds3f b) {
  return {max(a.lo, b.lo), min(a.hi, b.hi)};
}

/// An orthonormal basis (t, b, n) around unit n (Duff et al., "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1), 2017).
void orthonormal_basis(Vec3f n, Vec3f& t, Vec3f& b);

/// Unit quaternion (x, y, z, w) in glTF order.
struct Quat {
  double x = 0, y = 0, z = 0, w = 1;
};
/// Hamilton product q1 q2 = [w1 w2 - v1.v2, w1 v2 + w2 v1 + v1 x v2].
Quat operator*(const Quat& a, const Quat& b);

/// Affine or projective 4x4 transform, row-major m[row][col], acting on column vectors.
struct Transform {
  std::array<std::array<double, 4>, 4> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
};

Transform operator*(const Transform& a, const Transform& b);
Transform translate(double x, double y, double z);
Transform scale(double x, double y, double z);
/// Rotation matrix of a quaternion; q is normalised first (a zero q yields identity).
Transform rotate(const Quat& q);
/// glTF node TRS: T * R * S (scale first, then rotate, then translate).
Transform compose_trs(const std::array<double, 3>& t, const Quat& r, const std::array<double, 3>& s);
/// From 16 values in glTF's column-major order.
Transform from_column_major(const double* values16);
double determinant3x3(const Transform& t);
/// Eigenvalues (`values`, unsorted) and unit eigenvectors (the columns of `vectors`, in the same
/// order) of the symmetric 3x3 matrix `a`, which is overwritten, by cyclic Jacobi rotations
/// (Golub & Van Loan, "Matrix Computations", sec. 8.5) until the off-diagonal part is 1e-15 of
/// the diagonal's (relative) or 64 sweeps.
void symmetric_eigen3(double a[3][3], double vectors[3][3], double values[3]);
/// General inverse by cofactors; returns false (and leaves out untouched) if singular.
bool inverse(const Transform& t, Transform& out);
Transform transpose(const Transform& t);
bool is_finite(const Transform& t);

/// Single-precision affine map p -> L p + t for kernels (instance placements): row-major 3x4,
/// m[r][0..2] = L, m[r][3] = t. The default is the identity.
struct Affine3f {
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};
};

inline Vec3f apply_point(const Affine3f& a, Vec3f p) {
  const auto& m = a.m;
  return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
          m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
          m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
}
inline Vec3f apply_vector(const Affine3f& a, Vec3f v) {
  const auto& m = a.m;
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}
/// Normal transform L^-T n (unnormalised), given the inverse map.
inline Vec3f apply_normal(const Affine3f& inverse, Vec3f n) {
  const auto& m = inverse.m;
  return {m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z, m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
          m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z};
}
bool is_identity(const Affine3f& a);
/// The top three rows of an affine Transform, rounded to float.
Affine3f to_affine(const Transform& t);
Transform to_transform(const Affine3f& a);
/// Inverse computed in double and rounded; false (out untouched) if singular, not finite, or
/// not invertible in single precision: the determinant of the linear part, computed in float,
/// must be a normal number (a scale of 1e-13 on every axis is not), as single-precision
/// kernels such as Embree's instancing divide by it.
bool inverse(const Affine3f& a, Affine3f& out);
/// The box holding the image of `b` under `a` (its eight corners mapped); empty stays empty.
Bounds3f transform_bounds(const Affine3f& a, const Bounds3f& b);

Vec3f transform_point(const Transform& t, Vec3f p);
Vec3f transform_vector(const Transform& t, Vec3f v);
/// Transforms a normal by the inverse transpose of t's upper 3x3 (n' = M^-T n), unnormalised.
/// `inverse_t` must be the inverse of t.
Vec3f transform_normal(const Transform& inverse_t, Vec3f n);

}  // namespace penumbra
