// Penumbra core maths: Transform and quaternion implementations.
#include "renderer/core/math.h"

namespace penumbra {

Quat operator*(const Quat& a, const Quat& b) {
  // [w1 w2 - v1.v2, w1 v2 + w2 v1 + v1 x v2]
  return {a.w * b.x + b.w * a.x + (a.y * b.z - a.z * b.y), a.w * b.y + b.w * a.y + (a.z * b.x - a.x * b.z),
          a.w * b.z + b.w * a.z + (a.x * b.y - a.y * b.x), a.w * b.w - (a.x * b.x + a.y * b.y + a.z * b.z)};
}

Transform operator*(const Transform& a, const Transform& b) {
  Transform r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a.m[i][k] * b.m[k][j];
      r.m[i][j] = s;
    }
  return r;
}

Transform translate(double x, double y, double z) {
  Transform t;
  t.m[0][3] = x;
  t.m[1][3] = y;
  t.m[2][3] = z;
  return t;
}

Transform scale(double x, double y, double z) {
  Transform t;
  t.m[0][0] = x;
  t.m[1][1] = y;
  t.m[2][2] = z;
  return t;
}

Transform rotate(const Quat& q_in) {
  const double n = std::sqrt(q_in.x * q_in.x + q_in.y * q_in.y + q_in.z * q_in.z + q_in.w * q_in.w);
  if (!(n > 0)) return Transform{};
  const double x = q_in.x / n, y = q_in.y / n, z = q_in.z / n, w = q_in.w / n;
  Transform t;
  t.m[0] = {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0};
  t.m[1] = {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0};
  t.m[2] = {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0};
  return t;
}

Transform compose_trs(const std::array<double, 3>& t, const Quat& r, const std::array<double, 3>& s) {
  return translate(t[0], t[1], t[2]) * rotate(r) * scale(s[0], s[1], s[2]);
}

Transform from_column_major(const double* v) {
  Transform t;
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) t.m[row][col] = v[col * 4 + row];
  return t;
}

double determinant3x3(const Transform& t) {
  const auto& m = t.m;
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

void orthonormal_basis(Vec3f n, Vec3f& t, Vec3f& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = {1 + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

bool inverse(const Transform& t, Transform& out) {
  // Cofactor expansion of the full 4x4 (Laplace, 2x2 sub-determinants).
  const auto& a = t.m;
  const double s0 = a[0][0] * a[1][1] - a[1][0] * a[0][1];
  const double s1 = a[0][0] * a[1][2] - a[1][0] * a[0][2];
  const double s2 = a[0][0] * a[1][3] - a[1][0] * a[0][3];
  const double s3 = a[0][1] * a[1][2] - a[1][1] * a[0][2];
  const double s4 = a[0][1] * a[1][3] - a[1][1] * a[0][3];
  const double s5 = a[0][2] * a[1][3] - a[1][2] * a[0][3];
  const double c5 = a[2][2] * a[3][3] - a[3][2] * a[2][3];
  const double c4 = a[2][1] * a[3][3] - a[3][1] * a[2][3];
  const double c3 = a[2][1] * a[3][2] - a[3][1] * a[2][2];
  const double c2 = a[2][0] * a[3][3] - a[3][0] * a[2][3];
  const double c1 = a[2][0] * a[3][2] - a[3][0] * a[2][2];
  const double c0 = a[2][0] * a[3][1] - a[3][0] * a[2][1];
  const double det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return false;
  const double k = 1.0 / det;
  Transform r;
  auto& b = r.m;
  b[0][0] = (a[1][1] * c5 - a[1][2] * c4 + a[1][3] * c3) * k;
  b[0][1] = (-a[0][1] * c5 + a[0][2] * c4 - a[0][3] * c3) * k;
  b[0][2] = (a[3][1] * s5 - a[3][2] * s4 + a[3][3] * s3) * k;
  b[0][3] = (-a[2][1] * s5 + a[2][2] * s4 - a[2][3] * s3) * k;
  b[1][0] = (-a[1][0] * c5 + a[1][2] * c2 - a[1][3] * c1) * k;
  b[1][1] = (a[0][0] * c5 - a[0][2] * c2 + a[0][3] * c1) * k;
  b[1][2] = (-a[3][0] * s5 + a[3][2] * s2 - a[3][3] * s1) * k;
  b[1][3] = (a[2][0] * s5 - a[2][2] * s2 + a[2][3] * s1) * k;
  b[2][0] = (a[1][0] * c4 - a[1][1] * c2 + a[1][3] * c0) * k;
  b[2][1] = (-a[0][0] * c4 + a[0][1] * c2 - a[0][3] * c0) * k;
  b[2][2] = (a[3][0] * s4 - a[3][1] * s2 + a[3][3] * s0) * k;
  b[2][3] = (-a[2][0] * s4 + a[2][1] * s2 - a[2][3] * s0) * k;
  b[3][0] = (-a[1][0] * c3 + a[1][1] * c1 - a[1][2] * c0) * k;
  b[3][1] = (a[0][0] * c3 - a[0][1] * c1 + a[0][2] * c0) * k;
  b[3][2] = (-a[3][0] * s3 + a[3][1] * s1 - a[3][2] * s0) * k;
  b[3][3] = (a[2][0] * s3 - a[2][1] * s1 + a[2][2] * s0) * k;
  out = r;
  return true;
}

Transform transpose(const Transform& t) {
  Transform r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = t.m[j][i];
  return r;
}

bool is_finite(const Transform& t) {
  for (const auto& row : t.m)
    for (double v : row)
      if (!std::isfinite(v)) return false;
  return true;
}

Vec3f transform_point(const Transform& t, Vec3f p) {
  const auto& m = t.m;
  const double x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
  const double y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
  const double z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
  const double w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
  if (w == 1.0) return {float(x), float(y), float(z)};
  return {float(x / w), float(y / w), float(z / w)};
}

Vec3f transform_vector(const Transform& t, Vec3f v) {
  const auto& m = t.m;
  return {float(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z),
          float(m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z),
          float(m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z)};
}

Vec3f transform_normal(const Transform& inv, Vec3f n) {
  // (M^-1)^T n: multiply by the transpose of the inverse, i.e. use columns of inv as rows.
  const auto& m = inv.m;
  return {float(m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z),
          float(m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z),
          float(m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z)};
}

bool is_identity(const Affine3f& a) {
  const Affine3f id;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c)
      if (a.m[r][c] != id.m[r][c]) return false;
  return true;
}

Affine3f to_affine(const Transform& t) {
  Affine3f a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.m[r][c] = float(t.m[size_t(r)][size_t(c)]);
  return a;
}

Transform to_transform(const Affine3f& a) {
  Transform t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) t.m[size_t(r)][size_t(c)] = a.m[r][c];
  return t;
}

bool inverse(const Affine3f& a, Affine3f& out) {
  // The determinant of the linear part in single precision, as single-precision kernels
  // (Embree's instances) compute it before dividing by it: it must be a normal float.
  const Vec3f c0{a.m[0][0], a.m[1][0], a.m[2][0]}, c1{a.m[0][1], a.m[1][1], a.m[2][1]},
      c2{a.m[0][2], a.m[1][2], a.m[2][2]};
  if (!std::isnormal(dot(c0, cross(c1, c2)))) return false;
  Transform inv;
  if (!inverse(to_transform(a), inv)) return false;
  const Affine3f r = to_affine(inv);
  for (const auto& row : r.m)
    for (float v : row)
      if (!std::isfinite(v)) return false;
  out = r;
  return true;
}

Bounds3f transform_bounds(const Affine3f& a, const Bounds3f& b) {
  if (b.empty()) return b;
  Bounds3f out;
  for (int k = 0; k < 8; ++k)
    out = merge(out,
                apply_point(a, {k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z}));
  return out;
}

void symmetric_eigen3(double a[3][3], double v[3][3], double values[3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v[i][j] = i == j ? 1 : 0;
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (!(off > 1e-30 * diag)) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // a <- J^T a J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  for (int i = 0; i < 3; ++i) values[i] = a[i][i];
}

}  // namespace penumbra
