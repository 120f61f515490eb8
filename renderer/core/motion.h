// Transform motion over a shutter: keys decomposed as Embree's quaternion motion blur does
// (M = T * R * U: a translation, a unit quaternion and an upper-triangular scale-and-shear
// matrix), interpolated per ray time with T and U linear and R by slerp, so that rotations blur
// along arcs rather than chords; and conservative bounds of a box moved that way.
#pragma once

#include <span>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

/// One transform decomposed: to_world = translate(translation) * rotate(rotation) * U with U
/// upper triangular, u = {U00, U01, U02, U11, U12, U22}.
struct MotionKey {
  Vec3f translation;
  Quat rotation;
  float u[6] = {1, 0, 0, 1, 0, 1};
};

/// The decomposition of an invertible `m` (QR by Gram-Schmidt on its columns; a mirroring map
/// keeps a proper rotation and a negative U22). compose_motion(decompose_motion(m)) is m up to
/// rounding.
MotionKey decompose_motion(const Affine3f& m);

/// The keys of a sequence of maps (each invertible), their rotations kept on one hemisphere (key
/// k + 1's quaternion negated when it points away from key k's) so that every interpolation,
/// Embree's included, turns along the shorter arc between consecutive keys.
std::vector<MotionKey> make_motion_keys(std::span<const Affine3f> maps);

/// The transform of a key.
Affine3f compose_motion(const MotionKey& key);

/// The transform at `time` in [0, 1] (clamped) of keys spaced evenly over [0, 1] (keys[0] at 0,
/// keys.back() at 1): between the two keys around it, translation and U interpolated linearly
/// and the rotation by slerp along the shorter arc. One key: that key's transform. `keys` is
/// not empty. Never allocates or throws.
Affine3f interpolate_motion(std::span<const MotionKey> keys, float time);

/// World bounds of object-space box `b` under the motion at every time in [0, 1]: the box mapped
/// at 16 steps per key interval, padded by the arc a corner may bulge out between steps
/// (conservative). Empty for an empty box.
Bounds3f motion_bounds(std::span<const MotionKey> keys, const Bounds3f& b);

}  // namespace penumbra
