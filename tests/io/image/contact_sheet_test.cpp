// Tests for io/contact_sheet: the grid's shape, every cell's pixels where the layout puts them
// (read back through OpenImageIO), and refusals of mismatched images and oversized sheets.
#include "io/image/contact_sheet.h"

#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>

#include "io/files/error.h"
#include "support/test_util.h"

using namespace penumbra;
namespace fs = std::filesystem;

namespace {

/// A w x h RGB PNG whose pixel (x, y) is (id, x, y) (all below 256).
fs::path write_cell(const fs::path& dir, int id, int w, int h, int channels = 3) {
  const fs::path p = dir / ("cell" + std::to_string(id) + ".png");
  std::vector<uint8_t> px(size_t(w) * size_t(h) * size_t(channels));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* q = &px[(size_t(y) * size_t(w) + size_t(x)) * size_t(channels)];
      q[0] = uint8_t(id);
      if (channels > 1) q[1] = uint8_t(x);
      if (channels > 2) q[2] = uint8_t(y);
      if (channels > 3) q[3] = 255;
    }
  auto out = OIIO::ImageOutput::create(p.string());
  REQUIRE(out);
  REQUIRE(out->open(p.string(), OIIO::ImageSpec(w, h, channels, OIIO::TypeDesc::UINT8)));
  REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
  REQUIRE(out->close());
  return p;
}

}  // namespace

TEST_CASE("contact sheet layout: the fewest columns that keep the sheet no taller than wide",
          "[io][contact_sheet]") {
  // 8 square cells: 3 columns make 3 rows (square), 2 would make 4 rows (taller).
  ContactSheetLayout l = contact_sheet_layout(8, 0, 100, 100);
  CHECK(l.columns == 3);
  CHECK(l.rows == 3);
  // 8 cells of 16:9: 2 columns x 4 rows is 32 x 36 (taller); 3 x 3 is 48 x 27.
  l = contact_sheet_layout(8, 0, 160, 90);
  CHECK(l.columns == 3);
  CHECK(l.rows == 3);
  // 36 portrait cells of 1:2: 8 columns make 5 rows (500 tall, 400 wide); 9 make 4 (400 by 450).
  l = contact_sheet_layout(36, 0, 50, 100);
  CHECK(l.columns == 9);
  CHECK(l.rows == 4);
  // Given columns, capped by the count; one image is one cell.
  l = contact_sheet_layout(8, 4, 160, 90);
  CHECK((l.columns == 4 && l.rows == 2));
  CHECK(l.width() == 4 * (160 + kContactSheetGap) + kContactSheetGap);
  CHECK(l.height() == 2 * (90 + kContactSheetGap) + kContactSheetGap);
  l = contact_sheet_layout(3, 10, 160, 90);
  CHECK((l.columns == 3 && l.rows == 1));
  l = contact_sheet_layout(1, 0, 160, 90);
  CHECK((l.columns == 1 && l.rows == 1));
}

TEST_CASE("contact sheet: every cell's pixels where the layout puts them, the rest black",
          "[io][contact_sheet]") {
  const fs::path dir = test::temp_dir("contact-sheet");
  const int w = 13, h = 7;
  std::vector<fs::path> cells;
  for (int k = 0; k < 5; ++k) cells.push_back(write_cell(dir, k + 1, w, h));
  const fs::path sheet = dir / "sheet.png";
  write_contact_sheet(cells, 2, sheet, uint64_t(1) << 30);
  auto in = OIIO::ImageInput::open(sheet.string());
  REQUIRE(in);
  const OIIO::ImageSpec spec = in->spec();
  const ContactSheetLayout l = contact_sheet_layout(5, 2, w, h);
  REQUIRE(spec.width == l.width());
  REQUIRE(spec.height == l.height());
  REQUIRE(spec.nchannels == 3);
  std::vector<uint8_t> px(size_t(spec.width) * size_t(spec.height) * 3);
  REQUIRE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  size_t wrong = 0, cell_pixels = 0;
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) {
      const uint8_t* p = &px[(size_t(y) * size_t(spec.width) + size_t(x)) * 3];
      const int cx = (x - kContactSheetGap) / (w + kContactSheetGap),
                ox = (x - kContactSheetGap) % (w + kContactSheetGap);
      const int cy = (y - kContactSheetGap) / (h + kContactSheetGap),
                oy = (y - kContactSheetGap) % (h + kContactSheetGap);
      const int k = cy * 2 + cx;
      const bool inside = x >= kContactSheetGap && y >= kContactSheetGap && ox < w && oy < h && k < 5;
      if (inside) {
        ++cell_pixels;
        wrong += p[0] != k + 1 || p[1] != ox || p[2] != oy;
      } else {
        wrong += p[0] != 0 || p[1] != 0 || p[2] != 0;
      }
    }
  CHECK(cell_pixels == size_t(5 * w * h));
  CHECK(wrong == 0);
  fs::remove_all(dir);
}

TEST_CASE("contact sheet: mismatched images, no images and oversized sheets are refused",
          "[io][contact_sheet]") {
  const fs::path dir = test::temp_dir("contact-sheet-bad");
  const fs::path a = write_cell(dir, 1, 8, 8), b = write_cell(dir, 2, 9, 8), c = write_cell(dir, 3, 8, 8, 4);
  const fs::path sheet = dir / "sheet.png";
  CHECK_THROWS_WITH(write_contact_sheet({a, b}, 0, sheet, 1 << 30),
                    Catch::Contains("cell2.png") && Catch::Contains("9x8"));
  CHECK_THROWS_WITH(write_contact_sheet({a, c}, 0, sheet, 1 << 30), Catch::Contains("4 channels"));
  CHECK_THROWS_WITH(write_contact_sheet({a, dir / "missing.png"}, 0, sheet, 1 << 30),
                    Catch::Contains("missing.png"));
  CHECK_THROWS_AS(write_contact_sheet({}, 0, sheet, 1 << 30), InputError);
  // 2 cells of 8x8 RGB need (2 * 10 + 2) x 12 x 3 bytes; a budget below that is refused.
  CHECK_THROWS_WITH(write_contact_sheet({a, a}, 0, sheet, 22 * 12 * 3 - 1), Catch::Contains("budget"));
  CHECK_FALSE(fs::exists(sheet));
  CHECK_NOTHROW(write_contact_sheet({a, a}, 0, sheet, 22 * 12 * 3));
  CHECK(fs::exists(sheet));
  fs::remove_all(dir);
}

TEST_CASE("contact sheet size checks: sides and bytes, from numbers or the first image",
          "[io][contact_sheet]") {
  // 40 cells of 4096 x 16 fit one column (722 tall, 4100 wide); 20 columns are 20 x 4098 wide.
  CHECK_NOTHROW(check_contact_sheet_size(40, 0, 4096, 16, 3, "s.png", uint64_t(1) << 32));
  CHECK_THROWS_WITH(check_contact_sheet_size(40, 20, 4096, 16, 3, "s.png", uint64_t(1) << 32),
                    Catch::Contains("s.png") && Catch::Contains("65536"));
  // Bytes: 2 cells of 8 x 8 RGBA in one row need 22 x 12 x 4.
  CHECK_NOTHROW(check_contact_sheet_size(2, 0, 8, 8, 4, "s.png", 22 * 12 * 4));
  CHECK_THROWS_WITH(check_contact_sheet_size(2, 0, 8, 8, 4, "s.png", 22 * 12 * 4 - 1),
                    Catch::Contains("budget"));
  const fs::path dir = test::temp_dir("contact-sheet-size");
  const fs::path a = write_cell(dir, 1, 8, 8);
  CHECK_NOTHROW(check_contact_sheet_size(a, 2, 0, dir / "s.png", 22 * 12 * 3));
  CHECK_THROWS_WITH(check_contact_sheet_size(a, 2, 0, dir / "s.png", 22 * 12 * 3 - 1),
                    Catch::Contains("budget"));
  CHECK_THROWS_WITH(check_contact_sheet_size(dir / "none.png", 2, 0, dir / "s.png", 1 << 20),
                    Catch::Contains("none.png"));
  fs::remove_all(dir);
}
