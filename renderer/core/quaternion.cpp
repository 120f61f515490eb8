// Unit quaternions: slerp, matrix and Euler-angle conversions.
#include "renderer/core/quaternion.h"

#include <cmath>

namespace penumbra {

Quat quat_axis_angle(double ax, double ay, double az, double angle) {
  const double s = std::sin(0.5 * angle), c = std::cos(0.5 * angle);
  return normalize(Quat{ax * s, ay * s, az * s, c});
}

Quat normalize(const Quat& q) {
  const double n = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (!(n > 0) || !std::isfinite(n)) return Quat{};
  return {q.x / n, q.y / n, q.z / n, q.w / n};
}

double dot(const Quat& a, const Quat& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
}

std::array<double, 3> rotate_vector(const Quat& q, const std::array<double, 3>& v) {
  // v' = v + 2 w (u x v) + 2 u x (u x v), u = (x, y, z).
  const double tx = 2 * (q.y * v[2] - q.z * v[1]);
  const double ty = 2 * (q.z * v[0] - q.x * v[2]);
  const double tz = 2 * (q.x * v[1] - q.y * v[0]);
  return {v[0] + q.w * tx + (q.y * tz - q.z * ty), v[1] + q.w * ty + (q.z * tx - q.x * tz),
          v[2] + q.w * tz + (q.x * ty - q.y * tx)};
}

Quat slerp(const Quat& a_in, const Quat& b_in, double t) {
  const Quat a = normalize(a_in);
  Quat b = normalize(b_in);
  double d = dot(a, b);
  if (d < 0) {
    b = {-b.x, -b.y, -b.z, -b.w};
    d = -d;
  }
  double wa = 1 - t, wb = t;
  if (d < 0.99999) {  // within 0.009 radians: normalised lerp, error below 1e-7
    const double theta = std::acos(std::min(d, 1.0)), sin_theta = std::sin(theta);
    wa = std::sin((1 - t) * theta) / sin_theta;
    wb = std::sin(t * theta) / sin_theta;
  }
  return normalize(Quat{wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z, wa * a.w + wb * b.w});
}

Quat quat_from_matrix(const Transform& r) {
  const auto& m = r.m;
  const double trace = m[0][0] + m[1][1] + m[2][2];
  Quat q;
  if (trace >= m[0][0] && trace >= m[1][1] && trace >= m[2][2]) {
    const double s = 2 * std::sqrt(std::max(1 + trace, 0.0));  // 4 w
    q = {(m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s};
  } else if (m[0][0] >= m[1][1] && m[0][0] >= m[2][2]) {
    const double s = 2 * std::sqrt(std::max(1 + m[0][0] - m[1][1] - m[2][2], 0.0));  // 4 x
    q = {0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s};
  } else if (m[1][1] >= m[2][2]) {
    const double s = 2 * std::sqrt(std::max(1 + m[1][1] - m[0][0] - m[2][2], 0.0));  // 4 y
    q = {(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s};
  } else {
    const double s = 2 * std::sqrt(std::max(1 + m[2][2] - m[0][0] - m[1][1], 0.0));  // 4 z
    q = {(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s};
  }
  q = normalize(q);
  if (q.w < 0) q = {-q.x, -q.y, -q.z, -q.w};
  return q;
}

Quat quat_from_euler(const EulerAngles& e) {
  return quat_axis_angle(0, 1, 0, e.yaw) * quat_axis_angle(1, 0, 0, e.pitch) *
         quat_axis_angle(0, 0, 1, e.roll);
}

EulerAngles euler_from_quat(const Quat& q) {
  // R = Ry(yaw) Rx(pitch) Rz(roll): R[1][2] = -sin(pitch), R[0][2] = cos(pitch) sin(yaw),
  // R[2][2] = cos(pitch) cos(yaw), R[1][0] = cos(pitch) sin(roll), R[1][1] = cos(pitch) cos(roll).
  const Transform r = rotate(q);
  const auto& m = r.m;
  EulerAngles e;
  const double sp = std::clamp(-m[1][2], -1.0, 1.0);
  const double cp = std::hypot(m[1][0], m[1][1]);
  if (cp > 1e-9) {
    e.pitch = std::atan2(sp, cp);
    e.yaw = std::atan2(m[0][2], m[2][2]);
    e.roll = std::atan2(m[1][0], m[1][1]);
  } else {
    // Gimbal lock: R = Ry(yaw -/+ roll) Rx(+-pi/2); the turn is given to yaw, roll is 0.
    // With roll 0, R[0][0] = cos(yaw) and R[2][0] = -sin(yaw).
    e.pitch = sp > 0 ? 0.5 * M_PI : -0.5 * M_PI;
    e.yaw = std::atan2(-m[2][0], m[0][0]);
    e.roll = 0;
  }
  return e;
}

}  // namespace penumbra
