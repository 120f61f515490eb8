// Merging crops and tiles into one EXR.
#include "io/exr_merge.h"

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <string>

#include "io/atomic_file.h"
#include "io/error.h"

namespace penumbra {

void merge_exr_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out) {
  if (parts.empty()) throw InputError(out.string(), "", "no parts to merge");
  OIIO::ImageSpec full;
  std::vector<unsigned char> pixels;
  std::vector<int> owner;  // part index that wrote each pixel, -1 = none
  size_t pixel_bytes = 0;
  for (size_t k = 0; k < parts.size(); ++k) {
    const std::string name = parts[k].string();
    auto in = OIIO::ImageInput::open(name);
    if (!in) throw InputError(name, "", "cannot read: " + OIIO::geterror());
    const OIIO::ImageSpec spec = in->spec();
    if (spec.full_x != 0 || spec.full_y != 0 || spec.full_width < 1 || spec.full_height < 1 ||
        spec.full_width > 65536 || spec.full_height > 65536)
      throw InputError(name, "", "unsupported display window");
    if (spec.x < 0 || spec.y < 0 || spec.x + spec.width > spec.full_width || spec.y + spec.height > spec.full_height)
      throw InputError(name, "", "data window lies outside the display window");
    if (k == 0) {
      full = spec;
      pixel_bytes = spec.pixel_bytes(true);
      if (double(spec.full_width) * double(spec.full_height) * double(pixel_bytes) > 8.0 * (1ull << 30))
        throw InputError(name, "", "the full frame would need more than 8 GiB");
      pixels.assign(size_t(spec.full_width) * size_t(spec.full_height) * pixel_bytes, 0);
      owner.assign(size_t(spec.full_width) * size_t(spec.full_height), -1);
    } else {
      if (spec.full_width != full.full_width || spec.full_height != full.full_height)
        throw InputError(name, "", "display window " + std::to_string(spec.full_width) + "x" + std::to_string(spec.full_height) +
                                       " differs from " + parts[0].string() + "'s " + std::to_string(full.full_width) + "x" +
                                       std::to_string(full.full_height));
      bool same = spec.nchannels == full.nchannels;
      for (int c = 0; same && c < spec.nchannels; ++c)
        same = spec.channelnames[size_t(c)] == full.channelnames[size_t(c)] && spec.channelformat(c) == full.channelformat(c);
      if (!same) throw InputError(name, "", "its channels differ from " + parts[0].string() + "'s");
    }
    std::vector<unsigned char> data(size_t(spec.width) * size_t(spec.height) * pixel_bytes);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UNKNOWN, data.data()))
      throw InputError(name, "", "cannot decode: " + in->geterror());
    for (int y = 0; y < spec.height; ++y)
      for (int x = 0; x < spec.width; ++x) {
        const size_t f = size_t(spec.y + y) * size_t(full.full_width) + size_t(spec.x + x);
        if (owner[f] >= 0)
          throw InputError(name, "", "overlaps " + parts[size_t(owner[f])].string() + " at pixel " +
                                         std::to_string(spec.x + x) + "," + std::to_string(spec.y + y));
        owner[f] = int(k);
        std::memcpy(&pixels[f * pixel_bytes], &data[(size_t(y) * size_t(spec.width) + size_t(x)) * pixel_bytes], pixel_bytes);
      }
  }
  for (size_t f = 0; f < owner.size(); ++f)
    if (owner[f] < 0)
      throw InputError(out.string(), "", "the parts do not cover the frame: pixel " + std::to_string(f % size_t(full.full_width)) +
                                             "," + std::to_string(f / size_t(full.full_width)) + " is missing");
  OIIO::ImageSpec spec = full;
  spec.x = spec.y = 0;
  spec.width = full.full_width;
  spec.height = full.full_height;
  spec.tile_width = spec.tile_height = 0;
  write_atomically(out, [&](const std::filesystem::path& temp) {
    auto o = OIIO::ImageOutput::create(out.string());
    if (!o) throw std::runtime_error(out.string() + ": no image writer (" + OIIO::geterror() + ")");
    if (!o->open(temp.string(), spec)) throw std::runtime_error(out.string() + ": cannot open for writing: " + o->geterror());
    if (!o->write_image(OIIO::TypeDesc::UNKNOWN, pixels.data())) throw std::runtime_error(out.string() + ": write failed: " + o->geterror());
    if (!o->close()) throw std::runtime_error(out.string() + ": close failed: " + o->geterror());
  });
}

}  // namespace penumbra
