// Procedural patterns: mapping, the noise, Voronoi and wave patterns with their gradients, and
// the colour ramp.
#include "renderer/procedural/pattern.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

Quat axis_rotation(double degrees, int axis) {
  const double half = degrees * (3.14159265358979323846 / 360.0);
  Quat q;
  (axis == 0 ? q.x : axis == 1 ? q.y : q.z) = std::sin(half);
  q.w = std::cos(half);
  return q;
}

// t and its gradient for a fractal sum: Fbm's signed value mapped into [0, 1].
PatternSample noise_pattern(const ProceduralTexture& tex, Vec3f q, float max_octaves) {
  const Noise3 n = fractal_noise(tex.table, q, tex.fractal, max_octaves);
  if (tex.fractal.kind == FractalKind::Fbm) return {0.5f + 0.5f * n.value, n.grad * 0.5f};
  return {n.value, n.grad};
}

PatternSample voronoi_pattern(const ProceduralTexture& tex, Vec3f q) {
  const WorleyValue w = worley(tex.seed, q, tex.voronoi);
  if (tex.voronoi_output == VoronoiOutput::CellRandom) return {w.cell_random, {}};
  return {w.value, w.grad};
}

PatternSample wave_pattern(const ProceduralTexture& tex, Vec3f q, float max_octaves) {
  const WaveParams& wp = tex.wave;
  const int a = std::clamp(wp.axis, 0, 2);
  float d = 0;
  Vec3f dd;
  if (wp.type == WaveType::Bands) {
    d = q[a];
    dd[a] = 1;
  } else {
    Vec3f r = q;
    r[a] = 0;
    d = length(r);
    if (d > 0) dd = r / d;
  }
  if (wp.distortion != 0) {
    const Noise3 n = fractal_noise(tex.table, q, tex.fractal, max_octaves);
    d += wp.distortion * n.value;
    dd += n.grad * wp.distortion;
  }
  // d is the phase in periods; t = profile(d), dt/dd by the chain rule.
  constexpr float kTwoPi = 2 * kPi;
  switch (wp.profile) {
    case WaveProfile::Sine:
      return {0.5f + 0.5f * std::sin(kTwoPi * d), dd * (kPi * std::cos(kTwoPi * d))};
    case WaveProfile::Saw:
      return {d - std::floor(d), dd};
    default: {  // Triangle
      const float f = d - std::floor(d);
      return {1 - std::fabs(2 * f - 1), dd * (f < 0.5f ? 2.0f : -2.0f)};
    }
  }
}

}  // namespace

Affine3f procedural_mapping(Vec3f translation, Vec3f rotation_degrees, Vec3f s) {
  const Quat r = axis_rotation(rotation_degrees.z, 2) * axis_rotation(rotation_degrees.y, 1) *
                 axis_rotation(rotation_degrees.x, 0);
  return to_affine(translate(translation.x, translation.y, translation.z) * rotate(r) * scale(s.x, s.y, s.z));
}

PatternSample eval_pattern(const ProceduralTexture& tex, Vec3f q, float footprint) {
  if (!is_finite(q)) return {};
  const float max_octaves =
      tex.filter && footprint > 0 ? fractal_octave_limit(footprint, tex.fractal.lacunarity) : kInfinity;
  PatternSample s;
  switch (tex.kind) {
    case PatternKind::Noise:
      s = noise_pattern(tex, q, max_octaves);
      break;
    case PatternKind::Voronoi:
      s = voronoi_pattern(tex, q);
      break;
    case PatternKind::Wave:
      s = wave_pattern(tex, q, max_octaves);
      break;
  }
  if (!std::isfinite(s.t) || !is_finite(s.grad)) return {};
  // Feature distances can exceed 1 (Manhattan F2 reaches ~1.7): t is clamped, flat where clamped.
  if (s.t < 0 || s.t > 1) return {std::clamp(s.t, 0.0f, 1.0f), {}};
  return s;
}

Vec3f eval_ramp(const ColorRamp& ramp, float t) {
  const auto& stops = ramp.stops;
  if (stops.empty()) return {t, t, t};
  if (!(t > stops.front().position)) return stops.front().color;
  if (!(t < stops.back().position)) return stops.back().color;
  // First stop above t; t lies in [lo.position, hi.position).
  const auto hi = std::upper_bound(stops.begin(), stops.end(), t,
                                   [](float v, const RampStop& s) { return v < s.position; });
  const RampStop& b = *hi;
  const RampStop& a = *(hi - 1);
  if (ramp.interpolation == RampInterpolation::Constant) return a.color;
  const float span = b.position - a.position;
  float s = span > 0 ? (t - a.position) / span : 1.0f;
  if (ramp.interpolation == RampInterpolation::Smoothstep) s = s * s * (3 - 2 * s);
  return a.color * (1 - s) + b.color * s;
}

}  // namespace penumbra
