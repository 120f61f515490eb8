// Procedural noise: Perlin's improved gradient noise in 1-4 dimensions (Perlin, "Improving
// noise", SIGGRAPH 2002: quintic fade 6t^5 - 15t^4 + 10t^3, his gradient sets, a permutation
// table shuffled from a seed), fractal sums over it (fBm with a fractional octave count,
// turbulence, Musgrave's ridged multifractal; Ebert et al., "Texturing and Modeling: A
// Procedural Approach", 3rd ed., 2003), domain distortion, and cellular noise (Worley, "A
// cellular texture basis function", SIGGRAPH 1996) with F1, F2 and F2 - F1 under Euclidean,
// Manhattan and Chebyshev metrics. Every function returns its analytic gradient with its value.
// Plain data and free functions; evaluation never allocates, throws or logs.
#pragma once

#include <array>
#include <cstdint>

#include "renderer/core/math.h"

namespace penumbra {

/// Perlin's permutation of 0..255, shuffled (Fisher-Yates) by a generator seeded with `seed`
/// and stored twice so that lookups need no wrap. The noise it defines repeats every 256
/// lattice cells along each axis.
struct PerlinTable {
  uint32_t seed = 0;
  std::array<uint8_t, 512> perm{};
};

/// The table for `seed`: the same seed gives the same table on every platform.
PerlinTable make_perlin_table(uint32_t seed);

/// A noise value with its gradient.
struct Noise1 {
  float value = 0, d = 0;
};
struct Noise2 {
  float value = 0;
  Vec2f grad;
};
struct Noise3 {
  float value = 0;
  Vec3f grad;
};
struct Noise4 {
  float value = 0;
  Vec4f grad;
};

/// Improved gradient noise: 0 at every integer lattice point, C2 everywhere, scaled so that
/// every value lies in [-1, 1] (the scale is the reciprocal of the exact supremum over all
/// gradient choices, see kPerlinRawSupremum). NaN or infinite coordinates give 0.
Noise1 perlin(const PerlinTable& table, float x);
Noise2 perlin(const PerlinTable& table, Vec2f p);
Noise3 perlin(const PerlinTable& table, Vec3f p);
Noise4 perlin(const PerlinTable& table, Vec4f p);

/// Supremum of |noise| before scaling, over every point of a cell and every choice of corner
/// gradients, for dimensions 1..4 (index 0 = 1D): perlin() divides by these.
extern const std::array<float, 4> kPerlinRawSupremum;

/// An upper bound on |gradient| of the scaled 3D noise over all points and tables (used as
/// the noise's Lipschitz constant by displaced implicit surfaces).
extern const float kPerlinGradientBound3;

/// The mean of |perlin(table, p)| in 3D over space and tables (0.2125: 8 x 10^7 samples of four
/// tables gave 0.2102 to 0.2152); the value a turbulence octave is filtered to.
extern const float kPerlinMeanAbs3;

/// Fractal sums over 3D gradient noise.
enum class FractalKind : uint8_t {
  Fbm,         ///< sum of a_k n(f_k p), normalised by sum a_k: range [-1, 1]
  Turbulence,  ///< sum of a_k |n(f_k p)| / sum a_k: range [0, 1]
  Ridged,      ///< Musgrave's ridged multifractal, normalised by M^2 sum a_k with
               ///< M = max(offset, 1 - offset) (offset^2 for offset >= 0.5): range [0, 1]
};

/// Parameters of a fractal sum, with Blender's Noise / Musgrave texture names. Octave k (from 0)
/// has frequency lacunarity^k and amplitude roughness^k; each octave samples the noise at a
/// different fixed offset so that octaves do not share lattice points.
struct FractalParams {
  FractalKind kind = FractalKind::Fbm;
  float detail = 4;        ///< octaves beyond the first, in [0, 15]; a fractional part fades
                           ///< the last octave in linearly
  float roughness = 0.5f;  ///< amplitude gain per octave, in [0, 1]
  float lacunarity = 2;    ///< frequency gain per octave, in [1.01, 16]
  float offset = 1;        ///< Ridged: signal = (offset - |n|)^2, offset in [0, 2]
  float gain = 2;          ///< Ridged: weight of octave k+1 = clamp(gain x signal_k, 0, 1)
  float distortion = 0;    ///< domain distortion: p' = p + distortion x (3 decorrelated noises at p)
};

/// The fractal sum at p with its gradient (chain rule through the distortion). `max_octaves`
/// caps the number of octaves (fractional: the last one kept fades in), for antialiasing by a
/// footprint (fractal_octave_limit); octaves beyond the cap contribute their mean with a zero
/// gradient (0 for Fbm, kPerlinMeanAbs3 times their amplitude for Turbulence; Ridged drops them)
/// and the normalisation stays that of the uncapped sum, so max_octaves <= 0 gives Fbm's mean 0
/// and Turbulence's kPerlinMeanAbs3. Params outside their documented ranges are clamped into them.
Noise3 fractal_noise(const PerlinTable& table, Vec3f p, const FractalParams& params,
                     float max_octaves = kInfinity);

/// The number of octaves (fractional, >= 0) whose period 1 / lacunarity^k is at least twice a
/// footprint of width `width` (in the noise's own units): log_lacunarity(0.5 / width) + 1,
/// clamped to >= 0; infinite for width 0.
float fractal_octave_limit(float width, float lacunarity);

/// An upper bound on |gradient| of fractal_noise() with these parameters (from
/// kPerlinGradientBound3, the octave frequencies and amplitudes and the distortion's Jacobian),
/// so that f + amplitude x fractal_noise has Lipschitz bound L_f + |amplitude| x this.
float fractal_gradient_bound(const FractalParams& params);

enum class WorleyFeature : uint8_t { F1, F2, F2MinusF1 };
enum class WorleyMetric : uint8_t { Euclidean, Manhattan, Chebyshev };

/// Cellular noise over unit lattice cells with one feature point per cell.
struct WorleyParams {
  WorleyFeature feature = WorleyFeature::F1;
  WorleyMetric metric = WorleyMetric::Euclidean;
  float randomness = 1;  ///< jitter of each feature point from its cell centre, in [0, 1]
};

struct WorleyValue {
  float value = 0;        ///< the chosen feature distance
  Vec3f grad;             ///< its gradient with respect to p (zero where undefined)
  Vec3f nearest;          ///< the nearest feature point
  float cell_random = 0;  ///< a value in [0, 1) hashed from the nearest point's cell (per-cell colour)
};

/// The feature point of lattice cell (ix, iy, iz) for `seed`: cell centre + randomness x
/// (hashed jitter in [-0.5, 0.5)^3).
Vec3f worley_feature_point(uint32_t seed, int ix, int iy, int iz, float randomness);

/// Exact F1 / F2 over all cells (the search widens past the 3x3x3 neighbourhood whenever a
/// farther cell could still hold a closer point). NaN or infinite coordinates give value 0.
WorleyValue worley(uint32_t seed, Vec3f p, const WorleyParams& params);

}  // namespace penumbra
