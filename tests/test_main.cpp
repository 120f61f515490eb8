// The one Catch2 main shared by every test executable. A run whose selected test cases all
// pass exits 0, or kSkipExitCode when one of them skipped (it could not run here: no corpus, a
// missing tool), so that ctest reports the run as skipped rather than passed; any failure
// exits with Catch2's failure count and ctest reports it failed.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "support/skip_marker.h"

int main(int argc, char* argv[]) {
  const int failures = Catch::Session().run(argc, argv);
  if (failures == 0 && penumbra::test::any_test_skipped()) return penumbra::test::kSkipExitCode;
  return failures;
}
