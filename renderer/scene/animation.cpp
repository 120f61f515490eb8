// Keyframe interpolation (glTF 2.0 Appendix C "Interpolation").
#include "renderer/scene/animation.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/quaternion.h"

namespace penumbra {

namespace {
void normalise4(double* q) {
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (len > 0)
    for (int i = 0; i < 4; ++i) q[i] /= len;
  else
    q[0] = q[1] = q[2] = 0, q[3] = 1;
}

// Spherical linear interpolation of two keys along the shorter arc (core/quaternion.h).
void slerp_keys(const float* a, const float* b, double s, double* out) {
  const Quat q = slerp(Quat{a[0], a[1], a[2], a[3]}, Quat{b[0], b[1], b[2], b[3]}, s);
  out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
}
}  // namespace

void sample_track(std::span<const float> times, std::span<const float> values, size_t width,
                  Interpolation interp, bool rotation, double t, double* out) {
  const size_t n = times.size();
  const size_t stride = interp == Interpolation::CubicSpline ? 3 * width : width;
  const size_t value_at = interp == Interpolation::CubicSpline ? width : 0;  // skip in-tangent
  auto key_value = [&](size_t k) { return values.data() + k * stride + value_at; };
  auto copy = [&](const float* v) {
    for (size_t c = 0; c < width; ++c) out[c] = v[c];
    if (rotation) normalise4(out);
  };
  if (n == 0) return;
  if (!(t > times[0]) || n == 1) return copy(key_value(0));  // also NaN t
  if (t >= times[n - 1]) return copy(key_value(n - 1));
  // Interval [times[i], times[i+1]) containing t.
  const size_t i = size_t(std::upper_bound(times.begin(), times.end(), float(t)) - times.begin()) - 1;
  const size_t j = std::min(i + 1, n - 1);
  const double td = double(times[j]) - double(times[i]);
  const double s = td > 0 ? std::clamp((t - double(times[i])) / td, 0.0, 1.0) : 0.0;
  switch (interp) {
    case Interpolation::Step:
      return copy(key_value(i));
    case Interpolation::Linear:
      if (rotation) return slerp_keys(key_value(i), key_value(j), s, out);
      for (size_t c = 0; c < width; ++c) out[c] = (1 - s) * key_value(i)[c] + s * key_value(j)[c];
      return;
    case Interpolation::CubicSpline: {
      const float* vi = values.data() + i * stride + width;      // value k
      const float* bi = values.data() + i * stride + 2 * width;  // out-tangent k
      const float* aj = values.data() + j * stride;              // in-tangent k+1
      const float* vj = values.data() + j * stride + width;      // value k+1
      const double s2 = s * s, s3 = s2 * s;
      const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
      for (size_t c = 0; c < width; ++c)
        out[c] = h00 * vi[c] + h10 * td * bi[c] + h01 * vj[c] + h11 * td * aj[c];
      if (rotation) normalise4(out);
      return;
    }
  }
}

}  // namespace penumbra
