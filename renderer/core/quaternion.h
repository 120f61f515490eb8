// Unit quaternions as orientations: axis-angle construction, rotation of vectors, spherical
// linear interpolation (Shoemake, "Animating rotation with quaternion curves", SIGGRAPH 1985),
// conversion from a rotation matrix (Shepperd's method, J. Guidance and Control 1(3), 1978) and
// to and from Euler angles. Quat (x, y, z, w) and rotate(Quat) are in core/math.h.
//
// Euler angles here are yaw, pitch, roll applied intrinsically in the order Y, X', Z'':
// R = Ry(yaw) * Rx(pitch) * Rz(roll), right-handed, in radians. For a camera that looks down
// -Z with +Y up (glTF's convention) positive yaw turns it left (towards -X), positive pitch
// tilts it up and positive roll turns it counter-clockwise about its view direction as seen from
// behind it (its up vector leans towards -X), so the picture's content turns clockwise.
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// Rotation by `angle` radians about the unit vector (ax, ay, az) (right-handed).
Quat quat_axis_angle(double ax, double ay, double az, double angle);

/// q / |q|; the identity for a zero or non-finite q.
Quat normalize(const Quat& q);

/// The four-component dot product (cos of half the angle between unit orientations).
double dot(const Quat& a, const Quat& b);

/// The vector v rotated by the unit quaternion q (q v q*).
std::array<double, 3> rotate_vector(const Quat& q, const std::array<double, 3>& v);

/// Spherical linear interpolation from a (t = 0) to b (t = 1) at constant angular speed, along
/// the shorter of the two arcs (b is negated when a.b < 0: the same rotation). Inputs are
/// normalised; the result is a unit quaternion. Nearly equal inputs fall back to normalised
/// linear interpolation, whose error there is below 1e-7 radians.
Quat slerp(const Quat& a, const Quat& b, double t);

/// The unit quaternion of the rotation in the upper-left 3x3 of `r` (Shepperd's method: the
/// largest of the four squared components decides the stable formula). `r` must be a rotation
/// (orthonormal, determinant 1); the result has w >= 0.
Quat quat_from_matrix(const Transform& r);

/// Yaw, pitch and roll (radians) in the convention of this file's banner.
struct EulerAngles {
  double yaw = 0, pitch = 0, roll = 0;
};

/// Ry(yaw) * Rx(pitch) * Rz(roll) as a unit quaternion.
Quat quat_from_euler(const EulerAngles& e);

/// Angles that give the rotation q: pitch in [-pi/2, pi/2], yaw and roll in (-pi, pi]. At
/// pitch = +-pi/2 (gimbal lock: yaw and roll turn about the same axis) roll is 0 and yaw
/// carries the whole turn, so quat_from_euler(euler_from_quat(q)) is q up to sign.
EulerAngles euler_from_quat(const Quat& q);

}  // namespace penumbra
