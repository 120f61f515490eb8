// Tests for io/image/deep_exr and the deep side of io/image/exr_merge: a deep image written and
// read back sample for sample (window offsets, empty pixels, the background at +inf), flattened
// by OpenImageIO to the pixels its samples composite to, and deep stripes merged into the file a
// whole-frame write gives, byte for byte; flat and deep parts refused together.
#include "io/image/deep_exr.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>
#include <iterator>

#include "io/farm/render_settings.h"
#include "io/files/error.h"
#include "io/image/exr_merge.h"
#include "io/image/exr_parts.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {

/// A deep image of the whole w x h frame: pixel (x, y) holds (x + y) % 3 samples, front to back,
/// the last one of a pixel with 2 the background (alpha 0 at +inf).
DeepImage pattern(int w, int h) {
  DeepImage img;
  img.width = img.full_width = w;
  img.height = img.full_height = h;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint32_t n = uint32_t((x + y) % 3);
      img.counts.push_back(n);
      for (uint32_t k = 0; k < n; ++k) {
        DeepSample s;
        s.r = 0.1f * float(x);
        s.g = 0.05f * float(y);
        s.b = 0.5f;
        s.a = k == 0 ? 0.25f + 0.5f * float(x % 2) : 0.0f;
        s.z = s.zback = k == 0 ? 1.0f + 0.1f * float(y) : kInfinity;
        s.id = k == 0 ? float(1 + x % 4) : 0.0f;
        s.nz = 1;
        s.albedo_r = 0.3f;
        img.samples.push_back(s);
      }
    }
  return img;
}

/// Rows [y0, y1) of a whole-frame deep image, as a stripe of it.
DeepImage stripe(const DeepImage& full, int y0, int y1) {
  DeepImage s = full;
  s.origin_y = y0;
  s.height = y1 - y0;
  s.counts.assign(full.counts.begin() + y0 * full.width, full.counts.begin() + y1 * full.width);
  size_t first = 0;
  for (int i = 0; i < y0 * full.width; ++i) first += full.counts[size_t(i)];
  size_t n = 0;
  for (uint32_t c : s.counts) n += c;
  s.samples.assign(full.samples.begin() + ptrdiff_t(first), full.samples.begin() + ptrdiff_t(first + n));
  return s;
}

std::string bytes_of(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

ExrOptions identity() {
  ExrOptions o;
  o.metadata = {{kSceneHashAttribute, "5ca1ab1e"},
                {kSettingsAttribute, canonical_text(RenderSettings{{{"spp", "4"}}})},
                {"DateTime", ""}};
  return o;
}

}  // namespace

TEST_CASE("deep exr: samples read back exactly, and OpenImageIO flattens them as they composite",
          "[deep_exr]") {
  const auto dir = test::temp_dir("deep-exr");
  const DeepImage img = pattern(7, 5);
  write_deep_exr(img, dir / "d.exr", identity());
  const DeepImage back = read_deep_exr(dir / "d.exr", uint64_t(1) << 30);
  CHECK(back.width == 7);
  CHECK(back.height == 5);
  CHECK(back.counts == img.counts);
  REQUIRE(back.samples.size() == img.samples.size());
  CHECK(std::memcmp(back.samples.data(), img.samples.data(), img.samples.size() * sizeof(DeepSample)) == 0);

  OIIO::ImageBuf deep((dir / "d.exr").string());
  REQUIRE(deep.read());
  REQUIRE(deep.deep());
  const OIIO::ImageBuf flat = OIIO::ImageBufAlgo::flatten(deep);
  REQUIRE_FALSE(flat.has_error());
  size_t first = 0;
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      double rgba[4] = {0, 0, 0, 0};
      for (uint32_t k = 0; k < img.counts[size_t(y * 7 + x)]; ++k) {
        const DeepSample& s = img.samples[first + k];
        const double t = 1 - rgba[3];
        rgba[0] += t * s.r;
        rgba[1] += t * s.g;
        rgba[2] += t * s.b;
        rgba[3] += t * s.a;
      }
      first += img.counts[size_t(y * 7 + x)];
      for (int c = 0; c < 4; ++c) CHECK(flat.getchannel(x, y, 0, c) == Approx(rgba[c]).margin(1e-6));
    }
  CHECK_THROWS_WITH(read_deep_exr(dir / "d.exr", 100), Contains("over the"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("deep exr: stripes merge into the whole frame's file byte for byte", "[deep_exr]") {
  const auto dir = test::temp_dir("deep-merge");
  const DeepImage img = pattern(9, 8);
  write_deep_exr(img, dir / "whole.exr", identity());
  const std::vector<std::filesystem::path> parts = {dir / "p0.exr", dir / "p1.exr", dir / "p2.exr"};
  write_deep_exr(stripe(img, 0, 3), parts[0], identity());
  write_deep_exr(stripe(img, 3, 5), parts[1], identity());
  write_deep_exr(stripe(img, 5, 8), parts[2], identity());
  merge_exr_parts({parts[2], parts[0], parts[1]}, dir / "merged.exr");
  CHECK(bytes_of(dir / "merged.exr") == bytes_of(dir / "whole.exr"));
  // A gap, and a flat part among deep ones, are refused naming the file.
  CHECK_THROWS_WITH(merge_exr_parts({parts[0], parts[2]}, dir / "gap.exr"), Contains("do not cover"));
  Film f = make_film(9, 8);
  ExrOptions flat = identity();
  write_exr(f, dir / "flat.exr", flat);
  CHECK_THROWS_WITH(merge_exr_parts({parts[0], dir / "flat.exr"}, dir / "mixed.exr"),
                    Contains("flat.exr") && Contains("not a deep image"));
  CHECK_THROWS_WITH(merge_exr_parts({dir / "flat.exr", parts[0]}, dir / "mixed.exr"),
                    Contains("p0.exr") && Contains("is a deep image"));
  CHECK_FALSE(std::filesystem::exists(dir / "mixed.exr"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("deep exr: chunks that declare more than the file or the budget are refused unread", "[deep_exr]") {
  const auto dir = test::temp_dir("deep-hostile");
  write_deep_exr(pattern(6, 4), dir / "d.exr", identity());
  const uint64_t size = std::filesystem::file_size(dir / "d.exr");
  const exr_parts::ExrHeaderInfo info = exr_parts::check_exr_header(dir / "d.exr", size, true);
  REQUIRE(info.chunk_count == 4);  // one chunk a scanline (zips)
  std::string bytes = bytes_of(dir / "d.exr");
  uint64_t first = 0;
  std::memcpy(&first, &bytes[info.end], 8);
  // The first chunk's unpacked sample size (y, packed table size, packed data size, unpacked size).
  const auto patched = [&](size_t field, uint64_t value) {
    std::string b = bytes;
    std::memcpy(&b[first + 4 + 8 * field], &value, 8);
    std::ofstream(dir / "h.exr", std::ios::binary | std::ios::trunc)
        .write(b.data(), std::streamsize(b.size()));
    return dir / "h.exr";
  };
  CHECK_THROWS_WITH(read_deep_exr(patched(2, uint64_t(1) << 40), uint64_t(1) << 30),
                    Contains("h.exr") && Contains("limit"));
  CHECK_THROWS_WITH(read_deep_exr(patched(1, uint64_t(1) << 40), uint64_t(1) << 30),
                    Contains("claims more bytes than the file holds"));
  CHECK_THROWS_WITH(merge_exr_parts({patched(2, uint64_t(1) << 40)}, dir / "m.exr"), Contains("limit"));
  // A chunk table entry pointing past the end.
  std::string b = bytes;
  const uint64_t past = size + 100;
  std::memcpy(&b[info.end], &past, 8);
  std::ofstream(dir / "t.exr", std::ios::binary | std::ios::trunc).write(b.data(), std::streamsize(b.size()));
  CHECK_THROWS_WITH(read_deep_exr(dir / "t.exr", uint64_t(1) << 30), Contains("outside the file"));
  std::filesystem::remove_all(dir);
}
