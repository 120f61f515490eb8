// Tests for io/atomic_file: how each kind of target is classified and written, collisions
// between outputs (same path, relative path, symlink, hard link) and with inputs, the recorded
// SHA-256, kept permissions, and that a failed write changes nothing and leaves no temporary.
#include "io/files/atomic_file.h"

#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <fstream>
#include <sstream>

#include "io/files/error.h"
#include "io/files/hash.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {
std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
void write_text(const fs::path& temp, const std::string& text) {
  write_file_checked(temp, text.data(), text.size());
}
size_t entries(const fs::path& dir) {
  return size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}
}  // namespace

TEST_CASE("resolve_output: each kind of target", "[io][atomic][quick]") {
  const auto dir = test::temp_dir("atomic_resolve");
  CHECK(resolve_output(dir / "new.exr").kind == OutputKind::Replace);
  write_text(dir / "old.exr", "x");
  const OutputTarget regular = resolve_output(dir / "old.exr");
  CHECK(regular.kind == OutputKind::Replace);
  CHECK(regular.inode != 0);
  fs::create_symlink("old.exr", dir / "a.exr");
  fs::create_symlink(dir / "a.exr", dir / "b.exr");
  const OutputTarget chained = resolve_output(dir / "b.exr");
  CHECK(chained.kind == OutputKind::Replace);
  CHECK(chained.target == dir / "old.exr");
  CHECK(chained.inode == regular.inode);
  fs::create_symlink(dir / "loop2", dir / "loop1");
  fs::create_symlink(dir / "loop1", dir / "loop2");
  CHECK_THROWS_WITH(resolve_output(dir / "loop1", "-o"), Contains("too many levels of symbolic links"));
  CHECK(resolve_output("/dev/null").kind == OutputKind::Stream);
  const OutputTarget out = resolve_output("/dev/stdout");
  CHECK(out.kind == OutputKind::Stream);
  CHECK(out.fd == 1);
  REQUIRE(::mkfifo((dir / "fifo").c_str(), 0600) == 0);
  CHECK(resolve_output(dir / "fifo").kind == OutputKind::Stream);
  CHECK_THROWS_WITH(resolve_output(dir, "--png"), Contains("--png " + dir.string() + ": is a directory"));
  CHECK_THROWS_WITH(resolve_output(dir / "none" / "x.exr", "-o"), Contains("does not exist"));
  CHECK_THROWS_AS(resolve_output("/dev/fd/987"), InputError);
}

TEST_CASE("check_distinct_files: one file under any name is refused", "[io][atomic][quick]") {
  const auto dir = test::temp_dir("atomic_distinct");
  write_text(dir / "a.exr", "a");
  CHECK_NOTHROW(check_distinct_files({{"-o", dir / "a.exr"}, {"--png", dir / "a.png"}}));
  CHECK_THROWS_WITH(check_distinct_files({{"-o", dir / "a.exr"}, {"--stats-json", dir / "." / "a.exr"}}),
                    Contains("are the same file"));
  fs::create_hard_link(dir / "a.exr", dir / "hard.json");
  CHECK_THROWS_WITH(check_distinct_files({{"-o", dir / "a.exr"}, {"--stats-json", dir / "hard.json"}}),
                    Contains("-o " + (dir / "a.exr").string() + " and --stats-json"));
  fs::create_symlink(dir / "new.exr", dir / "dangling.json");  // neither exists yet
  CHECK_THROWS_AS(check_distinct_files({{"-o", dir / "new.exr"}, {"--stats-json", dir / "dangling.json"}}),
                  InputError);
  CHECK_THROWS_WITH(
      check_distinct_files({{"--stats-json", dir / "a.exr"}}, {{"the scene file", dir / "hard.json"}}),
      Contains("would overwrite the scene file"));
}

TEST_CASE("write_atomically: replaces, streams, records and keeps the old file on failure",
          "[io][atomic][quick]") {
  const auto dir = test::temp_dir("atomic_write");
  const fs::path dest = dir / "out.json";
  write_text(dest, "previous");
  ::chmod(dest.c_str(), 0640);
  std::string sha;
  write_atomically(
      dest, [](const fs::path& temp) { write_text(temp, "new contents"); }, &sha);
  CHECK(read_text(dest) == "new contents");
  CHECK(sha == sha256_hex("new contents"));
  CHECK((fs::status(dest).permissions() & fs::perms::all) ==
        (fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read));
  // Through a symlink: the target is replaced, the link stays a link.
  fs::create_symlink("out.json", dir / "link.json");
  write_atomically(dir / "link.json", [](const fs::path& temp) { write_text(temp, "via link"); });
  CHECK(fs::is_symlink(dir / "link.json"));
  CHECK(read_text(dest) == "via link");
  // A failing writer changes nothing and leaves no temporary.
  CHECK_THROWS(write_atomically(dest, [](const fs::path& temp) {
    write_text(temp, "half");
    throw std::runtime_error("interrupted");
  }));
  CHECK(read_text(dest) == "via link");
  CHECK(entries(dir) == 2);
  // Streams: /dev/null takes the bytes and stays a device; /dev/full reports its errno.
  write_atomically(
      "/dev/null", [](const fs::path& temp) { write_text(temp, "discarded"); }, &sha);
  CHECK(sha == sha256_hex("discarded"));
  CHECK(fs::is_character_file("/dev/null"));
  CHECK_THROWS_WITH(write_atomically("/dev/full", [](const fs::path& temp) { write_text(temp, "x"); }),
                    Contains("/dev/full: write failed: No space left on device"));
  CHECK(fs::is_character_file("/dev/full"));
  // A directory target is refused before the writer runs.
  bool ran = false;
  CHECK_THROWS_AS(write_atomically(dir, [&](const fs::path&) { ran = true; }), InputError);
  CHECK_FALSE(ran);
}
