// Pixel filters: profiles, sampling tables and inverse-CDF sampling.
#include "renderer/film/filter.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

float default_filter_width(FilterType type) {
  switch (type) {
    case FilterType::Box:
      return 1;
    case FilterType::Tent:
      return 2;
    case FilterType::Gaussian:
      return 3;
    case FilterType::BlackmanHarris:
      return 1.5f;
  }
  return 1;
}

bool parse_filter_type(std::string_view name, FilterType& out) {
  for (FilterType t : {FilterType::Box, FilterType::Tent, FilterType::Gaussian, FilterType::BlackmanHarris})
    if (name == filter_name(t)) {
      out = t;
      return true;
    }
  return false;
}

const char* filter_name(FilterType type) {
  switch (type) {
    case FilterType::Box:
      return "box";
    case FilterType::Tent:
      return "tent";
    case FilterType::Gaussian:
      return "gaussian";
    case FilterType::BlackmanHarris:
      return "blackman-harris";
  }
  return "box";
}

float filter_profile(const PixelFilter& f, float x) {
  const float r = f.width / 2;
  if (!(std::fabs(x) <= r)) return 0;
  switch (f.type) {
    case FilterType::Box:
      return 1;
    case FilterType::Tent:
      return 1 - std::fabs(x) / r;
    case FilterType::Gaussian: {
      // pbrt-v4's Gaussian: shifted so it reaches zero at the radius.
      const float sigma = f.width / 6;
      const auto g = [&](float t) { return std::exp(-t * t / (2 * sigma * sigma)); };
      return std::max(0.0f, g(x) - g(r));
    }
    case FilterType::BlackmanHarris: {
      // 4-term Blackman-Harris window over [-r, r] (Harris 1978), as Cycles uses.
      const float t = 2 * kPi * (x + r) / f.width;
      return std::max(
          0.0f, 0.35875f - 0.48829f * std::cos(t) + 0.14128f * std::cos(2 * t) - 0.01168f * std::cos(3 * t));
    }
  }
  return 0;
}

PixelFilter make_filter(FilterType type, float width) {
  PixelFilter f;
  f.type = type;
  f.width = width;
  // Midpoint-rule CDF of the profile on kTableSize bins over [-r, r].
  const int n = PixelFilter::kTableSize;
  double acc = 0;
  std::array<double, PixelFilter::kTableSize + 1> c{};
  for (int i = 0; i < n; ++i) {
    const float x = (float(i) + 0.5f) / float(n) * width - width / 2;
    acc += double(filter_profile(f, x));
    c[size_t(i) + 1] = acc;
  }
  for (int i = 0; i <= n; ++i) f.cdf[size_t(i)] = acc > 0 ? float(c[size_t(i)] / acc) : float(i) / float(n);
  f.cdf[size_t(n)] = 1;
  for (int j = 0; j < PixelFilter::kGuideSize; ++j) {
    const float u = float(j) / float(PixelFilter::kGuideSize);
    const auto it = std::upper_bound(f.cdf.begin(), f.cdf.end(), u);
    f.guide[size_t(j)] = uint16_t(std::clamp(int(it - f.cdf.begin()) - 1, 0, n - 1));
  }
  return f;
}

namespace {
float sample_1d(const PixelFilter& f, float u) {
  const float r = f.width / 2;
  switch (f.type) {
    case FilterType::Box:
      return (u - 0.5f) * f.width;
    case FilterType::Tent:  // inverse CDF of the triangle on [-r, r]
      return u < 0.5f ? r * (std::sqrt(2 * u) - 1) : r * (1 - std::sqrt(2 * (1 - u)));
    default: {
      // Piecewise-linear CDF: find the bin (the last i with cdf[i] <= u, from the guide
      // table's bin onwards), then interpolate inside it.
      constexpr int n = PixelFilter::kTableSize, g = PixelFilter::kGuideSize;
      int i = 0;
      if (u >= 0 && u < 1) {
        i = f.guide[size_t(std::min(int(u * float(g)), g - 1))];
        while (i < n - 1 && f.cdf[size_t(i) + 1] <= u) ++i;
      } else {
        const auto it = std::upper_bound(f.cdf.begin(), f.cdf.end(), u);
        i = std::clamp(int(it - f.cdf.begin()) - 1, 0, n - 1);
      }
      const float c0 = f.cdf[size_t(i)], c1 = f.cdf[size_t(i) + 1];
      const float t = c1 > c0 ? (u - c0) / (c1 - c0) : 0.5f;
      return ((float(i) + t) / float(PixelFilter::kTableSize)) * f.width - r;
    }
  }
}
}  // namespace

Vec2f sample_filter(const PixelFilter& f, Vec2f u) {
  return {sample_1d(f, u.x), sample_1d(f, u.y)};
}

}  // namespace penumbra
