// Contact sheets read through OpenImageIO and written like every other output (atomic rename).
#include "io/image/contact_sheet.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <string>

#include "io/files/atomic_file.h"
#include "io/files/checked_file.h"
#include "io/files/error.h"

namespace penumbra {

namespace {

constexpr int kMaxSheetSide = 65536;

/// One image's pixels, 8 bits per channel.
struct Cell {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;
  std::string colour_space;  ///< the file's oiio:ColorSpace tag, carried to the sheet
};

Cell read_cell(const std::filesystem::path& file, uint64_t max_bytes) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError(file.string(), "contact sheet", "cannot read the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  Cell c{spec.width, spec.height, spec.nchannels, {}, spec.get_string_attribute("oiio:ColorSpace")};
  if (c.width <= 0 || c.height <= 0 || c.channels < 1 || c.channels > 4 ||
      uint64_t(c.width) * uint64_t(c.height) * uint64_t(c.channels) > max_bytes)
    throw InputError(file.string(), "contact sheet", "unexpected image size or channel count");
  c.pixels.resize(size_t(c.width) * size_t(c.height) * size_t(c.channels));
  if (!in->read_image(0, 0, 0, c.channels, OIIO::TypeDesc::UINT8, c.pixels.data()))
    throw InputError(file.string(), "contact sheet", "cannot read the pixels: " + in->geterror());
  return c;
}

}  // namespace

ContactSheetLayout contact_sheet_layout(size_t images, int columns, int cell_width, int cell_height) {
  ContactSheetLayout l{columns, 0, cell_width, cell_height};
  const size_t n = std::max<size_t>(images, 1);
  if (l.columns <= 0) {
    // The fewest columns whose sheet is no taller than it is wide.
    for (l.columns = 1; size_t(l.columns) < n; ++l.columns) {
      const size_t rows = (n + size_t(l.columns) - 1) / size_t(l.columns);
      if (double(rows) * cell_height <= double(l.columns) * cell_width) break;
    }
  }
  l.columns = int(std::min<size_t>(size_t(l.columns), n));
  l.rows = int((n + size_t(l.columns) - 1) / size_t(l.columns));
  return l;
}

void check_contact_sheet_size(size_t images, int columns, int cell_width, int cell_height, int channels,
                              const std::filesystem::path& out, uint64_t max_bytes) {
  const ContactSheetLayout l = contact_sheet_layout(images, columns, cell_width, cell_height);
  const uint64_t bytes = uint64_t(l.width()) * uint64_t(l.height()) * uint64_t(channels);
  if (l.width() > kMaxSheetSide || l.height() > kMaxSheetSide || bytes > max_bytes)
    throw InputError(out.string(), "contact sheet",
                     "a " + std::to_string(l.width()) + "x" + std::to_string(l.height()) + " sheet of " +
                         std::to_string(images) +
                         " frames exceeds 65536 pixels a side or the memory budget (--max-memory)");
}

void check_contact_sheet_size(const std::filesystem::path& first, size_t images, int columns,
                              const std::filesystem::path& out, uint64_t max_bytes) {
  auto in = OIIO::ImageInput::open(first.string());
  if (!in) throw InputError(first.string(), "contact sheet", "cannot read the image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  check_contact_sheet_size(images, columns, spec.width, spec.height, spec.nchannels, out, max_bytes);
}

void write_contact_sheet(const std::vector<std::filesystem::path>& images, int columns,
                         const std::filesystem::path& out, uint64_t max_bytes) {
  if (images.empty()) throw InputError(out.string(), "contact sheet", "no images to tile");
  const Cell first = read_cell(images[0], max_bytes);
  check_contact_sheet_size(images.size(), columns, first.width, first.height, first.channels, out, max_bytes);
  const ContactSheetLayout l = contact_sheet_layout(images.size(), columns, first.width, first.height);
  const uint64_t bytes = uint64_t(l.width()) * uint64_t(l.height()) * uint64_t(first.channels);
  const size_t nc = size_t(first.channels);
  std::vector<uint8_t> sheet(size_t(bytes), 0);
  for (size_t k = 0; k < images.size(); ++k) {
    const Cell c = k == 0 ? first : read_cell(images[k], max_bytes);
    if (c.width != first.width || c.height != first.height || c.channels != first.channels)
      throw InputError(images[k].string(), "contact sheet",
                       "is " + std::to_string(c.width) + "x" + std::to_string(c.height) + " with " +
                           std::to_string(c.channels) + " channels; " + images[0].string() + " is " +
                           std::to_string(first.width) + "x" + std::to_string(first.height) + " with " +
                           std::to_string(first.channels));
    const size_t x0 = size_t(int(k) % l.columns) * size_t(l.cell_width + kContactSheetGap) + kContactSheetGap;
    const size_t y0 =
        size_t(int(k) / l.columns) * size_t(l.cell_height + kContactSheetGap) + kContactSheetGap;
    const size_t row_bytes = size_t(c.width) * nc;
    for (size_t y = 0; y < size_t(c.height); ++y)
      std::copy_n(c.pixels.data() + y * row_bytes, row_bytes,
                  sheet.data() + ((y0 + y) * size_t(l.width()) + x0) * nc);
  }
  OIIO::ImageSpec spec(l.width(), l.height(), first.channels, OIIO::TypeDesc::UINT8);
  if (first.channels == 4) spec.alpha_channel = 3;
  if (!first.colour_space.empty()) spec.attribute("oiio:ColorSpace", first.colour_space);
  write_atomically(out, [&](const std::filesystem::path& temp) {
    auto o = OIIO::ImageOutput::create(out.string());
    if (!o)
      throw std::runtime_error(out.string() + ": no image writer for this extension (" + OIIO::geterror() +
                               ")");
    write_through_checked_file(o, temp, out, [&] {
      if (!o->open(temp.string(), spec))
        throw std::runtime_error(out.string() + ": cannot open for writing: " + o->geterror());
      if (!o->write_image(OIIO::TypeDesc::UINT8, sheet.data()))
        throw std::runtime_error(out.string() + ": write failed: " + o->geterror());
      if (!o->close()) throw std::runtime_error(out.string() + ": close failed: " + o->geterror());
    });
  });
}

}  // namespace penumbra
