// Tests for renderer/filter: filter importance sampling draws offsets distributed as the
// filter profile (moments against quadrature), inside the support, monotone in u.
#include "renderer/film/filter.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

using namespace penumbra;

TEST_CASE("filter: sampled offsets follow each filter's profile", "[filter][quick]") {
  for (FilterType t : {FilterType::Box, FilterType::Tent, FilterType::Gaussian, FilterType::BlackmanHarris}) {
    const PixelFilter f = make_filter(t, default_filter_width(t));
    INFO(filter_name(t));
    // Reference moments of the normalised profile by the midpoint rule.
    const int q = 200000;
    double w = 0, m2 = 0, m4 = 0;
    for (int i = 0; i < q; ++i) {
      const double x = (i + 0.5) / q * f.width - f.width / 2;
      const double p = filter_profile(f, float(x));
      w += p;
      m2 += p * x * x;
      m4 += p * x * x * x * x;
    }
    m2 /= w;
    m4 /= w;
    // Stratified u: the sample moments converge fast.
    const int n = 100000;
    double s2 = 0, s4 = 0, s1 = 0;
    float prev = -1e9f;
    for (int i = 0; i < n; ++i) {
      const float u = (float(i) + 0.5f) / float(n);
      const Vec2f o = sample_filter(f, {u, u});
      REQUIRE(std::fabs(o.x) <= f.width / 2 + 1e-5f);
      REQUIRE(o.x >= prev);  // monotone: stratification survives
      prev = o.x;
      s1 += o.x;
      s2 += double(o.x) * o.x;
      s4 += double(o.x) * o.x * o.x * o.x;
    }
    CHECK(s1 / n == Approx(0).margin(1e-3));
    CHECK(s2 / n == Approx(m2).epsilon(0.01));
    CHECK(s4 / n == Approx(m4).epsilon(0.02));
  }
  // Closed forms: box of width 1 has variance 1/12, tent of radius 1 has 1/6.
  CHECK(filter_profile(make_filter(FilterType::Box, 1), 0.49f) == 1);
  CHECK(filter_profile(make_filter(FilterType::Tent, 2), 0.5f) == Approx(0.5));
  CHECK(filter_profile(make_filter(FilterType::Gaussian, 3), 1.5f) == Approx(0).margin(1e-7));
  CHECK(filter_profile(make_filter(FilterType::BlackmanHarris, 1.5f), 0.0f) == Approx(1).margin(1e-4));
}

TEST_CASE("filter: names parse and unknown names are refused", "[filter][quick]") {
  FilterType t = FilterType::Box;
  CHECK(parse_filter_type("blackman-harris", t));
  CHECK(t == FilterType::BlackmanHarris);
  CHECK(parse_filter_type("gaussian", t));
  CHECK(t == FilterType::Gaussian);
  CHECK_FALSE(parse_filter_type("mitchell", t));
}

TEST_CASE("filter: the guide table finds the bin a full search of the CDF finds", "[filter][quick]") {
  for (FilterType t : {FilterType::Gaussian, FilterType::BlackmanHarris}) {
    const PixelFilter f = make_filter(t, default_filter_width(t));
    INFO(filter_name(t));
    // The offset of the bin the whole-table search picks, interpolated as sample_filter does.
    const auto searched = [&](float u) {
      constexpr int n = PixelFilter::kTableSize;
      const auto it = std::upper_bound(f.cdf.begin(), f.cdf.end(), u);
      const int i = std::clamp(int(it - f.cdf.begin()) - 1, 0, n - 1);
      const float c0 = f.cdf[size_t(i)], c1 = f.cdf[size_t(i) + 1];
      const float tt = c1 > c0 ? (u - c0) / (c1 - c0) : 0.5f;
      return ((float(i) + tt) / float(n)) * f.width - f.width / 2;
    };
    std::vector<float> us;
    for (int i = 0; i < (1 << 16); ++i) us.push_back(float(i) / float(1 << 16));
    for (float c : f.cdf) us.insert(us.end(), {c, std::nextafter(c, 0.0f), std::nextafter(c, 1.0f)});
    us.push_back(0x1.fffffep-1f);
    for (float u : us) {
      if (!(u >= 0 && u < 1)) continue;
      INFO(u);
      REQUIRE(sample_filter(f, {u, u}).x == searched(u));
    }
  }
}
