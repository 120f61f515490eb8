// Keyframe interpolation for animation channels (glTF 2.0 spec 3.11 and Appendix C): STEP,
// LINEAR (spherical linear for rotations) and CUBICSPLINE (Hermite with in/out tangents).
// Plain functions over arrays; io/ maps glTF channels onto them.
#pragma once

#include <cstddef>
#include <span>

namespace penumbra {

enum class Interpolation { Step, Linear, CubicSpline };

/// Value of a sampled track at time t, written to out[0..width).
/// times: n >= 1 key times, non-decreasing. values: n x width (Step, Linear) or n x 3 x width
/// for CubicSpline, laid out per key as [in-tangent, value, out-tangent].
/// Before the first key the first value holds, after the last the last value.
/// rotation: width == 4 unit quaternions (x, y, z, w): Linear uses slerp along the shorter
/// arc and every result is normalised.
void sample_track(std::span<const float> times, std::span<const float> values, size_t width,
                  Interpolation interp, bool rotation, double t, double* out);

}  // namespace penumbra
