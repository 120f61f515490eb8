// Test helpers: locating the shared corpus and the project's scenes, temporary folders.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <string>

#include "support/skip_marker.h"

namespace penumbra::test {

/// ../shared/corpus beside the checkout, or $PENUMBRA_CORPUS; nullopt if neither exists.
inline std::optional<std::filesystem::path> corpus_dir() {
  const char* env = std::getenv("PENUMBRA_CORPUS");
  std::filesystem::path p =
      env && *env ? std::filesystem::path(env) : std::filesystem::path(PENUMBRA_CORPUS_DEFAULT);
  if (std::filesystem::is_directory(p / "valid")) return p;
  return std::nullopt;
}

/// Prints why a test cannot run here and marks the run: an executable whose selected test
/// cases all pass but one of them skipped exits with kSkipExitCode, which ctest reports as
/// skipped (see tests/CMakeLists.txt and tests/test_main.cpp).
inline void skip(const std::string& why) {
  std::cout << "PENUMBRA_SKIP: " << why << std::endl;
  any_test_skipped() = true;
}

inline std::filesystem::path source_dir() {
  return PENUMBRA_SOURCE_DIR;
}

/// A fresh, empty temporary folder unique to this process and name.
inline std::filesystem::path temp_dir(const std::string& name) {
  auto p =
      std::filesystem::temp_directory_path() / ("penumbra-test-" + std::to_string(::getpid()) + "-" + name);
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

}  // namespace penumbra::test
