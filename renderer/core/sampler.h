// Per-(pixel, sample) sample streams for the path tracer: a padded, shuffled, Owen-scrambled
// Sobol sequence (Burley, "Practical Hash-based Owen Scrambling", JCGT 9(4), 2020) or
// independent PCG32 numbers. Every stream is a pure function of (pixel, sample index, seed),
// so images never depend on thread scheduling, passes or tile order.
#pragma once

// Sobol: each request takes the next "dimension" d of the path; a hash of (pixel, seed, d)
// shuffles the sample index by a nested uniform scramble (so dimensions are decorrelated
// from one another and from neighbouring pixels) and Owen-scrambles the first two Sobol
// dimensions. For any power-of-two count 2^k the first 2^k samples of a pixel form a
// (0, k, 2)-net in every 2D request: stratified in every elementary interval.

#include <cstdint>

#include "renderer/core/rng.h"

namespace penumbra {

enum class SamplerType : uint8_t { Sobol, Independent };

inline uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

/// Burley's improved Laine-Karras hash: a random permutation in which each output bit depends
/// only on the input bits below it.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

/// Owen scrambling of a 32-bit binary fraction (a random nested uniform permutation of its
/// elementary intervals).
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

/// Sobol dimension 0 (van der Corput) and 1 (primitive polynomial x + 1), as 32-bit fractions.
inline uint32_t sobol_dim0(uint32_t i) {
  return reverse_bits(i);
}
/// Sobol dimension 1 by bit loop: the XOR of the direction numbers v_k of i's set bits.
constexpr uint32_t sobol_dim1_loop(uint32_t i, uint32_t v = 1u << 31) {
  uint32_t r = 0;
  for (; i; i >>= 1, v ^= v >> 1)
    if (i & 1) r ^= v;
  return r;
}
/// Dimension 1 is linear over GF(2) in i's bits, so it is the XOR of four byte tables: entry b
/// of table k is the contribution of byte k of i holding b.
struct SobolDim1Tables {
  uint32_t t[4][256]{};
  constexpr SobolDim1Tables() {
    uint32_t v = 1u << 31;  // direction number of bit 8k
    for (int k = 0; k < 4; ++k) {
      for (uint32_t b = 0; b < 256; ++b) t[k][b] = sobol_dim1_loop(b, v);
      for (int j = 0; j < 8; ++j) v ^= v >> 1;
    }
  }
};
inline constexpr SobolDim1Tables kSobolDim1{};
inline uint32_t sobol_dim1(uint32_t i) {
  return kSobolDim1.t[0][i & 0xff] ^ kSobolDim1.t[1][(i >> 8) & 0xff] ^ kSobolDim1.t[2][(i >> 16) & 0xff] ^
         kSobolDim1.t[3][i >> 24];
}

inline uint32_t hash32(uint64_t a, uint64_t b) {
  return uint32_t(splitmix64(splitmix64(a) ^ b) >> 32);
}

/// 32-bit fraction -> float in [0, 1).
inline float fraction_to_float(uint32_t x) {
  return float(x >> 8) * 0x1p-24f;
}

/// The sample stream of sample `index` of one pixel. Cheap to construct; not thread-shared.
struct SampleStream {
  SamplerType type = SamplerType::Sobol;
  uint64_t pixel_key = 0;  ///< hash of (pixel, seed)
  uint64_t key_mix = 0;    ///< splitmix64(pixel_key), the first half of every dimension's hash32
  uint32_t index = 0;      ///< sample index within the pixel
  uint32_t dim = 0;        ///< next dimension
  Rng rng;                 ///< Independent only

  float get1d() {
    if (type == SamplerType::Independent) return rng.next_float();
    const uint32_t seed = dimension_seed();
    const uint32_t i = nested_uniform_scramble(index, seed);
    return fraction_to_float(nested_uniform_scramble(sobol_dim0(i), hash32(seed, 0)));
  }
  /// hash32(pixel_key, dim++), with splitmix64(pixel_key) computed once per stream.
  uint32_t dimension_seed() { return uint32_t(splitmix64(key_mix ^ dim++) >> 32); }
  Vec2f get2d() {
    if (type == SamplerType::Independent) {
      const float a = rng.next_float();
      return {a, rng.next_float()};
    }
    const uint32_t seed = dimension_seed();
    const uint32_t i = nested_uniform_scramble(index, seed);
    return {fraction_to_float(nested_uniform_scramble(sobol_dim0(i), hash32(seed, 0))),
            fraction_to_float(nested_uniform_scramble(sobol_dim1(i), hash32(seed, 1)))};
  }
};

/// The stream for sample `sample` of pixel (x, y) under `seed`.
inline SampleStream make_sample_stream(SamplerType type, uint32_t x, uint32_t y, uint32_t sample,
                                       uint64_t seed) {
  SampleStream s;
  s.type = type;
  s.index = sample;
  s.pixel_key = splitmix64(splitmix64(seed ^ 0x5eed5eed5eedull) ^ ((uint64_t(y) << 32) | x));
  s.key_mix = splitmix64(s.pixel_key);
  if (type == SamplerType::Independent) s.rng = make_pixel_rng(x, y, sample, seed);
  return s;
}

}  // namespace penumbra
