// Procedural textures as material inputs: a pattern (gradient noise and its fractal sums,
// cellular noise, or bands and rings distorted by noise, as Blender's Noise, Voronoi and Wave
// texture nodes) evaluated at a mapped point, giving a scalar t in [0, 1] and its gradient; a
// colour ramp and scalar ranges that turn t into base colour, roughness, metallic and emission
// strength; a bump height from the gradient. Plain data built by io/ (or tests); evaluation
// never allocates, throws or logs. Applying it to a surface point is materials/material.h's job.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/procedural/noise.h"

namespace penumbra {

/// The space a procedural texture is evaluated in, before its own mapping.
enum class ProceduralSpace : uint8_t {
  Object,  ///< the instance's object space (the texture moves with the object)
  World,   ///< world space
  Uv,      ///< (u, v, 0) of a texture coordinate set
};

enum class PatternKind : uint8_t {
  Noise,    ///< a fractal sum (FractalParams); Fbm maps to t = 0.5 + 0.5 value
  Voronoi,  ///< cellular noise: t = the feature distance, or the nearest cell's random value
  Wave,     ///< bands along an axis or rings around it, phase distorted by a fractal sum
};

enum class VoronoiOutput : uint8_t { Distance, CellRandom };
enum class WaveType : uint8_t { Bands, Rings };
enum class WaveProfile : uint8_t { Sine, Saw, Triangle };

/// Wave pattern: phase = 2 pi (d + distortion x fractal(q)) with d = q[axis] for bands, the
/// distance from the axis for rings; t = profile(phase): sine 0.5 + 0.5 sin, saw the fraction
/// of a period, triangle 1 - |2 fraction - 1|.
struct WaveParams {
  WaveType type = WaveType::Bands;
  int axis = 0;  ///< 0, 1, 2 = X, Y, Z
  WaveProfile profile = WaveProfile::Sine;
  float distortion = 0;  ///< periods of phase shift per unit of fractal value
};

enum class RampInterpolation : uint8_t {
  Linear,      ///< linear between neighbouring stops
  Constant,    ///< the colour of the stop at or below t
  Smoothstep,  ///< 3s^2 - 2s^3 between neighbouring stops
};

struct RampStop {
  float position = 0;  ///< in [0, 1], non-decreasing along the ramp
  Vec3f color{1, 1, 1};
};

/// Maps t to a colour; t outside the first and last stop takes their colour. At least one stop.
struct ColorRamp {
  std::vector<RampStop> stops{{0, {0, 0, 0}}, {1, {1, 1, 1}}};
  RampInterpolation interpolation = RampInterpolation::Linear;
};

/// How a procedural value combines with the material's own input (factor x image texture).
enum class Compose : uint8_t { Multiply, Replace };

/// A scalar input driven by t: value = min + (max - min) t.
struct ScalarDrive {
  bool enabled = false;
  float min = 0, max = 1;
  Compose compose = Compose::Multiply;
};

struct ProceduralTexture {
  ProceduralSpace space = ProceduralSpace::Object;
  int texcoord = 0;  ///< Uv space: 0 = TEXCOORD_0, 1 = TEXCOORD_1
  /// The texture's own mapping from its space to pattern space: translation x rotation x scale.
  Affine3f mapping;
  PatternKind kind = PatternKind::Noise;
  uint32_t seed = 0;
  PerlinTable table;  ///< make_perlin_table(seed)
  FractalParams fractal;
  WorleyParams voronoi;
  VoronoiOutput voronoi_output = VoronoiOutput::Distance;
  WaveParams wave;
  bool drives_base_color = false;
  ColorRamp base_color;
  Compose base_color_compose = Compose::Multiply;
  ScalarDrive roughness, metallic, emission_strength;
  float bump_height = 0;  ///< world-space height of the bump at t = 1 (0: no bump)
  bool filter = true;     ///< drop octaves finer than the pixel footprint
};

/// A pattern value t in [0, 1] and its gradient with respect to the pattern-space point.
struct PatternSample {
  float t = 0;
  Vec3f grad;
};

/// The mapping translation x R x S with R from Euler angles in degrees applied X, then Y, then Z
/// (Blender's Mapping node in Point mode).
Affine3f procedural_mapping(Vec3f translation, Vec3f rotation_degrees, Vec3f scale);

/// The pattern at pattern-space point q, t clamped to [0, 1] (with a zero gradient where
/// clamped: Voronoi distances can exceed 1). `footprint` is the width of a pixel in pattern space
/// (0: unknown or a point sample); when tex.filter is set, fractal octaves whose period is under
/// two footprints are dropped (fractal_octave_limit).
PatternSample eval_pattern(const ProceduralTexture& tex, Vec3f q, float footprint);

/// The ramp's colour at t.
Vec3f eval_ramp(const ColorRamp& ramp, float t);

/// min + (max - min) t.
inline float eval_drive(const ScalarDrive& d, float t) {
  return d.min + (d.max - d.min) * t;
}

}  // namespace penumbra
