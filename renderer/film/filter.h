// Pixel reconstruction filters applied by filter importance sampling (Ernst et al., "Filter
// Importance Sampling", IEEE RT 2006): each camera sample is placed at an offset drawn from
// the (separable, non-negative) filter, and the pixel is the plain mean of its samples, so
// samples stay independent and the image stays unbiased for any sample count.
#pragma once

#include <array>
#include <string_view>

#include "renderer/core/math.h"

namespace penumbra {

enum class FilterType : uint8_t { Box, Tent, Gaussian, BlackmanHarris };

/// A filter of total `width` pixels (support [-width/2, width/2] on each axis).
/// Defaults (default_filter_width): box 1, tent 2, Gaussian 3 (sigma = width / 6),
/// Blackman-Harris 1.5 (Cycles' default pixel filter).
struct PixelFilter {
  FilterType type = FilterType::Box;
  float width = 1;
  static constexpr int kTableSize = 256;
  std::array<float, kTableSize + 1> cdf{};  ///< tabulated 1D CDF over [-r, r] (Gaussian, B-H)
  /// Guide table (the cutpoint method, Chen & Asau 1974): guide[j] is the last
  /// bin i with cdf[i] <= j / kGuideSize, so sampling scans forward from there instead of
  /// searching the whole CDF. Filled by make_filter.
  static constexpr int kGuideSize = 1024;
  std::array<uint16_t, kGuideSize> guide{};
};

float default_filter_width(FilterType type);
/// Parses "box", "tent", "gaussian", "blackman-harris"; false if unknown.
bool parse_filter_type(std::string_view name, FilterType& out);
const char* filter_name(FilterType type);

/// Builds the filter and its sampling table. Requires width > 0 and finite.
PixelFilter make_filter(FilterType type, float width);

/// The 1D filter profile at offset x (unnormalised; zero outside the support).
float filter_profile(const PixelFilter& f, float x);

/// An offset from the pixel centre distributed as profile(x) profile(y), from u in [0,1)^2.
/// Monotone in each coordinate of u, so stratified u gives stratified offsets.
/// Never allocates.
Vec2f sample_filter(const PixelFilter& f, Vec2f u);

}  // namespace penumbra
