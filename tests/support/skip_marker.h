// The flag a skipped test case raises, read by the shared Catch2 main after the run.
#pragma once

namespace penumbra::test {

/// The exit code of a test run whose selected cases all passed but at least one skipped.
inline constexpr int kSkipExitCode = 77;

/// Set by skip(); true once any test case of this process has skipped.
inline bool& any_test_skipped() {
  static bool skipped = false;
  return skipped;
}

}  // namespace penumbra::test
