// Transform motion: decomposition, interpolation and bounds.
#include "renderer/core/motion.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/quaternion.h"

namespace penumbra {

namespace {

using D3 = std::array<double, 3>;

double dot3(const D3& a, const D3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

}  // namespace

MotionKey decompose_motion(const Affine3f& m) {
  D3 a[3];
  for (int c = 0; c < 3; ++c) a[c] = {m.m[0][c], m.m[1][c], m.m[2][c]};
  // Gram-Schmidt: a0 = U00 q0; a1 = U01 q0 + U11 q1; a2 = U02 q0 + U12 q1 + U22 q2.
  D3 q[3];
  double u[6];
  const auto unit = [](D3 v, double& len) {
    len = std::sqrt(dot3(v, v));
    const double inv = len > 0 ? 1 / len : 0;
    return D3{v[0] * inv, v[1] * inv, v[2] * inv};
  };
  q[0] = unit(a[0], u[0]);
  u[1] = dot3(q[0], a[1]);
  q[1] = unit({a[1][0] - u[1] * q[0][0], a[1][1] - u[1] * q[0][1], a[1][2] - u[1] * q[0][2]}, u[3]);
  u[2] = dot3(q[0], a[2]);
  u[4] = dot3(q[1], a[2]);
  q[2] = unit({a[2][0] - u[2] * q[0][0] - u[4] * q[1][0], a[2][1] - u[2] * q[0][1] - u[4] * q[1][1],
               a[2][2] - u[2] * q[0][2] - u[4] * q[1][2]},
              u[5]);
  // A mirroring map: keep R a rotation, the sign in U22.
  const D3 cross01 = {q[0][1] * q[1][2] - q[0][2] * q[1][1], q[0][2] * q[1][0] - q[0][0] * q[1][2],
                      q[0][0] * q[1][1] - q[0][1] * q[1][0]};
  if (dot3(cross01, q[2]) < 0) {
    q[2] = {-q[2][0], -q[2][1], -q[2][2]};
    u[5] = -u[5];
  }
  Transform r;
  for (int row = 0; row < 3; ++row)
    for (int c = 0; c < 3; ++c) r.m[size_t(row)][size_t(c)] = q[c][size_t(row)];
  MotionKey k;
  k.translation = {m.m[0][3], m.m[1][3], m.m[2][3]};
  k.rotation = quat_from_matrix(r);
  for (int i = 0; i < 6; ++i) k.u[i] = float(u[i]);
  return k;
}

std::vector<MotionKey> make_motion_keys(std::span<const Affine3f> maps) {
  std::vector<MotionKey> keys;
  keys.reserve(maps.size());
  for (const Affine3f& m : maps) {
    MotionKey k = decompose_motion(m);
    if (!keys.empty() && dot(keys.back().rotation, k.rotation) < 0)
      k.rotation = {-k.rotation.x, -k.rotation.y, -k.rotation.z, -k.rotation.w};
    keys.push_back(k);
  }
  return keys;
}

Affine3f compose_motion(const MotionKey& k) {
  // The rotation's columns, then A = R U.
  D3 col[3];
  for (int c = 0; c < 3; ++c)
    col[c] = rotate_vector(k.rotation, {c == 0 ? 1.0 : 0.0, c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0});
  const double u00 = k.u[0], u01 = k.u[1], u02 = k.u[2], u11 = k.u[3], u12 = k.u[4], u22 = k.u[5];
  Affine3f m;
  for (int r = 0; r < 3; ++r) {
    const size_t i = size_t(r);
    m.m[r][0] = float(col[0][i] * u00);
    m.m[r][1] = float(col[0][i] * u01 + col[1][i] * u11);
    m.m[r][2] = float(col[0][i] * u02 + col[1][i] * u12 + col[2][i] * u22);
    m.m[r][3] = k.translation[r];
  }
  return m;
}

Affine3f interpolate_motion(std::span<const MotionKey> keys, float time) {
  if (keys.size() == 1) return compose_motion(keys[0]);
  const float f = std::clamp(time, 0.0f, 1.0f) * float(keys.size() - 1);
  const size_t i = std::min(size_t(f), keys.size() - 2);
  const float s = f - float(i);
  const MotionKey& a = keys[i];
  const MotionKey& b = keys[i + 1];
  MotionKey k;
  k.translation = a.translation + (b.translation - a.translation) * s;
  k.rotation = slerp(a.rotation, b.rotation, s);
  for (int j = 0; j < 6; ++j) k.u[j] = a.u[j] + (b.u[j] - a.u[j]) * s;
  return compose_motion(k);
}

Bounds3f motion_bounds(std::span<const MotionKey> keys, const Bounds3f& b) {
  return motion_bounds(keys, b, 0, 1);
}

Bounds3f motion_bounds(std::span<const MotionKey> keys, const Bounds3f& b, float t0, float t1) {
  if (b.empty() || keys.empty()) return {};
  constexpr int kSteps = 16;  // per key interval
  const int intervals = int(keys.size()) - 1;
  const int n = intervals == 0 ? 1 : std::max(2, int(std::ceil(double(t1 - t0) * intervals * kSteps)) + 1);
  // How far a corner lies from the object origin under U: the arm a rotation swings.
  float arm = 0;
  for (const MotionKey& k : keys) {
    const float norm = std::fabs(k.u[0]) + std::fabs(k.u[1]) + std::fabs(k.u[2]) + std::fabs(k.u[3]) +
                       std::fabs(k.u[4]) + std::fabs(k.u[5]);
    arm = std::max(arm, norm * std::max(length(b.lo), length(b.hi)));
  }
  Bounds3f out;
  for (int s = 0; s < n; ++s) {
    const float t = n == 1 ? t0 : (s == n - 1 ? t1 : t0 + (t1 - t0) * float(s) / float(n - 1));
    const Bounds3f m = transform_bounds(interpolate_motion(keys, t), b);
    out = merge(merge(out, m.lo), m.hi);
  }
  // Between two steps a corner turns by at most the largest key interval's angle times the
  // share of an interval the steps are apart: it leaves the chord by less than arm * angle
  // (generous: the sagitta is arm * angle^2 / 8).
  double angle = 0;
  for (size_t i = 0; i + 1 < keys.size(); ++i)
    angle =
        std::max(angle, 2 * std::acos(std::min(1.0, std::fabs(dot(keys[i].rotation, keys[i + 1].rotation)))));
  const double step = n > 1 ? double(t1 - t0) / (n - 1) * intervals : 0.0;
  const float pad = arm * float(angle * step) + 1e-6f * (length(out.hi - out.lo) + arm);
  out.lo = out.lo - Vec3f{pad, pad, pad};
  out.hi = out.hi + Vec3f{pad, pad, pad};
  return out;
}

}  // namespace penumbra
