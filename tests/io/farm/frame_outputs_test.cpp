// Tests for io/frame_outputs: the --frames grammar and its limits, `#` substitution with
// padding and signs, and the EXR completeness check on a whole, a truncated and a foreign file.
#include "io/farm/frame_outputs.h"

#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <fstream>
#include <vector>

#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

TEST_CASE("parse_frame_range accepts N, A-B and A-B:STEP", "[io][quick]") {
  FrameRange r = parse_frame_range("7");
  CHECK((r.first == 7 && r.last == 7 && r.step == 1 && r.count() == 1));
  r = parse_frame_range("1-240");
  CHECK((r.first == 1 && r.last == 240 && r.step == 1 && r.count() == 240));
  r = parse_frame_range("1-10:3");  // 1, 4, 7, 10
  CHECK((r.step == 3 && r.count() == 4));
  r = parse_frame_range("1-9:3");  // 1, 4, 7
  CHECK(r.count() == 3);
  r = parse_frame_range("-5--1");
  CHECK((r.first == -5 && r.last == -1 && r.count() == 5));
  r = parse_frame_range("-2-2");
  CHECK((r.first == -2 && r.last == 2));
}

TEST_CASE("parse_frame_range rejects malformed, empty and oversized ranges", "[io][quick]") {
  CHECK_THROWS_WITH(parse_frame_range("5-2"), Contains("empty"));
  CHECK_THROWS_WITH(parse_frame_range("1-3:0"), Contains("step"));
  CHECK_THROWS_WITH(parse_frame_range("1-3:-1"), Contains("step"));
  CHECK_THROWS_WITH(parse_frame_range("1-200000"), Contains("more than 100000"));
  CHECK_THROWS_WITH(parse_frame_range("1-99999999999999999999"), Contains("within"));
  CHECK_THROWS_WITH(parse_frame_range("0-2000000000000"), Contains("within"));
  for (const char* bad : {"", "x", "1-", "-", "1-3:", "1:3", "1-3:2x", "+1", "1.5", "1 -3", "1-3-5"})
    CHECK_THROWS_WITH(parse_frame_range(bad), Contains("--frames"));
}

TEST_CASE("substitute_frame pads every run of # to its length", "[io][quick]") {
  CHECK(substitute_frame("shots/sh010.####.exr", 12) == "shots/sh010.0012.exr");
  CHECK(substitute_frame("f.#.exr", 12) == "f.12.exr");  // longer numbers are written in full
  CHECK(substitute_frame("f.####.exr", -1) == "f.-001.exr");
  CHECK(substitute_frame("f.##.exr", -12) == "f.-12.exr");
  CHECK(substitute_frame("#/f.###.exr", 5) == "5/f.005.exr");
  CHECK(substitute_frame("plain.exr", 5) == "plain.exr");
  CHECK(has_frame_pattern("a.#.exr"));
  CHECK_FALSE(has_frame_pattern("a.exr"));
}

TEST_CASE("is_complete_exr reads the pixels of every part", "[io][quick]") {
  const auto dir = test::temp_dir("frame_outputs");
  const auto path = dir / "whole.exr";
  {
    OIIO::ImageSpec spec(64, 64, 4, OIIO::TypeDesc::HALF);
    spec.attribute("compression", "none");
    auto out = OIIO::ImageOutput::create(path.string());
    REQUIRE(out);
    REQUIRE(out->open(path.string(), spec));
    std::vector<float> pixels(64 * 64 * 4, 0.5f);
    REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
    REQUIRE(out->close());
  }
  std::string problem;
  CHECK(is_complete_exr(path, problem));
  CHECK_FALSE(is_complete_exr(dir / "missing.exr", problem));
  CHECK_THAT(problem, Contains("does not exist"));
  // The same file cut to half its bytes: the header opens, the pixels do not.
  const auto cut = dir / "cut.exr";
  std::filesystem::copy_file(path, cut, std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(cut, std::filesystem::file_size(path) / 2);
  CHECK_FALSE(is_complete_exr(cut, problem));
  const auto text = dir / "text.exr";
  std::ofstream(text) << "not an image\n";
  CHECK_FALSE(is_complete_exr(text, problem));
  CHECK_FALSE(is_complete_exr(dir, problem));
}
