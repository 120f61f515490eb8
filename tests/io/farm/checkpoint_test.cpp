// Tests for io/checkpoint: the resume state survives the disk byte for byte; any damaged byte,
// other settings, the old format, FIFOs, foreign and truncated files, and well-sealed files
// with impossible values are errors naming the file.
#include "io/farm/checkpoint.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include "io/files/error.h"
#include "support/fifo_test_util.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {

// A consistent state of a 4x2 window after 16 samples, half the pixels stopped early.
PathAccumulators sample_state() {
  PathAccumulators st;
  st.window = {2, 3, 6, 5};
  st.pixels.resize(8);
  for (size_t i = 0; i < st.pixels.size(); ++i) {
    st.pixels[i].active = i % 2;
    st.pixels[i].n = st.pixels[i].active ? 16 : uint32_t(4 + i);
    st.pixels[i].rgba[0] = 0.1 * double(i) + 1e-17;
    st.pixels[i].rgba[3] = 0.5 * st.pixels[i].n;
    st.pixels[i].sum_y = 0.25;
    st.pixels[i].sum_y2 = 1.0 / 3.0;
  }
  st.groups.assign(8 * 15, 0.25);
  for (const auto& p : st.pixels)  // the odd samples' sums: half the colour, a quarter of the coverage
    for (const double v : {p.rgba[0] / 2, 0.0, 0.0, p.rgba[3] / 2}) st.odd.push_back(v);
  st.reached = 16;
  st.passes = 5;
  return st;
}

RenderSettings settings(const std::string& fingerprint) {
  return RenderSettings{{{"camera", "Main"}, {"fingerprint", fingerprint}, {"width", "960"}}};
}

std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

std::string error_of(const std::filesystem::path& p, const RenderSettings& expected) {
  try {
    (void)read_checkpoint(p, expected);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("checkpoint: round trip, settings check and damaged files", "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint");
  const PathAccumulators st = sample_state();
  write_checkpoint(dir / "a.resume", st, settings("settings A"));
  const PathAccumulators back = read_checkpoint(dir / "a.resume", settings("settings A"));
  CHECK(back.window.x0 == 2);
  CHECK(back.window.y1 == 5);
  CHECK(back.reached == 16);
  CHECK(back.passes == 5);
  CHECK_FALSE(back.complete);
  REQUIRE(back.pixels.size() == 8);
  CHECK(std::memcmp(back.pixels.data(), st.pixels.data(), 8 * sizeof(PathAccumulators::Pixel)) == 0);
  CHECK(back.groups == st.groups);
  CHECK(back.odd == st.odd);

  REQUIRE_THROWS_WITH(
      read_checkpoint(dir / "a.resume", settings("settings B")),
      Contains("a.resume") && Contains("other settings") && Contains("settings A") && Contains("settings B"));
  std::filesystem::resize_file(dir / "a.resume", std::filesystem::file_size(dir / "a.resume") - 9);
  REQUIRE_THROWS_WITH(read_checkpoint(dir / "a.resume", settings("settings A")),
                      Contains("truncated or corrupt"));
  std::ofstream(dir / "junk.resume") << "hello, not a checkpoint at all";
  REQUIRE_THROWS_WITH(read_checkpoint(dir / "junk.resume", settings("settings A")),
                      Contains("not a Penumbra checkpoint"));
  REQUIRE_THROWS_AS(read_checkpoint(dir / "none.resume", settings("x")), InputError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: complete, empty-group and single-pixel states round trip bit-exactly",
          "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-exact");
  PathAccumulators st;
  st.window = {7, 0, 8, 1};
  st.pixels.resize(1);
  st.pixels[0] = {{0x1p-1074, 1e300, 0.1, 1.0}, 3.0, 9.0, 1, 0};
  st.reached = 1;
  st.passes = 1;
  st.complete = true;
  const RenderSettings s{{{"camera", "a=b\nwidth=1"}}};
  write_checkpoint(dir / "c.resume", st, s);
  const PathAccumulators back = read_checkpoint(dir / "c.resume", s);
  CHECK(back.complete);
  CHECK(back.groups.empty());
  REQUIRE(back.pixels.size() == 1);
  CHECK(std::memcmp(back.pixels.data(), st.pixels.data(), sizeof(PathAccumulators::Pixel)) == 0);
  // Writing what was read gives the same bytes.
  write_checkpoint(dir / "d.resume", back, s);
  CHECK(read_bytes(dir / "c.resume") == read_bytes(dir / "d.resume"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: one flipped byte anywhere is refused, outside the magic and sizes by the checksum",
          "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-flip");
  write_checkpoint(dir / "good.resume", sample_state(), settings("A"));
  const std::string good = read_bytes(dir / "good.resume");
  const size_t settings_begin = 72, settings_end = settings_begin + canonical_text(settings("A")).size();
  const size_t digest_begin = good.size() - 32;
  const auto is_size_field = [](size_t i) { return i >= 36 && i < 72; };  // pixel size and the four counts
  int checksum_errors = 0, regions[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < good.size(); ++i) {
    std::string bad = good;
    bad[i] = char(bad[i] ^ 0x10);
    write_bytes(dir / "bad.resume", bad);
    const std::string message = error_of(dir / "bad.resume", settings("A"));
    INFO("byte " << i << ": " << message);
    REQUIRE(message != "accepted");
    REQUIRE_THAT(message, Contains("bad.resume"));
    if (i < 8) {
      CHECK_THAT(message, Contains("not a Penumbra checkpoint"));
    } else if (is_size_field(i)) {
      CHECK_THAT(message, Contains("truncated or corrupt"));
    } else {
      CHECK_THAT(message, Contains("checksum"));
      ++checksum_errors;
      ++regions[i < settings_begin ? 0 : i < settings_end ? 1 : i < digest_begin ? 2 : 3];
    }
  }
  CHECK(checksum_errors == int(good.size()) - 8 - 36);
  CHECK(regions[0] == 28);  // header: window, reached, passes, complete
  CHECK(regions[1] > 0);    // settings
  CHECK(regions[2] == 8 * 56 + 8 * 15 * 8 + 8 * 4 * 8);
  CHECK(regions[3] == 32);
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: truncated, extended and absurdly sized files are refused before any allocation",
          "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-size");
  write_checkpoint(dir / "good.resume", sample_state(), settings("A"));
  const std::string good = read_bytes(dir / "good.resume");
  for (const size_t keep : {size_t(0), size_t(5), size_t(8), size_t(40), size_t(64), good.size() - 1}) {
    write_bytes(dir / "t.resume", good.substr(0, keep));
    INFO("kept " << keep << " bytes");
    CHECK_THAT(error_of(dir / "t.resume", settings("A")),
               Contains("t.resume") && (Contains("truncated") || Contains("not a Penumbra")));
  }
  write_bytes(dir / "t.resume", good + "x");
  CHECK_THAT(error_of(dir / "t.resume", settings("A")), Contains("truncated or corrupt"));
  // Counts near 2^64 (that would overflow a naive size sum) or 2^40 pixels.
  for (const uint64_t count : {~uint64_t(0), ~uint64_t(0) / 56 + 1, uint64_t(1) << 40}) {
    for (const size_t field : {size_t(40), size_t(48), size_t(56), size_t(64)}) {
      std::string bad = good;
      std::memcpy(&bad[field], &count, 8);
      write_bytes(dir / "h.resume", bad);
      INFO("count " << count << " at byte " << field);
      CHECK_THAT(error_of(dir / "h.resume", settings("A")), Contains("truncated or corrupt"));
    }
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: a FIFO, a directory and /dev/zero are refused without reading",
          "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-fifo");
  test::make_fifo(dir / "state.resume");
  const std::string message = test::message_without_blocking(
      [&] { (void)read_checkpoint(dir / "state.resume", settings("A")); }, dir / "state.resume");
  CHECK_THAT(message, Contains("state.resume") && Contains("FIFO"));
  CHECK_THAT(error_of(dir, settings("A")), Contains("directory"));
  CHECK_THAT(error_of("/dev/zero", settings("A")), Contains("/dev/zero") && Contains("character device"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: the old format without a checksum is refused with a clear message",
          "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-old");
  // PNMBRCK1: magic, a 56-byte header, the fingerprint text, raw pixels.
  std::string old = "PNMBRCK1" + std::string(56, '\0') + "settings A" + std::string(56, '\0');
  write_bytes(dir / "old.resume", old);
  CHECK_THAT(error_of(dir / "old.resume", settings("A")),
             Contains("old.resume") && Contains("old format") && Contains("delete it"));
  // PNMBRCK2: sealed, but without the odd-sample sums' count.
  write_bytes(dir / "old2.resume", "PNMBRCK2" + std::string(56, '\0'));
  CHECK_THAT(error_of(dir / "old2.resume", settings("A")),
             Contains("old2.resume") && Contains("PNMBRCK2") && Contains("delete it"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: other settings are refused listing each differing key with both values",
          "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-settings");
  RenderSettings stored{{{"camera", "Main"}, {"scene.sha256", "aaaa"}, {"spp.min", "4"}, {"width", "960"}}};
  write_checkpoint(dir / "s.resume", sample_state(), stored);
  RenderSettings now = stored;
  now.entries["width"] = "480";
  now.entries.erase("spp.min");
  now.entries["seed"] = "7";
  const std::string message = error_of(dir / "s.resume", now);
  CHECK_THAT(message, Contains("s.resume") && Contains("other settings"));
  CHECK_THAT(message, Contains("  width: stored '960', this render '480'"));
  CHECK_THAT(message, Contains("  spp.min: stored '4', this render (not set)"));
  CHECK_THAT(message, Contains("  seed: stored (not set), this render '7'"));
  CHECK_THAT(message, !Contains("camera") && !Contains("scene.sha256"));
  // A value holding a newline and '=' cannot pose as two entries.
  RenderSettings forged{{{"camera", "Main\nscene.sha256=aaaa"}, {"spp.min", "4"}, {"width", "960"}}};
  CHECK_THAT(error_of(dir / "s.resume", forged), Contains("other settings") && Contains("scene.sha256"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("checkpoint: well-sealed files with impossible values are refused", "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint-forged");
  constexpr double inf = std::numeric_limits<double>::infinity();
  const struct {
    const char* what;
    void (*forge)(PathAccumulators&);
    const char* says;
  } cases[] = {
      {"-inf red sum", [](PathAccumulators& s) { s.pixels[3].rgba[0] = -inf; }, "pixel 5,3"},
      {"+inf green sum", [](PathAccumulators& s) { s.pixels[0].rgba[1] = inf; }, "not finite"},
      {"NaN luminance", [](PathAccumulators& s) { s.pixels[2].sum_y2 = std::nan(""); }, "luminance"},
      {"negative colour", [](PathAccumulators& s) { s.pixels[5].rgba[2] = -1e-9; }, "colour sum"},
      {"coverage above samples", [](PathAccumulators& s) { s.pixels[1].rgba[3] = 17; }, "coverage"},
      {"NaN light group", [](PathAccumulators& s) { s.groups[40] = std::nan(""); }, "light-group"},
      {"samples above reached", [](PathAccumulators& s) { s.pixels[0].n = 17; }, "more than the 16 reached"},
      {"active with fewer samples", [](PathAccumulators& s) { s.pixels[1].n = 15; }, "still sampling"},
      {"active flag 2", [](PathAccumulators& s) { s.pixels[4].active = 2; }, "active flag"},
      {"reached far beyond the samples", [](PathAccumulators& s) { s.reached = 4096; }, "still sampling"},
      {"window too small", [](PathAccumulators& s) { s.window.x1 = 5; }, "the window holds 6 pixels"},
      {"empty window", [](PathAccumulators& s) { s.window = {}; }, "empty"},
      {"light groups of another size", [](PathAccumulators& s) { s.groups.resize(8 * 14); },
       "light-group sums for 8"},
      {"odd sums of another size", [](PathAccumulators& s) { s.odd.resize(8 * 3); }, "odd-sample sums for 8"},
      {"NaN odd sum", [](PathAccumulators& s) { s.odd[6] = std::nan(""); }, "odd-sample sum"},
      {"odd sum above the pixel's", [](PathAccumulators& s) { s.odd[4] = s.pixels[1].rgba[0] + 1; },
       "odd-sample sum"},
      {"odd coverage above the odd samples",
       [](PathAccumulators& s) {
         s.pixels[1].rgba[3] = 12;
         s.odd[7] = 10;
       },
       "odd-sample coverage"},
      {"negative passes", [](PathAccumulators& s) { s.passes = -1; }, "passes"},
      {"more passes than samples", [](PathAccumulators& s) { s.passes = 17; }, "passes"},
      {"samples without passes", [](PathAccumulators& s) { s.passes = 0; }, "without a completed pass"},
      {"complete without a pass",
       [](PathAccumulators& s) {
         s = PathAccumulators{};
         s.window = {0, 0, 1, 1};
         s.pixels.resize(1);
         s.complete = true;
       },
       "complete without a pass"},
      {"sums without samples",
       [](PathAccumulators& s) {
         s = PathAccumulators{};
         s.window = {0, 0, 1, 1};
         s.pixels.resize(1);
         s.pixels[0].rgba[0] = 1;
       },
       "sums without samples"},
  };
  for (const auto& c : cases) {
    PathAccumulators st = sample_state();
    c.forge(st);
    write_checkpoint(dir / "f.resume", st, settings("A"));
    INFO(c.what);
    CHECK_THAT(error_of(dir / "f.resume", settings("A")),
               Contains("f.resume") && Contains("inconsistent") && Contains(c.says));
  }
  std::filesystem::remove_all(dir);
}
