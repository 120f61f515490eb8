// Wall-clock timing for the benchmark: seconds since a time point, the median of samples, and
// the median time of repeated calls after a warm-up.
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

namespace penumbra::bench {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// The median of `v` (0 for none).
inline double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

/// The median seconds of `repeats` calls of fn after one warm-up call.
template <typename Fn>
double median_seconds(int repeats, Fn&& fn) {
  fn();
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    fn();
    t.push_back(seconds_since(t0));
  }
  return median(t);
}

}  // namespace penumbra::bench
