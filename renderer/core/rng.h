// Deterministic random numbers for rendering: a PCG32 generator seeded by hashing
// (pixel x, pixel y, sample index, user seed), so results never depend on thread scheduling.
// O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically Good Algorithms for
// Random Number Generation", 2014; seed mixing with SplitMix64 (Steele et al. 2014).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "renderer/core/math.h"

namespace penumbra {

constexpr uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

struct Rng {
  uint64_t state = 0x853c49e6748fea9bull;
  uint64_t inc = 0xda3e39cb94b95bdbull;

  uint32_t next_u32() {
    const uint64_t old = state;
    state = old * 6364136223846793005ull + inc;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
  }
  /// Uniform in [0, 1).
  float next_float() { return float(next_u32() >> 8) * 0x1p-24f; }
};

/// The generator for sample `sample` of pixel (x, y).
inline Rng make_pixel_rng(uint32_t x, uint32_t y, uint32_t sample, uint64_t seed) {
  const uint64_t key = splitmix64(splitmix64(splitmix64(seed) ^ ((uint64_t(y) << 32) | x)) ^ sample);
  Rng r;
  r.inc = (splitmix64(key) << 1u) | 1u;
  r.state = 0;
  r.next_u32();
  r.state += key;
  r.next_u32();
  return r;
}

/// Stratified jittered position of sample s of n inside the unit pixel: the first
/// cols x rows samples (cols = floor(sqrt n), rows = n / cols) each fall in their own stratum;
/// any remaining samples are uniform. Unbiased for every n, fully stratified for n = k^2.
inline Vec2f stratified_sample(uint32_t s, uint32_t n, Rng& rng) {
  const float jx = rng.next_float(), jy = rng.next_float();
  uint32_t cols = 1;
  while ((cols + 1) * (cols + 1) <= n) ++cols;
  const uint32_t rows = n / cols;
  if (s >= cols * rows) return {jx, jy};
  return {(float(s % cols) + jx) / float(cols), (float(s / cols) + jy) / float(rows)};
}

/// Uniform direction on the unit sphere from u in [0,1)^2 (Archimedes' projection; pbrt-v4
/// SampleUniformSphere).
inline Vec3f sample_uniform_sphere(Vec2f u) {
  const float z = 1 - 2 * u.x;
  const float r = std::sqrt(std::max(0.0f, 1 - z * z));
  const float phi = 2 * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

}  // namespace penumbra
