// Tests for io/file_checks: regular files pass with their size; directories, FIFOs, devices,
// missing and oversized files are InputErrors that say what the path is.
#include "io/file_checks.h"

#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <fstream>

#include "io/error.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {
std::string message_of(const std::filesystem::path& p, uint64_t max = 1 << 20) {
  try {
    check_input_file(p, "--thing", max);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("check_input_file: only bounded regular files", "[io][files][quick]") {
  const auto dir = test::temp_dir("file_checks");
  { std::ofstream(dir / "ten.bin") << "0123456789"; }
  CHECK(check_input_file(dir / "ten.bin", "x", 10) == 10);
  CHECK_THAT(message_of(dir / "ten.bin", 9),
             Contains("ten.bin: --thing: is 10 bytes, over the 9 bytes limit"));
  CHECK_THAT(message_of(dir / "missing"), Contains("--thing: file not found"));
  CHECK_THAT(message_of(dir), Contains("is a directory, not a regular file"));
  REQUIRE(::mkfifo((dir / "fifo").c_str(), 0600) == 0);
  CHECK_THAT(message_of(dir / "fifo"), Contains("is a FIFO, not a regular file"));
  CHECK_THAT(message_of("/dev/zero"), Contains("is a character device, not a regular file"));
  std::filesystem::create_symlink(dir / "ten.bin", dir / "link");
  CHECK(check_input_file(dir / "link", "x", 10) == 10);
  CHECK(describe_file_type(dir / "link", false) == "a symbolic link");
  CHECK(describe_file_type(dir / "nope") == "nothing (it does not exist)");
}

TEST_CASE("format_bytes: binary units", "[io][files][quick]") {
  CHECK(format_bytes(512) == "512 bytes");
  CHECK(format_bytes(1536) == "1.5 KiB");
  CHECK(format_bytes(3ull << 30) == "3.0 GiB");
  CHECK(format_bytes(uint64_t(2.2 * double(1ull << 30))) == "2.2 GiB");
}
