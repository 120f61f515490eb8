// Tests for renderer/procedural/noise: lattice zeros, the [-1, 1] range against a supremum
// re-derived here, C1 continuity across cells, analytic gradients against central differences,
// the predicted variance, fBm's spectral falloff, seeding, Worley against a brute-force search,
// the fractal gradient bound and the octave cap.
#include "renderer/procedural/noise.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <functional>
#include <random>
#include <vector>

using namespace penumbra;

namespace {

// An N-dimensional point in double, for the dimension-generic checks.
template <int N>
using Point = std::array<double, N>;

// perlin() in N dimensions at p: the value and gradient in double.
template <int N>
double eval_perlin(const PerlinTable& t, const Point<N>& p, Point<N>* grad = nullptr) {
  Point<N> g{};
  double v = 0;
  if constexpr (N == 1) {
    const Noise1 n = perlin(t, float(p[0]));
    v = n.value, g = {n.d};
  } else if constexpr (N == 2) {
    const Noise2 n = perlin(t, Vec2f{float(p[0]), float(p[1])});
    v = n.value, g = {n.grad.x, n.grad.y};
  } else if constexpr (N == 3) {
    const Noise3 n = perlin(t, Vec3f{float(p[0]), float(p[1]), float(p[2])});
    v = n.value, g = {n.grad.x, n.grad.y, n.grad.z};
  } else {
    const Noise4 n = perlin(t, Vec4f{float(p[0]), float(p[1]), float(p[2]), float(p[3])});
    v = n.value, g = {n.grad.x, n.grad.y, n.grad.z, n.grad.w};
  }
  if (grad) *grad = g;
  return v;
}

// The documented gradient sets, as the table index h & mask selects them (so a uniform index
// gives each entry the weight 1 / size).
template <int N>
std::vector<Point<N>> gradient_set() {
  std::vector<Point<N>> set;
  if constexpr (N == 1) {
    for (int h = 0; h < 16; ++h) set.push_back({(h & 8 ? -1.0 : 1.0) * (1 + (h & 7)) / 8.0});
  } else if constexpr (N == 2) {
    set = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};
  } else {
    // The vectors with one zero coordinate and the others +-1: 12 in 3D, 32 in 4D.
    for (int zero = 0; zero < N; ++zero)
      for (int s = 0; s < (1 << (N - 1)); ++s) {
        Point<N> g{};
        for (int i = 0, bit = 0; i < N; ++i) g[size_t(i)] = i == zero ? 0 : ((s >> bit++) & 1 ? -1 : 1);
        set.push_back(g);
      }
    if constexpr (N == 3) {  // Perlin's padding to 16
      set.push_back({1, 1, 0}), set.push_back({-1, 1, 0}), set.push_back({0, -1, 1}),
          set.push_back({0, -1, -1});
    }
  }
  return set;
}

double fade(double t) {
  return t * t * t * (t * (t * 6 - 15) + 10);
}

// The weight of cell corner c (bit i = offset along axis i) at the in-cell position t.
template <int N>
double corner_weight(const Point<N>& t, int c) {
  double w = 1;
  for (int i = 0; i < N; ++i) w *= (c >> i) & 1 ? fade(t[size_t(i)]) : 1 - fade(t[size_t(i)]);
  return w;
}

// Every point of a grid of r^N points over [0, hi]^N, passed to `f`.
template <int N>
void for_grid(int r, double hi, const std::function<void(const Point<N>&)>& f) {
  long total = 1;
  for (int i = 0; i < N; ++i) total *= r;
  for (long k = 0; k < total; ++k) {
    Point<N> t;
    long q = k;
    for (int i = 0; i < N; ++i, q /= r) t[size_t(i)] = hi * double(q % r) / (r - 1);
    f(t);
  }
}

// sup over gradient choices of the raw noise at t: sum_c w_c max_g g.(t - c).
template <int N>
double separable_supremum_at(const Point<N>& t, const std::vector<Point<N>>& set) {
  double s = 0;
  for (int c = 0; c < (1 << N); ++c) {
    double best = -1e30;
    for (const auto& g : set) {
      double dot = 0;
      for (int i = 0; i < N; ++i) dot += g[size_t(i)] * (t[size_t(i)] - ((c >> i) & 1));
      best = std::max(best, dot);
    }
    s += corner_weight<N>(t, c) * best;
  }
  return s;
}

// sup over gradient choices of |gradient| of the scaled 3D noise at t: the maximum over unit u
// (a Fibonacci lattice of `directions` points) of sum_c max_g u.v_c(g), with
// v_c(g) = grad(w_c) (g.d_c) + w_c g; the lattice misses the maximum by a factor cos(gap).
double gradient_supremum_at(const Point<3>& t, const std::vector<Point<3>>& set, int directions) {
  std::vector<Point<3>> v;  // v_c(g) for every corner and gradient, corner-major
  for (int c = 0; c < 8; ++c) {
    const double w = corner_weight<3>(t, c);
    Point<3> dw, d;
    for (int i = 0; i < 3; ++i) {
      const double ti = t[size_t(i)], df = 30 * ti * ti * (1 - ti) * (1 - ti);
      const double wi = (c >> i) & 1 ? fade(ti) : 1 - fade(ti);
      dw[size_t(i)] = ((c >> i) & 1 ? df : -df) * (wi > 0 ? w / wi : 0);
      d[size_t(i)] = ti - ((c >> i) & 1);
    }
    for (const auto& g : set) {
      const double gd = g[0] * d[0] + g[1] * d[1] + g[2] * d[2];
      v.push_back({dw[0] * gd + w * g[0], dw[1] * gd + w * g[1], dw[2] * gd + w * g[2]});
    }
  }
  double best = 0;
  for (int k = 0; k < directions; ++k) {
    const double z = 1 - (k + 0.5) / directions, r = std::sqrt(1 - z * z), phi = k * 2.399963229728653;
    const Point<3> u{r * std::cos(phi), r * std::sin(phi), z};
    double sum = 0;
    for (size_t c = 0; c < 8; ++c) {
      double m = -1e30;
      for (size_t j = 0; j < set.size(); ++j) {
        const Point<3>& x = v[c * set.size() + j];
        m = std::max(m, u[0] * x[0] + u[1] * x[1] + u[2] * x[2]);
      }
      sum += m;
    }
    best = std::max(best, sum);
  }
  return best / kPerlinRawSupremum[2];
}

template <int N>
Point<N> random_point(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  Point<N> p;
  for (auto& x : p) x = u(rng);
  return p;
}

Vec3f random_vec3(std::mt19937& rng, float lo, float hi) {
  std::uniform_real_distribution<float> u(lo, hi);
  const float x = u(rng), y = u(rng), z = u(rng);
  return {x, y, z};
}

// Central difference of f along axis `axis` at p (step h), over the step actually represented.
template <class F>
double central_difference(const F& f, Vec3f p, int axis, float h) {
  Vec3f a = p, b = p;
  a[axis] += h, b[axis] -= h;
  return (double(f(a)) - double(f(b))) / (double(a[axis]) - double(b[axis]));
}

// The fraction of `samples` random points in [0, 8)^3 where f's analytic gradient agrees with
// central differences to within tol (1 + |grad|).
template <class F>
double gradient_agreement(const F& f, int samples, float h, double tol, uint32_t seed) {
  std::mt19937 rng(seed);
  int good = 0;
  for (int s = 0; s < samples; ++s) {
    const Vec3f p = random_vec3(rng, 0, 8);
    const Noise3 n = f(p);
    const auto value = [&](Vec3f q) { return f(q).value; };
    bool ok = true;
    for (int i = 0; i < 3; ++i)
      ok = ok && std::abs(central_difference(value, p, i, h) - n.grad[i]) <= tol * (1 + length(n.grad));
    good += ok;
  }
  return double(good) / samples;
}

FractalParams fractal(FractalKind kind, float detail, float distortion = 0) {
  FractalParams p;
  p.kind = kind, p.detail = detail, p.distortion = distortion;
  return p;
}

// The uncapped normaliser sum_k c_k roughness^k for `detail` (c_k the octave weights).
double amplitude_sum(double detail, double roughness) {
  double sum = 0, a = 1;
  const int whole = int(std::floor(detail));
  for (int k = 0; k <= whole; ++k, a *= roughness) sum += a;
  return sum + (detail - whole) * a;
}

void fft(std::vector<std::complex<double>>& x) {
  const size_t n = x.size();
  for (size_t i = 1, j = 0; i < n; ++i) {  // bit-reversal permutation
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(x[i], x[j]);
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const std::complex<double> w = std::polar(1.0, -2 * M_PI / double(len));
    for (size_t i = 0; i < n; i += len) {
      std::complex<double> wk = 1;
      for (size_t k = 0; k < len / 2; ++k, wk *= w) {
        const std::complex<double> a = x[i + k], b = x[i + k + len / 2] * wk;
        x[i + k] = a + b, x[i + k + len / 2] = a - b;
      }
    }
  }
}

// check(std::integral_constant<int, N>{}) for N = 1..4.
template <class F>
void for_each_dimension(const F& check) {
  check(std::integral_constant<int, 1>{});
  check(std::integral_constant<int, 2>{});
  check(std::integral_constant<int, 3>{});
  check(std::integral_constant<int, 4>{});
}

constexpr uint32_t kSeeds[] = {0, 1, 7, 0xDEADBEEF};

}  // namespace

TEST_CASE("noise: the table is a seeded permutation stored twice", "[procedural][noise][quick]") {
  for (uint32_t seed : kSeeds) {
    const PerlinTable t = make_perlin_table(seed);
    CHECK(t.seed == seed);
    std::array<int, 256> count{};
    for (size_t i = 0; i < 256; ++i) {
      ++count[t.perm[i]];
      CHECK(t.perm[256 + i] == t.perm[i]);
    }
    CHECK(std::count(count.begin(), count.end(), 1) == 256);
    CHECK(make_perlin_table(seed).perm == t.perm);
  }
  CHECK(make_perlin_table(1).perm != make_perlin_table(2).perm);
}

TEST_CASE("noise: gradient noise vanishes at every lattice point", "[procedural][noise][quick]") {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> small(-300, 300), large(-10000000, 10000000);
  for (uint32_t seed : kSeeds) {
    const PerlinTable t = make_perlin_table(seed);
    for (int s = 0; s < 500; ++s) {
      auto& dist = s % 2 ? large : small;
      const float x = float(dist(rng)), y = float(dist(rng)), z = float(dist(rng)), w = float(dist(rng));
      CHECK(std::abs(perlin(t, x).value) <= 1e-7f);
      CHECK(std::abs(perlin(t, Vec2f{x, y}).value) <= 1e-7f);
      CHECK(std::abs(perlin(t, Vec3f{x, y, z}).value) <= 1e-7f);
      CHECK(std::abs(perlin(t, Vec4f{x, y, z, w}).value) <= 1e-7f);
    }
  }
}

TEST_CASE("noise: non-finite coordinates give zero", "[procedural][noise][quick]") {
  const PerlinTable t = make_perlin_table(5);
  for (float bad : {std::nanf(""), kInfinity, -kInfinity}) {
    const Noise3 n = perlin(t, Vec3f{1.5f, bad, 0.25f});
    CHECK(n.value == 0);
    CHECK(n.grad == Vec3f{});
    CHECK(perlin(t, bad).d == 0);
    CHECK(fractal_noise(t, {bad, 0, 0}, {}).value == 0);
    CHECK(worley(1, {0, 0, bad}, {}).value == 0);
  }
  // Coordinates far beyond the period stay finite and in range.
  const Noise3 far = perlin(t, Vec3f{3e9f, -7e20f, 12345.678f});
  CHECK(std::isfinite(far.value));
  CHECK(std::abs(far.value) <= 1);
}

TEST_CASE("noise: the supremum constants match a re-derivation from the gradient sets",
          "[procedural][noise][quick][heavy]") {
  // Coarse grids (sign symmetry of every set: half cells for 3D and 4D).
  const auto check = [](auto dim, int r, double hi) {
    constexpr int N = decltype(dim)::value;
    const auto set = gradient_set<N>();
    double sup = 0;
    for_grid<N>(r, hi, [&](const Point<N>& t) { sup = std::max(sup, separable_supremum_at<N>(t, set)); });
    INFO("dimension " << N << ": re-derived " << sup << ", constant " << kPerlinRawSupremum[N - 1]);
    CHECK(kPerlinRawSupremum[N - 1] >= sup);
    CHECK(kPerlinRawSupremum[N - 1] <= 1.01 * sup);
  };
  check(std::integral_constant<int, 1>{}, 1001, 1.0);
  check(std::integral_constant<int, 2>{}, 101, 1.0);
  check(std::integral_constant<int, 3>{}, 41, 1.0);
  check(std::integral_constant<int, 4>{}, 21, 0.5);
}

TEST_CASE("noise: the 3D gradient bound covers a re-derivation from the gradient set",
          "[procedural][noise][quick]") {
  // A coarse grid of the half cell (the set is symmetric under sign flips); +-u is covered by
  // the hemisphere lattice because the set is symmetric under g -> -g.
  const auto set = gradient_set<3>();
  double sup = 0;
  for_grid<3>(6, 0.5, [&](const Point<3>& t) { sup = std::max(sup, gradient_supremum_at(t, set, 1500)); });
  INFO("re-derived " << sup << ", bound " << kPerlinGradientBound3);
  CHECK(kPerlinGradientBound3 >= sup);
  CHECK(kPerlinGradientBound3 <= 1.05 * sup);
}

TEST_CASE("noise: values lie in [-1, 1] and come close to its ends", "[procedural][noise][heavy]") {
  const auto max_abs = [](auto dim, long samples) {
    constexpr int N = decltype(dim)::value;
    const PerlinTable t = make_perlin_table(11);
    std::mt19937 rng(N);
    double m = 0;
    for (long s = 0; s < samples; ++s)
      m = std::max(m, std::abs(eval_perlin<N>(t, random_point<N>(rng, -300, 300))));
    INFO("dimension " << N << ": max |value| " << m);
    CHECK(m <= 1);
    CHECK(m > 0.6);
  };
  max_abs(std::integral_constant<int, 1>{}, 1000000);
  max_abs(std::integral_constant<int, 2>{}, 1000000);
  max_abs(std::integral_constant<int, 3>{}, 10000000);
  max_abs(std::integral_constant<int, 4>{}, 1000000);
}

TEST_CASE("noise: value and gradient are continuous across cell borders", "[procedural][noise][quick]") {
  const auto check = [](auto dim) {
    constexpr int N = decltype(dim)::value;
    const PerlinTable t = make_perlin_table(2);
    std::mt19937 rng(N + 10);
    for (int s = 0; s < 200; ++s) {
      Point<N> p = random_point<N>(rng, -20, 20);
      const int axis = s % N;
      p[size_t(axis)] = std::round(p[size_t(axis)]);
      double previous_jump = 1e30;
      for (double eps : {1e-2, 1e-3, 1e-4}) {
        Point<N> a = p, b = p, ga, gb;
        a[size_t(axis)] += eps, b[size_t(axis)] -= eps;
        const double jump = std::abs(eval_perlin<N>(t, a, &ga) - eval_perlin<N>(t, b, &gb));
        double grad_jump = 0;
        for (int i = 0; i < N; ++i) grad_jump = std::max(grad_jump, std::abs(ga[size_t(i)] - gb[size_t(i)]));
        CHECK(jump <= 16 * eps + 1e-6);
        CHECK(grad_jump <= 200 * eps + 1e-4);
        CHECK(jump <= previous_jump + 1e-6);
        previous_jump = jump;
      }
    }
  };
  for_each_dimension(check);
}

TEST_CASE("noise: gradient noise's analytic gradient matches central differences",
          "[procedural][noise][quick]") {
  const auto check = [](auto dim) {
    constexpr int N = decltype(dim)::value;
    const PerlinTable t = make_perlin_table(4);
    std::mt19937 rng(N + 20);
    for (int s = 0; s < 2000; ++s) {
      const Point<N> p = random_point<N>(rng, -50, 50);
      Point<N> g;
      eval_perlin<N>(t, p, &g);
      for (int i = 0; i < N; ++i) {
        Point<N> a = p, b = p;
        a[size_t(i)] += 1e-3, b[size_t(i)] -= 1e-3;
        const double fd = (eval_perlin<N>(t, a) - eval_perlin<N>(t, b)) /
                          (double(float(a[size_t(i)])) - double(float(b[size_t(i)])));
        CHECK(std::abs(fd - g[size_t(i)]) <= 2e-3);
      }
    }
  };
  for_each_dimension(check);
}

TEST_CASE("noise: fractal gradients match central differences", "[procedural][noise][quick]") {
  const PerlinTable t = make_perlin_table(6);
  for (float distortion : {0.0f, 0.6f}) {
    // fBm is smooth: every sample agrees. Turbulence and Ridged have creases where an octave
    // crosses zero (and Ridged where a weight saturates): almost every sample agrees.
    const FractalParams fbm = fractal(FractalKind::Fbm, 3.5f, distortion);
    CHECK(gradient_agreement([&](Vec3f p) { return fractal_noise(t, p, fbm); }, 1000, 2e-4f, 2e-2, 1) == 1);
    for (FractalKind kind : {FractalKind::Turbulence, FractalKind::Ridged}) {
      const FractalParams fp = fractal(kind, 3.5f, distortion);
      const double agree =
          gradient_agreement([&](Vec3f p) { return fractal_noise(t, p, fp); }, 1000, 2e-4f, 2e-2, 2);
      INFO("kind " << int(kind) << ", distortion " << distortion);
      CHECK(agree >= 0.97);
    }
  }
}

TEST_CASE("noise: Worley gradients match central differences off the cell borders",
          "[procedural][noise][quick]") {
  for (WorleyMetric metric : {WorleyMetric::Euclidean, WorleyMetric::Manhattan, WorleyMetric::Chebyshev})
    for (WorleyFeature feature : {WorleyFeature::F1, WorleyFeature::F2, WorleyFeature::F2MinusF1}) {
      const WorleyParams wp{feature, metric, 0.9f};
      const auto f = [&](Vec3f p) {
        const WorleyValue w = worley(3, p, wp);
        return Noise3{w.value, w.grad};
      };
      INFO("metric " << int(metric) << ", feature " << int(feature));
      CHECK(gradient_agreement(f, 2000, 1e-4f, 1e-2, 3) >= 0.97);
    }
}

TEST_CASE("noise: Euclidean F1's gradient is exact away from the Voronoi cells' borders",
          "[procedural][noise][quick]") {
  std::mt19937 rng(5);
  const WorleyParams f1{WorleyFeature::F1, WorleyMetric::Euclidean, 1};
  const WorleyParams gap{WorleyFeature::F2MinusF1, WorleyMetric::Euclidean, 1};
  const auto value = [&](Vec3f q) { return worley(4, q, f1).value; };
  int tested = 0;
  for (int s = 0; s < 2000; ++s) {
    const Vec3f p = random_vec3(rng, -10, 10);
    if (worley(4, p, gap).value < 0.01f) continue;  // within 0.005 of a border
    const WorleyValue w = worley(4, p, f1);
    for (int i = 0; i < 3; ++i)
      CHECK(central_difference(value, p, i, 1e-4f) == Approx(w.grad[i]).margin(5e-3));
    CHECK(length(w.grad) == Approx(1).margin(1e-5));
    ++tested;
  }
  CHECK(tested > 1900);
}

TEST_CASE("noise: mean and variance match the prediction from the gradient set", "[procedural][noise]") {
  const auto check = [](auto dim) {
    constexpr int N = decltype(dim)::value;
    // Predicted Var = sum_c E_p[w_c^2 d_c^T E[g g^T] d_c] / sup^2 (independent corner gradients,
    // the index uniform over the set), by midpoint quadrature over the cell.
    const auto set = gradient_set<N>();
    std::array<std::array<double, N>, N> ggt{};
    for (const auto& g : set)
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j)
          ggt[size_t(i)][size_t(j)] += g[size_t(i)] * g[size_t(j)] / double(set.size());
    const int q = N == 4 ? 12 : 24;
    double predicted = 0;
    long nodes = 0;
    for_grid<N>(q, 1.0, [&](const Point<N>& grid) {
      Point<N> t;
      for (int i = 0; i < N; ++i) t[size_t(i)] = (grid[size_t(i)] * (q - 1) + 0.5) / q;
      for (int c = 0; c < (1 << N); ++c) {
        Point<N> d;
        for (int i = 0; i < N; ++i) d[size_t(i)] = t[size_t(i)] - ((c >> i) & 1);
        double quad = 0;
        for (int i = 0; i < N; ++i)
          for (int j = 0; j < N; ++j) quad += d[size_t(i)] * ggt[size_t(i)][size_t(j)] * d[size_t(j)];
        predicted += corner_weight<N>(t, c) * corner_weight<N>(t, c) * quad;
      }
      ++nodes;
    });
    predicted /= double(nodes) * kPerlinRawSupremum[N - 1] * kPerlinRawSupremum[N - 1];

    const PerlinTable t = make_perlin_table(8);
    std::mt19937 rng(N + 30);
    double sum = 0, sum2 = 0;
    const int samples = 1000000;
    for (int s = 0; s < samples; ++s) {
      const double v = eval_perlin<N>(t, random_point<N>(rng, 0, 256));
      sum += v, sum2 += v * v;
    }
    const double mean = sum / samples, var = sum2 / samples - mean * mean;
    INFO("dimension " << N << ": mean " << mean << ", variance " << var << ", predicted " << predicted);
    CHECK(std::abs(mean) < 0.01);
    CHECK(var == Approx(predicted).epsilon(0.1));
  };
  for_each_dimension(check);
}

TEST_CASE("noise: fBm's band energies fall by roughness^2 per octave", "[procedural][noise]") {
  // 2^16 samples 1/512 apart along a generic direction, 8 octaves (frequencies 1..128). Band j
  // holds frequencies [2^j, 2^(j+1)) / 4 cycles per unit (bins 32 2^j ..); bands 3..6 (2 to 32
  // cycles per unit) lie where every octave's scaled copy of the base spectrum is present and
  // below aliasing, so consecutive bands' energies have the ratio roughness^2 (checked to 15%;
  // four lines of 256 bins or more per band keep the estimate's scatter to a few percent).
  const PerlinTable t = make_perlin_table(9);
  const size_t n = size_t(1) << 16;
  const double spacing = 1.0 / 512;
  const Vec3f dir = normalize(Vec3f{0.48f, 0.62f, 0.61f});
  for (float roughness : {0.5f, 0.7f}) {
    FractalParams fp = fractal(FractalKind::Fbm, 7);
    fp.roughness = roughness;
    std::array<double, 8> band{};
    for (int line = 0; line < 4; ++line) {
      const Vec3f origin{17.3f * float(line), 5.1f, -3.7f * float(line)};
      std::vector<std::complex<double>> x(n);
      for (size_t i = 0; i < n; ++i)
        x[i] = fractal_noise(t, origin + dir * float(double(i) * spacing), fp).value;
      fft(x);
      for (size_t j = 0; j < band.size(); ++j)
        for (size_t b = 32u << j; b < (64u << j) && b < n / 2; ++b) band[j] += std::norm(x[b]);
    }
    for (size_t j = 3; j < 6; ++j) {
      INFO("roughness " << roughness << ", bands " << j << ", " << j + 1 << ": ratio "
                        << band[j + 1] / band[j]);
      CHECK(band[j + 1] / band[j] == Approx(double(roughness) * roughness).epsilon(0.15));
    }
  }
}

TEST_CASE("noise: the same seed gives the same field, other seeds uncorrelated ones",
          "[procedural][noise][quick]") {
  const PerlinTable a = make_perlin_table(21), a2 = make_perlin_table(21), b = make_perlin_table(22);
  std::mt19937 rng(40);
  double sab = 0, saa = 0, sbb = 0;
  for (int s = 0; s < 100000; ++s) {
    const Vec3f p = random_vec3(rng, -100, 100);
    const float va = perlin(a, p).value, vb = perlin(b, p).value;
    REQUIRE(perlin(a2, p).value == va);
    REQUIRE(worley(21, p, {}).value == worley(21, p, {}).value);
    sab += double(va) * vb, saa += double(va) * va, sbb += double(vb) * vb;
  }
  CHECK(std::abs(sab / std::sqrt(saa * sbb)) < 0.03);
  std::mt19937 rng2(41);
  double wab = 0, waa = 0, wbb = 0, ma = 0, mb = 0;
  std::vector<std::pair<double, double>> w;
  for (int s = 0; s < 50000; ++s) {
    const Vec3f p = random_vec3(rng2, -100, 100);
    w.emplace_back(worley(21, p, {}).value, worley(22, p, {}).value);
    ma += w.back().first / 50000, mb += w.back().second / 50000;
  }
  for (const auto& [va, vb] : w)
    wab += (va - ma) * (vb - mb), waa += (va - ma) * (va - ma), wbb += (vb - mb) * (vb - mb);
  CHECK(std::abs(wab / std::sqrt(waa * wbb)) < 0.03);
}

TEST_CASE("noise: Worley F1 and F2 equal a brute-force search", "[procedural][noise][quick]") {
  std::mt19937 rng(50);
  for (WorleyMetric metric : {WorleyMetric::Euclidean, WorleyMetric::Manhattan, WorleyMetric::Chebyshev})
    for (float randomness : {0.0f, 0.5f, 1.0f})
      for (int s = 0; s < 300; ++s) {
        Vec3f p = random_vec3(rng, -40, 40);
        if (s % 3 == 0) p = {std::round(p.x) + 1e-4f, std::round(p.y) - 1e-4f, std::round(p.z) + 1e-5f};
        const uint32_t seed = uint32_t(s);
        const int cx = int(std::floor(p.x)), cy = int(std::floor(p.y)), cz = int(std::floor(p.z));
        double f1 = 1e30, f2 = 1e30;
        for (int dz = -4; dz <= 4; ++dz)
          for (int dy = -4; dy <= 4; ++dy)
            for (int dx = -4; dx <= 4; ++dx) {
              const Vec3f d = p - worley_feature_point(seed, cx + dx, cy + dy, cz + dz, randomness);
              const Vec3f a = abs(d);
              const double dist = metric == WorleyMetric::Euclidean   ? length(d)
                                  : metric == WorleyMetric::Manhattan ? a.x + a.y + a.z
                                                                      : max_component(a);
              if (dist < f1) {
                f2 = f1, f1 = dist;
              } else if (dist < f2) {
                f2 = dist;
              }
            }
        const WorleyValue w1 = worley(seed, p, {WorleyFeature::F1, metric, randomness});
        const WorleyValue w2 = worley(seed, p, {WorleyFeature::F2, metric, randomness});
        const WorleyValue w21 = worley(seed, p, {WorleyFeature::F2MinusF1, metric, randomness});
        INFO("metric " << int(metric) << ", randomness " << randomness << ", p " << p.x << " " << p.y << " "
                       << p.z);
        CHECK(w1.value == Approx(f1).margin(1e-5));
        CHECK(w2.value == Approx(f2).margin(1e-5));
        CHECK(w21.value == Approx(f2 - f1).margin(2e-5));
        CHECK(w2.value >= w1.value);
        CHECK(w1.cell_random >= 0);
        CHECK(w1.cell_random < 1);
        const Vec3f dn = p - w1.nearest;
        const double nearest_dist = metric == WorleyMetric::Euclidean ? length(dn)
                                    : metric == WorleyMetric::Manhattan
                                        ? std::abs(dn.x) + std::abs(dn.y) + std::abs(dn.z)
                                        : max_component(abs(dn));
        CHECK(nearest_dist == Approx(f1).margin(1e-5));
      }
}

TEST_CASE("noise: the fractal gradient bound holds", "[procedural][noise]") {
  const PerlinTable t = make_perlin_table(12);
  for (FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged})
    for (float distortion : {0.0f, 0.5f}) {
      FractalParams fp = fractal(kind, 3.4f, distortion);
      fp.lacunarity = 2.3f;
      const float bound = fractal_gradient_bound(fp);
      INFO("kind " << int(kind) << ", distortion " << distortion << ", bound " << bound);
      std::mt19937 rng(60 + int(kind));
      float worst = 0, worst_lipschitz = 0;
      for (int s = 0; s < 100000; ++s) {
        const Vec3f a = random_vec3(rng, -30, 30);
        worst = std::max(worst, length(fractal_noise(t, a, fp).grad));
        if (s % 4 == 0) {
          const Vec3f b = a + random_vec3(rng, -0.05f, 0.05f);
          const float lip =
              std::abs(fractal_noise(t, a, fp).value - fractal_noise(t, b, fp).value) / length(a - b);
          worst_lipschitz = std::max(worst_lipschitz, lip);
        }
      }
      CHECK(worst <= bound);
      CHECK(worst_lipschitz <= bound);
      if (kind != FractalKind::Ridged) CHECK(worst > 0.1f * bound);  // not vacuous
    }
  // The 3D noise itself, at many random points of several tables.
  float worst = 0;
  std::mt19937 rng(70);
  for (uint32_t seed : kSeeds) {
    const PerlinTable ts = make_perlin_table(seed);
    for (int s = 0; s < 100000; ++s)
      worst = std::max(worst, length(perlin(ts, random_vec3(rng, -300, 300)).grad));
  }
  CHECK(worst <= kPerlinGradientBound3);
  CHECK(worst > 0.6f * kPerlinGradientBound3);
}

TEST_CASE("noise: fractal sums stay in their ranges", "[procedural][noise][quick]") {
  const PerlinTable t = make_perlin_table(13);
  std::mt19937 rng(80);
  for (FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged})
    for (float offset : {0.2f, 1.0f, 1.8f}) {
      FractalParams fp = fractal(kind, 2.5f, 0.3f);
      fp.offset = offset, fp.roughness = 0.8f;
      const float lo = kind == FractalKind::Fbm ? -1.0f : 0.0f;
      for (int s = 0; s < 20000; ++s) {
        const float v = fractal_noise(t, random_vec3(rng, -50, 50), fp).value;
        REQUIRE(v >= lo);
        REQUIRE(v <= 1);
      }
    }
}

TEST_CASE("noise: capping the octaves keeps the uncapped normalisation", "[procedural][noise][quick]") {
  const PerlinTable t = make_perlin_table(14);
  std::mt19937 rng(90);
  for (FractalKind kind : {FractalKind::Fbm, FractalKind::Turbulence, FractalKind::Ridged}) {
    const FractalParams full = fractal(kind, 4.5f, 0.25f);
    for (float cap : {1.0f, 2.5f, 3.0f, 4.7f}) {
      // Capped at m octaves = uncapped with detail m - 1, rescaled to the full normaliser.
      const FractalParams fewer = fractal(kind, cap - 1, 0.25f);
      const double ratio =
          amplitude_sum(cap - 1, full.roughness) / amplitude_sum(full.detail, full.roughness);
      for (int s = 0; s < 200; ++s) {
        const Vec3f p = random_vec3(rng, -20, 20);
        const Noise3 capped = fractal_noise(t, p, full, cap), reference = fractal_noise(t, p, fewer);
        // Turbulence's dropped octaves add their mean |n| x their share of the amplitude.
        const double mean = kind == FractalKind::Turbulence ? kPerlinMeanAbs3 * (1 - ratio) : 0;
        CHECK(capped.value == Approx(reference.value * ratio + mean).margin(1e-5));
        for (int i = 0; i < 3; ++i) CHECK(capped.grad[i] == Approx(reference.grad[i] * ratio).margin(1e-4));
      }
    }
    CHECK(fractal_noise(t, {0.3f, 0.4f, 0.5f}, full, 0).value ==
          (kind == FractalKind::Turbulence ? kPerlinMeanAbs3 : 0.0f));
    CHECK(fractal_noise(t, {0.3f, 0.4f, 0.5f}, full, -1).grad == Vec3f{});
    CHECK(fractal_noise(t, {0.3f, 0.4f, 0.5f}, full, 99).value ==
          fractal_noise(t, {0.3f, 0.4f, 0.5f}, full).value);
  }
  // fBm's variance drops with the cap.
  double previous = 1e30;
  for (float cap : {5.5f, 4.0f, 3.0f, 2.0f, 1.0f, 0.5f}) {
    std::mt19937 r(91);
    double sum2 = 0;
    for (int s = 0; s < 20000; ++s) {
      const float v = fractal_noise(t, random_vec3(r, 0, 256), fractal(FractalKind::Fbm, 4.5f), cap).value;
      sum2 += double(v) * v;
    }
    CHECK(sum2 < previous);
    previous = sum2;
  }
}

TEST_CASE("noise: the octave limit of a footprint", "[procedural][noise][quick]") {
  CHECK(fractal_octave_limit(0, 2) == kInfinity);
  CHECK(fractal_octave_limit(0.5f, 2) == Approx(1));
  CHECK(fractal_octave_limit(0.125f, 2) == Approx(3));
  CHECK(fractal_octave_limit(1 / 18.0f, 3) == Approx(3));
  CHECK(fractal_octave_limit(10, 2) == 0);
}

TEST_CASE("noise: the mean of |noise| that turbulence is filtered to", "[procedural][noise]") {
  // 2 x 10^6 samples of each of four tables: the mean |n| lies within 3% of kPerlinMeanAbs3, and
  // a fully capped turbulence sum equals the mean of the uncapped one within 3%.
  std::mt19937 rng(77);
  for (uint32_t seed : {2u, 3u, 5u, 8u}) {
    const PerlinTable t = make_perlin_table(seed);
    double sum = 0, turbulence = 0;
    const int n = 2000000;
    const FractalParams params = fractal(FractalKind::Turbulence, 3);
    for (int i = 0; i < n; ++i) {
      const Vec3f p = random_vec3(rng, -128, 128);
      sum += std::fabs(perlin(t, p).value);
      if (i % 8 == 0) turbulence += fractal_noise(t, p, params).value;
    }
    INFO("seed " << seed);
    CHECK(sum / n == Approx(kPerlinMeanAbs3).epsilon(0.03));
    CHECK(turbulence / (n / 8) ==
          Approx(fractal_noise(t, {0.1f, 0.2f, 0.3f}, params, 0).value).epsilon(0.03));
  }
}
