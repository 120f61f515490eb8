// Transform motion over a shutter: keys decomposed as Embree's quaternion motion blur does
// (M = T * R * U: a translation, a unit quaternion and an upper-triangular scale-and-shear
// matrix), interpolated per ray time with T and U linear and R by slerp, so that rotations blur
// along arcs rather than chords; conservative bounds of a box moved that way; and the linear
// interpolation of deforming vertices between their time steps.
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
/// The same over the times in [t0, t1] only (0 <= t0 <= t1 <= 1): the box mapped at t0, t1 and
/// steps between them as dense as motion_bounds()'s, padded the same way.
Bounds3f motion_bounds(std::span<const MotionKey> keys, const Bounds3f& b, float t0, float t1);

/// Where `time` in [0, 1] (clamped; NaN as 0) falls among `steps` >= 2 time steps spaced
/// evenly over [0, 1]: between step `k` and k + 1, at fraction `a` of the way, k <= steps - 2.
/// Embree interpolates its multi-step geometry the same way (linearly between the two steps).
struct MotionSegment {
  uint32_t k = 0;
  float a = 0;
};
inline MotionSegment motion_segment(float time, uint32_t steps) {
  const float t = time > 0 ? (time < 1 ? time : 1.0f) : 0.0f;
  const float f = t * float(steps - 1);
  uint32_t k = uint32_t(f);
  if (k > steps - 2) k = steps - 2;
  return {k, f - float(k)};
}

/// Vertex `i` of a deforming mesh at `time`: `keys` holds `steps` copies of its `count`
/// vertices, step after step, linearly interpolated between the two steps around `time`.
inline Vec3f interpolate_vertex(const Vec3f* keys, size_t count, uint32_t steps, size_t i, float time) {
  const MotionSegment s = motion_segment(time, steps);
  const Vec3f p0 = keys[size_t(s.k) * count + i], p1 = keys[size_t(s.k + 1) * count + i];
  return p0 * (1.0f - s.a) + p1 * s.a;
}

}  // namespace penumbra
