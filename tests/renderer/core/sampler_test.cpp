// Tests for renderer/sampler: the Sobol generator's known values, the (0, k, 2)-net property
// of every 2D request of a pixel's first 2^k samples, determinism and decorrelation.
#include "renderer/core/sampler.h"

#include <catch2/catch.hpp>
#include <set>

using namespace penumbra;

TEST_CASE("sampler: Sobol dimensions 0 and 1 have their textbook values", "[sampler][quick]") {
  // Dimension 0 is the van der Corput sequence; dimension 1 has direction numbers
  // 1/2, 3/4, 5/8, 15/16, ... (v_k = v_{k-1} ^ v_{k-1} >> 1).
  const double d0[] = {0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
  const double d1[] = {0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (uint32_t i = 0; i < 8; ++i) {
    CHECK(sobol_dim0(i) * 0x1p-32 == d0[i]);
    CHECK(sobol_dim1(i) * 0x1p-32 == d1[i]);
  }
  CHECK(reverse_bits(1) == 0x80000000u);
  CHECK(reverse_bits(0x12345678u) == 0x1e6a2c48u);
}

TEST_CASE("sampler: Owen scrambling keeps every elementary interval stratified", "[sampler][quick]") {
  // For n = 2^k samples of one pixel, every 2D request must put exactly one point in each
  // elementary interval of area 1/n: (2^a x 2^(k-a)) grids for a = 0..k.
  for (uint32_t k : {2u, 4u, 6u}) {
    const uint32_t n = 1u << k;
    for (uint32_t pixel : {0u, 7u, 123u}) {
      std::vector<std::vector<Vec2f>> requests(5);
      std::vector<float> one_d;
      for (uint32_t s = 0; s < n; ++s) {
        SampleStream st = make_sample_stream(SamplerType::Sobol, pixel, pixel * 3, s, 42);
        for (auto& r : requests) r.push_back(st.get2d());
        one_d.push_back(st.get1d());
      }
      for (const auto& pts : requests) {
        for (uint32_t a = 0; a <= k; ++a) {
          const uint32_t cols = 1u << a, rows = n / cols;
          std::set<uint32_t> cells;
          for (const Vec2f& p : pts) {
            REQUIRE(p.x >= 0);
            REQUIRE(p.x < 1);
            REQUIRE(p.y >= 0);
            REQUIRE(p.y < 1);
            cells.insert(uint32_t(p.x * float(cols)) * rows + uint32_t(p.y * float(rows)));
          }
          CHECK(cells.size() == n);
        }
      }
      std::set<uint32_t> strata;
      for (float u : one_d) strata.insert(uint32_t(u * float(n)));
      CHECK(strata.size() == n);
    }
  }
}

TEST_CASE("sampler: streams are deterministic and decorrelated across pixels and seeds", "[sampler][quick]") {
  for (SamplerType t : {SamplerType::Sobol, SamplerType::Independent}) {
    SampleStream a = make_sample_stream(t, 5, 9, 3, 0), b = make_sample_stream(t, 5, 9, 3, 0);
    SampleStream other_pixel = make_sample_stream(t, 6, 9, 3, 0),
                 other_seed = make_sample_stream(t, 5, 9, 3, 1);
    int same_pixel = 0, same_seed = 0;
    for (int d = 0; d < 16; ++d) {
      const float x = a.get1d();
      CHECK(x == b.get1d());
      same_pixel += x == other_pixel.get1d();
      same_seed += x == other_seed.get1d();
    }
    CHECK(same_pixel == 0);
    CHECK(same_seed == 0);
  }
  // Over many pixels the mean and variance of a dimension are those of U(0, 1).
  double sum = 0, sum2 = 0;
  const int n = 64 * 64;
  for (int p = 0; p < n; ++p) {
    SampleStream s = make_sample_stream(SamplerType::Sobol, uint32_t(p % 64), uint32_t(p / 64), 0, 0);
    s.get2d();
    const double u = s.get1d();
    sum += u;
    sum2 += u * u;
  }
  CHECK(sum / n == Approx(0.5).margin(0.02));
  CHECK(sum2 / n - (sum / n) * (sum / n) == Approx(1.0 / 12).margin(0.01));
}

TEST_CASE("sampler: the byte tables of Sobol dimension 1 equal its bit loop", "[sampler][quick]") {
  Rng rng = make_pixel_rng(3, 5, 7, 11);
  for (uint32_t i = 0; i < 70000; ++i) {
    const uint32_t x = i < 65536 ? i : rng.next_u32();
    INFO(x);
    REQUIRE(sobol_dim1(x) == sobol_dim1_loop(x));
  }
  REQUIRE(sobol_dim1(0xffffffffu) == sobol_dim1_loop(0xffffffffu));
}
