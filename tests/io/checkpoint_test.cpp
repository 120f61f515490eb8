// Tests for io/checkpoint: the resume state survives the disk byte for byte; other settings,
// foreign and truncated files are errors naming the file.
#include "io/checkpoint.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "io/error.h"
#include "test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

TEST_CASE("checkpoint: round trip, settings check and damaged files", "[io][checkpoint][quick]") {
  const auto dir = test::temp_dir("checkpoint");
  PathAccumulators st;
  st.window = {2, 3, 6, 5};
  st.pixels.resize(8);
  for (size_t i = 0; i < st.pixels.size(); ++i) {
    st.pixels[i].rgba[0] = 0.1 * double(i) + 1e-17;
    st.pixels[i].sum_y2 = 1.0 / 3.0;
    st.pixels[i].n = uint32_t(i + 16);
    st.pixels[i].active = i % 2;
  }
  st.groups.assign(8 * 15, 0.25);
  st.reached = 16;
  st.passes = 5;
  write_checkpoint(dir / "a.resume", st, "settings A");
  const PathAccumulators back = read_checkpoint(dir / "a.resume", "settings A");
  CHECK(back.window.x0 == 2);
  CHECK(back.window.y1 == 5);
  CHECK(back.reached == 16);
  CHECK(back.passes == 5);
  CHECK_FALSE(back.complete);
  REQUIRE(back.pixels.size() == 8);
  CHECK(std::memcmp(back.pixels.data(), st.pixels.data(), 8 * sizeof(PathAccumulators::Pixel)) == 0);
  CHECK(back.groups == st.groups);

  REQUIRE_THROWS_WITH(read_checkpoint(dir / "a.resume", "settings B"),
                      Contains("a.resume") && Contains("other settings") && Contains("settings A") && Contains("settings B"));
  std::filesystem::resize_file(dir / "a.resume", std::filesystem::file_size(dir / "a.resume") - 9);
  REQUIRE_THROWS_WITH(read_checkpoint(dir / "a.resume", "settings A"), Contains("truncated or corrupt"));
  std::ofstream(dir / "junk.resume") << "hello, not a checkpoint at all";
  REQUIRE_THROWS_WITH(read_checkpoint(dir / "junk.resume", "settings A"), Contains("not a Penumbra checkpoint"));
  REQUIRE_THROWS_AS(read_checkpoint(dir / "none.resume", "x"), InputError);
  std::filesystem::remove_all(dir);
}
