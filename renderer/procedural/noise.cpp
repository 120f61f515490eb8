// Procedural noise: Perlin's improved gradient noise in 1-4 dimensions over a seeded
// permutation table, fractal sums over the 3D noise (fBm, turbulence, ridged multifractal, with
// domain distortion) and Worley cellular noise, each with its analytic gradient. Evaluation
// never allocates, throws or logs; non-finite input gives zero.
#include "renderer/procedural/noise.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

// Supremum of |raw noise| over a cell and every choice of corner gradients. For a fixed point p
// the choices are independent per corner, so the supremum over them is sum_c w_c(p) max_g
// g.(p - c); its maximum over the cell was found offline (a dense grid of the cell, of the half
// cell [0, 0.5]^N for 3D and 4D by the sets' sign symmetry, then pattern search from the 20 best
// grid points):
//   1D 0.5 at t = 0.5;  2D 1.0 at the cell centre;  3D 1.0363538 at (0.3553, 0.5, 0.4815)
//   (and its mirror images);  4D 1.5365823 at (0.5, 0.4919, 0.4816, 0.3564).
// The constants are those maxima plus 0.1%, so that scaled values are within [-1, 1].
const std::array<float, 4> kPerlinRawSupremum = {0.5005f, 1.001f, 1.03739f, 1.53812f};

// Supremum of |gradient| of the scaled 3D noise. The gradient is sum_c v_c(g_c) with
// v_c(g) = grad(w_c) (g.d_c) + w_c g; for fixed p, sup over gradient choices of |sum_c v_c| =
// sup over unit u of sum_c max_g u.v_c(g) (separable for fixed u). Computed offline over a
// 26^3 grid of the half cell [0, 0.5]^3 (sorted coordinates, by symmetry) and 3000 directions
// u of a hemisphere (Fibonacci lattice), each refined by pattern search in u and then in p from
// the 8 best points: the maximum is 3.6148 (raw 3.75) at the cell centre. The constant adds 3%
// for the discretisation of p and u.
const float kPerlinGradientBound3 = 3.73f;
const float kPerlinMeanAbs3 = 0.2125f;

namespace {

// splitmix64's finaliser (a bijection of 64-bit words).
uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Steele, Lea and Flood's splitmix64 generator.
uint64_t splitmix64(uint64_t& state) {
  return mix64(state += 0x9E3779B97F4A7C15ull);
}

float sign_of(float x) {
  return x > 0 ? 1.0f : (x < 0 ? -1.0f : 0.0f);
}

float fade(float t) {
  return t * t * t * (t * (t * 6 - 15) + 10);
}
float fade_derivative(float t) {
  return 30 * t * t * (t * (t - 2) + 1);
}

// The lattice index of an integral float, modulo 256. Floats of magnitude >= 2^31 are
// multiples of 256, so their index is 0.
int lattice_index(float integral) {
  if (std::fabs(integral) >= 2147483648.0f) return 0;
  return int(int64_t(integral) & 255);
}

// Gradient sets: 1D g = +-(1 + (h & 7)) / 8; 2D the 8 directions (+-1, 0), (0, +-1), (+-1, +-1);
// 3D Perlin's 12 cube-edge vectors padded to 16 with (1,1,0), (-1,1,0), (0,-1,1), (0,-1,-1);
// 4D the 32 vectors with one zero coordinate and the others +-1 (zero at h >> 3, signs h & 7).
constexpr float kGrad2[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};
constexpr float kGrad3[16][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                 {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                                 {1, 1, 0},  {-1, 1, 0},  {0, -1, 1}, {0, -1, -1}};

template <int N>
void corner_gradient(int h, float (&g)[N]) {
  if constexpr (N == 1) {
    g[0] = float(1 + (h & 7)) * ((h & 8) ? -0.125f : 0.125f);
  } else if constexpr (N == 2) {
    for (int i = 0; i < 2; ++i) g[i] = kGrad2[h & 7][i];
  } else if constexpr (N == 3) {
    for (int i = 0; i < 3; ++i) g[i] = kGrad3[h & 15][i];
  } else {
    const int zero = (h >> 3) & 3;
    for (int i = 0, bit = 0; i < 4; ++i) g[i] = i == zero ? 0.0f : (((h >> bit++) & 1) ? -1.0f : 1.0f);
  }
}

// Improved noise in N dimensions, scaled into [-1, 1]; writes the gradient.
template <int N>
float gradient_noise(const PerlinTable& table, const float (&p)[N], float (&grad)[N]) {
  for (int i = 0; i < N; ++i) grad[i] = 0;
  for (int i = 0; i < N; ++i)
    if (!std::isfinite(p[i])) return 0;
  int cell[N];
  float t[N], u[N], du[N];
  for (int i = 0; i < N; ++i) {
    const float fl = std::floor(p[i]);
    cell[i] = lattice_index(fl);
    t[i] = p[i] - fl;
    u[i] = fade(t[i]);
    du[i] = fade_derivative(t[i]);
  }
  // Corner c (bit i = offset along axis i) hashes to perm[...perm[perm[x_0] + x_1]... + x_{N-1}],
  // built axis by axis: after axis i, hash[c] for c < 2^(i+1) holds the prefix over axes 0..i.
  int hash[1 << N] = {0};
  for (int i = 0; i < N; ++i) {
    const int half = 1 << i;
    for (int c = half; c < 2 * half; ++c) hash[c] = table.perm[size_t(hash[c - half] + cell[i] + 1)];
    for (int c = 0; c < half; ++c) hash[c] = table.perm[size_t(hash[c] + cell[i])];
  }
  float value = 0;
#pragma GCC unroll 16
  for (int c = 0; c < (1 << N); ++c) {
    float d[N], axis_weight[N], g[N];
    for (int i = 0; i < N; ++i) {
      const int bit = (c >> i) & 1;
      d[i] = t[i] - float(bit);
      axis_weight[i] = bit ? u[i] : 1 - u[i];
    }
    corner_gradient<N>(hash[c], g);
    float dot = 0, w = 1;
    for (int i = 0; i < N; ++i) dot += g[i] * d[i], w *= axis_weight[i];
    value += w * dot;
    for (int i = 0; i < N; ++i) {
      float dw = ((c >> i) & 1) ? du[i] : -du[i];
      for (int j = 0; j < N; ++j)
        if (j != i) dw *= axis_weight[j];
      grad[i] += dw * dot + w * g[i];
    }
  }
  const float scale = 1 / kPerlinRawSupremum[N - 1];
  for (int i = 0; i < N; ++i) grad[i] *= scale;
  return value * scale;
}

}  // namespace

PerlinTable make_perlin_table(uint32_t seed) {
  PerlinTable table;
  table.seed = seed;
  for (int i = 0; i < 256; ++i) table.perm[size_t(i)] = uint8_t(i);
  uint64_t state = seed;
  for (int i = 255; i > 0; --i) {
    const auto j = size_t(((splitmix64(state) >> 32) * uint64_t(i + 1)) >> 32);
    std::swap(table.perm[size_t(i)], table.perm[j]);
  }
  for (size_t i = 0; i < 256; ++i) table.perm[256 + i] = table.perm[i];
  return table;
}

Noise1 perlin(const PerlinTable& table, float x) {
  const float p[1] = {x};
  float g[1];
  const float v = gradient_noise<1>(table, p, g);
  return {v, g[0]};
}

Noise2 perlin(const PerlinTable& table, Vec2f q) {
  const float p[2] = {q.x, q.y};
  float g[2];
  const float v = gradient_noise<2>(table, p, g);
  return {v, {g[0], g[1]}};
}

Noise3 perlin(const PerlinTable& table, Vec3f q) {
  const float p[3] = {q.x, q.y, q.z};
  float g[3];
  const float v = gradient_noise<3>(table, p, g);
  return {v, {g[0], g[1], g[2]}};
}

Noise4 perlin(const PerlinTable& table, Vec4f q) {
  const float p[4] = {q.x, q.y, q.z, q.w};
  float g[4];
  const float v = gradient_noise<4>(table, p, g);
  return {v, {g[0], g[1], g[2], g[3]}};
}

// ---------------------------------------------------------------------------------------------
// Fractal sums

namespace {

// Octave k samples the noise at f_k p + (k + 1) kOctaveStep: fractional offsets, so that no two
// octaves share lattice points (the fractional parts of (k + 1) x 0.31, 0.79, 0.57 never vanish
// for k < 99). The distortion noises sample at p + kDistortionOffset[i].
constexpr Vec3f kOctaveStep{17.31f, 41.79f, 29.57f};
constexpr Vec3f kDistortionOffset[3] = {
    {5.37f, 11.83f, 2.71f}, {13.19f, 3.47f, 23.61f}, {31.73f, 19.29f, 7.13f}};

FractalParams clamped(const FractalParams& in) {
  const auto fix = [](float v, float lo, float hi, float fallback) {
    return std::isfinite(v) ? std::clamp(v, lo, hi) : fallback;
  };
  FractalParams p = in;
  if (p.kind != FractalKind::Turbulence && p.kind != FractalKind::Ridged) p.kind = FractalKind::Fbm;
  p.detail = fix(in.detail, 0, 15, 4);
  p.roughness = fix(in.roughness, 0, 1, 0.5f);
  p.lacunarity = fix(in.lacunarity, 1.01f, 16, 2);
  p.offset = fix(in.offset, 0, 2, 1);
  p.gain = fix(in.gain, 0, 1e6f, 2);
  p.distortion = fix(in.distortion, -1e6f, 1e6f, 0);
  return p;
}

// The weight of octave k in a sum of `octaves` (fractional) octaves: 1 for the whole ones, the
// fractional part for the last, 0 beyond.
float octave_weight(float octaves, int k) {
  return std::clamp(octaves - float(k), 0.0f, 1.0f);
}

// sum_k weight_k roughness^k over `octaves` (fractional) octaves.
float capped_amplitude_sum(const FractalParams& p, float octaves) {
  float sum = 0, a = 1;
  for (int k = 0; k < octaves; ++k, a *= p.roughness) sum += octave_weight(octaves, k) * a;
  return sum;
}

// The same over the uncapped octaves (detail + 1 of them).
float amplitude_sum(const FractalParams& p) {
  return capped_amplitude_sum(p, p.detail + 1);
}

// The largest |offset - |n|| for |n| <= 1: Ridged's signals are at most its square.
float ridged_signal_root_max(float offset) {
  return std::max(offset, 1 - offset);
}

Noise3 octave_noise(const PerlinTable& table, Vec3f q, float frequency, int k) {
  Noise3 n = perlin(table, q * frequency + float(k + 1) * kOctaveStep);
  n.grad *= frequency;
  return n;
}

// fBm or turbulence at q: the unnormalised sum and its gradient in q.
Noise3 sum_fbm(const PerlinTable& table, Vec3f q, const FractalParams& p, float octaves) {
  Noise3 sum;
  float a = 1, f = 1;
  for (int k = 0; k < octaves; ++k, a *= p.roughness, f *= p.lacunarity) {
    Noise3 n = octave_noise(table, q, f, k);
    if (p.kind == FractalKind::Turbulence) {
      const float s = sign_of(n.value);
      n.value *= s, n.grad *= s;
    }
    const float c = a * octave_weight(octaves, k);
    sum.value += c * n.value;
    sum.grad += c * n.grad;
  }
  return sum;
}

// Musgrave's ridged multifractal at q: signal s_k = (offset - |n_k|)^2, weighted signal
// S_k = s_k w_k with w_0 = 1 and w_{k+1} = clamp(gain S_k, 0, 1); the sum of a_k S_k and its
// gradient (chain rule through the weights), unnormalised.
Noise3 sum_ridged(const PerlinTable& table, Vec3f q, const FractalParams& p, float octaves) {
  Noise3 sum;
  float a = 1, f = 1, w = 1;
  Vec3f dw{};
  for (int k = 0; k < octaves; ++k, a *= p.roughness, f *= p.lacunarity) {
    const Noise3 n = octave_noise(table, q, f, k);
    const float sign = sign_of(n.value);
    const float root = p.offset - std::fabs(n.value);
    const float s = root * root;
    const Vec3f ds = n.grad * (-2 * root * sign);
    const float weighted = s * w;
    const Vec3f d_weighted = ds * w + dw * s;
    const float c = a * octave_weight(octaves, k);
    sum.value += c * weighted;
    sum.grad += c * d_weighted;
    const float x = p.gain * weighted;
    if (x <= 0) {
      w = 0, dw = {};
    } else if (x >= 1) {
      w = 1, dw = {};
    } else {
      w = x, dw = d_weighted * p.gain;
    }
  }
  return sum;
}

// p' = p + distortion x (n(p + o_0), n(p + o_1), n(p + o_2)) and the rows of its Jacobian
// J = I + distortion x dV/dp.
Vec3f distort(const PerlinTable& table, Vec3f p, float distortion, Vec3f (&jacobian)[3]) {
  Vec3f q = p;
  for (int i = 0; i < 3; ++i) {
    const Noise3 n = perlin(table, p + kDistortionOffset[i]);
    q[i] += distortion * n.value;
    jacobian[i] = n.grad * distortion;
    jacobian[i][i] += 1;
  }
  return q;
}

}  // namespace

Noise3 fractal_noise(const PerlinTable& table, Vec3f p, const FractalParams& params, float max_octaves) {
  const FractalParams fp = clamped(params);
  const float octaves = std::min(fp.detail + 1, max_octaves);  // a NaN cap keeps detail + 1
  if (!is_finite(p)) return {};
  // Turbulence's octaves past the cap are filtered to their mean |n|.
  const float dropped_mean =
      fp.kind == FractalKind::Turbulence && octaves < fp.detail + 1
          ? kPerlinMeanAbs3 * (1 - capped_amplitude_sum(fp, octaves) / amplitude_sum(fp))
          : 0.0f;
  if (!(octaves > 0)) return {dropped_mean, {}};

  Vec3f jacobian[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Vec3f q = fp.distortion != 0 ? distort(table, p, fp.distortion, jacobian) : p;
  Noise3 sum =
      fp.kind == FractalKind::Ridged ? sum_ridged(table, q, fp, octaves) : sum_fbm(table, q, fp, octaves);

  // Normalise by the uncapped sum's range, and take the gradient back through the distortion:
  // grad_p = J^T grad_q.
  float normaliser = amplitude_sum(fp);
  if (fp.kind == FractalKind::Ridged)
    normaliser *= ridged_signal_root_max(fp.offset) * ridged_signal_root_max(fp.offset);
  const Vec3f g = sum.grad / normaliser;
  sum.value /= normaliser;
  sum.grad = jacobian[0] * g.x + jacobian[1] * g.y + jacobian[2] * g.z;
  sum.value += dropped_mean;
  return sum;
}

float fractal_octave_limit(float width, float lacunarity) {
  if (!(width > 0)) return kInfinity;
  const float lac = std::isfinite(lacunarity) ? std::clamp(lacunarity, 1.01f, 16.0f) : 2.0f;
  return std::max(0.0f, std::log(0.5f / width) / std::log(lac) + 1);
}

// For fBm and turbulence |grad| <= L sum_k c_k a_k f_k / A (L = kPerlinGradientBound3, c_k the
// octave weights, A the normaliser). For Ridged, with M = max(offset, 1 - offset) (so s_k <= M^2
// and |d s_k| <= 2 M L f_k) and w_k in [0, 1] with |d w_{k+1}| <= gain |d S_k|, the weighted
// signals obey |d S_k| <= B_k with B_0 = 2 M L f_0, B_k = 2 M L f_k + M^2 gain B_{k-1}, and
// |grad| <= sum_k c_k a_k B_k / (M^2 A). The distortion's Jacobian has norm at most
// 1 + |distortion| |dV/dp|_F <= 1 + |distortion| sqrt(3) L.
float fractal_gradient_bound(const FractalParams& params) {
  const FractalParams fp = clamped(params);
  const float L = kPerlinGradientBound3, octaves = fp.detail + 1;
  const float m = ridged_signal_root_max(fp.offset);
  float sum = 0, a = 1, f = 1, b = 0;
  for (int k = 0; k < octaves; ++k, a *= fp.roughness, f *= fp.lacunarity) {
    const float c = a * octave_weight(octaves, k);
    if (fp.kind == FractalKind::Ridged) {
      b = 2 * m * L * f + m * m * fp.gain * b;
      sum += c * b;
    } else {
      sum += c * L * f;
    }
  }
  float normaliser = amplitude_sum(fp);
  if (fp.kind == FractalKind::Ridged) normaliser *= m * m;
  return sum / normaliser * (1 + std::fabs(fp.distortion) * std::sqrt(3.0f) * L);
}

// ---------------------------------------------------------------------------------------------
// Cellular noise

namespace {

// 64 hashed bits of (seed, ix, iy, iz): for a fixed (seed, ix), a bijection of (iy, iz).
uint64_t cell_hash(uint32_t seed, int ix, int iy, int iz) {
  const uint64_t a = (uint64_t(seed) << 32) | uint32_t(ix);
  const uint64_t b = (uint64_t(uint32_t(iy)) << 32) | uint32_t(iz);
  return mix64(a ^ mix64(b + 0x9E3779B97F4A7C15ull));
}

// A value in [0, 1) from 21 bits of h starting at bit `shift`.
float unit_float21(uint64_t h, int shift) {
  return float((h >> shift) & 0x1FFFFF) * (1.0f / 2097152.0f);
}

// The metric's length of v, squared for Euclidean (the same order, without the root).
float metric_rank(Vec3f v, WorleyMetric metric) {
  const Vec3f a = abs(v);
  switch (metric) {
    case WorleyMetric::Manhattan:
      return a.x + a.y + a.z;
    case WorleyMetric::Chebyshev:
      return max_component(a);
    default:
      return dot(v, v);
  }
}

float rank_to_distance(float rank, WorleyMetric metric) {
  return metric == WorleyMetric::Euclidean ? std::sqrt(rank) : rank;
}
float distance_to_rank(float distance, WorleyMetric metric) {
  return metric == WorleyMetric::Euclidean ? distance * distance : distance;
}

// d |v|_metric / dv (zero where undefined: at v = 0).
Vec3f metric_gradient(Vec3f v, WorleyMetric metric) {
  switch (metric) {
    case WorleyMetric::Manhattan:
      return {sign_of(v.x), sign_of(v.y), sign_of(v.z)};
    case WorleyMetric::Chebyshev: {
      const Vec3f a = abs(v);
      const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
      Vec3f g{};
      g[axis] = sign_of(v[axis]);
      return g;
    }
    default:
      return normalize(v);
  }
}

// The two nearest feature points so far, with their metric_rank.
struct Candidates {
  float d1 = kInfinity, d2 = kInfinity;
  Vec3f q1, q2;
  int cell1[3] = {0, 0, 0};
};

// Visits cell k: skipped when even the nearest point of the box its feature point can lie in
// (centre +- randomness / 2) is no closer than the current F2 (F1 if only F1 is wanted).
void visit_cell(uint32_t seed, Vec3f p, const int (&k)[3], const WorleyParams& wp, bool only_f1,
                Candidates& c) {
  Vec3f gap;
  for (int i = 0; i < 3; ++i) {
    const float centre = float(k[i]) + 0.5f;
    gap[i] = std::max(0.0f, std::fabs(p[i] - centre) - 0.5f * wp.randomness);
  }
  if (metric_rank(gap, wp.metric) >= (only_f1 ? c.d1 : c.d2)) return;
  const Vec3f q = worley_feature_point(seed, k[0], k[1], k[2], wp.randomness);
  const float d = metric_rank(p - q, wp.metric);
  if (d < c.d1) {
    c.d2 = c.d1, c.q2 = c.q1;
    c.d1 = d, c.q1 = q;
    for (int i = 0; i < 3; ++i) c.cell1[i] = k[i];
  } else if (d < c.d2) {
    c.d2 = d, c.q2 = q;
  }
}

// Ring r holds the cells at Chebyshev index distance r from p's cell. A feature point of ring
// r + 1 lies at least r + (1 - randomness) / 2 from p along one axis, so at least that far in
// every metric: the search stops before a ring that cannot beat the current F2 (F1 if only F1
// is wanted). It never needs ring 5: F2 is at most the distance to the second-nearest of p's
// cell and a face neighbour, <= 4 in every metric (Manhattan 2 + 1 + 1; Euclidean sqrt(6);
// Chebyshev 2), and ring 5 lies farther than 4.
Candidates nearest_features(uint32_t seed, Vec3f p, const WorleyParams& wp) {
  constexpr int kMaxRing = 4;
  const bool only_f1 = wp.feature == WorleyFeature::F1;
  const int base[3] = {int(std::floor(p.x)), int(std::floor(p.y)), int(std::floor(p.z))};
  Candidates c;
  for (int r = 0; r <= kMaxRing; ++r) {
    const float ring_distance = float(r - 1) + 0.5f * (1 - wp.randomness);
    if (r >= 2 && distance_to_rank(ring_distance, wp.metric) >= (only_f1 ? c.d1 : c.d2)) break;
    for (int dz = -r; dz <= r; ++dz)
      for (int dy = -r; dy <= r; ++dy) {
        const bool on_shell = dz == -r || dz == r || dy == -r || dy == r;
        for (int dx = -r; dx <= r; dx += (on_shell || r == 0) ? 1 : 2 * r) {
          const int k[3] = {base[0] + dx, base[1] + dy, base[2] + dz};
          visit_cell(seed, p, k, wp, only_f1, c);
        }
      }
  }
  return c;
}

}  // namespace

Vec3f worley_feature_point(uint32_t seed, int ix, int iy, int iz, float randomness) {
  const uint64_t h = cell_hash(seed, ix, iy, iz);
  const Vec3f jitter{unit_float21(h, 0) - 0.5f, unit_float21(h, 21) - 0.5f, unit_float21(h, 42) - 0.5f};
  return Vec3f{float(ix) + 0.5f, float(iy) + 0.5f, float(iz) + 0.5f} + jitter * randomness;
}

WorleyValue worley(uint32_t seed, Vec3f p, const WorleyParams& params) {
  if (!is_finite(p)) return {};
  WorleyParams wp = params;
  wp.randomness = std::isfinite(wp.randomness) ? std::clamp(wp.randomness, 0.0f, 1.0f) : 1.0f;
  // Cell indices must fit an int: beyond 2^30 floats are 128 apart and cells meaningless anyway.
  constexpr float kLimit = 1073741824.0f;
  p = {std::clamp(p.x, -kLimit, kLimit), std::clamp(p.y, -kLimit, kLimit), std::clamp(p.z, -kLimit, kLimit)};
  const Candidates c = nearest_features(seed, p, wp);
  const float d1 = rank_to_distance(c.d1, wp.metric), d2 = rank_to_distance(c.d2, wp.metric);

  WorleyValue out;
  out.nearest = c.q1;
  out.cell_random = unit_float21(mix64(cell_hash(seed, c.cell1[0], c.cell1[1], c.cell1[2])), 40);
  const Vec3f g1 = metric_gradient(p - c.q1, wp.metric);
  switch (wp.feature) {
    case WorleyFeature::F2:
      out.value = d2, out.grad = metric_gradient(p - c.q2, wp.metric);
      break;
    case WorleyFeature::F2MinusF1:
      out.value = d2 - d1, out.grad = metric_gradient(p - c.q2, wp.metric) - g1;
      break;
    default:
      out.value = d1, out.grad = g1;
  }
  return out;
}

}  // namespace penumbra
