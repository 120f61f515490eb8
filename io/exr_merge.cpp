// Merging crops and tiles into one EXR (single- or multi-part).
#include "io/exr_merge.h"

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <string>

#include "io/atomic_file.h"
#include "io/error.h"

namespace penumbra {

void merge_exr_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out) {
  if (parts.empty()) throw InputError(out.string(), "", "no parts to merge");
  std::vector<OIIO::ImageSpec> full;            // per EXR part (subimage), from the first file
  std::vector<std::vector<unsigned char>> pixels;  // per subimage, the whole frame
  std::vector<int> owner;                        // file that wrote each pixel, -1 = none
  for (size_t k = 0; k < parts.size(); ++k) {
    const std::string name = parts[k].string();
    auto in = OIIO::ImageInput::open(name);
    if (!in) throw InputError(name, "", "cannot read: " + OIIO::geterror());
    std::vector<OIIO::ImageSpec> specs;
    for (int sub = 0; in->seek_subimage(sub, 0); ++sub) specs.push_back(in->spec());
    if (specs.empty()) throw InputError(name, "", "has no image");
    const OIIO::ImageSpec& s0 = specs[0];
    if (s0.full_x != 0 || s0.full_y != 0 || s0.full_width < 1 || s0.full_height < 1 || s0.full_width > 65536 ||
        s0.full_height > 65536)
      throw InputError(name, "", "unsupported display window");
    if (s0.x < 0 || s0.y < 0 || s0.x + s0.width > s0.full_width || s0.y + s0.height > s0.full_height)
      throw InputError(name, "", "data window lies outside the display window");
    for (const auto& sp : specs)
      if (sp.x != s0.x || sp.y != s0.y || sp.width != s0.width || sp.height != s0.height || sp.full_width != s0.full_width ||
          sp.full_height != s0.full_height)
        throw InputError(name, "", "its parts have different windows");
    if (k == 0) {
      full = specs;
      double bytes = 0;
      for (const auto& sp : specs) bytes += double(sp.full_width) * double(sp.full_height) * double(sp.pixel_bytes(true));
      if (bytes > 8.0 * (1ull << 30)) throw InputError(name, "", "the full frame would need more than 8 GiB");
      for (const auto& sp : specs) pixels.emplace_back(size_t(sp.full_width) * size_t(sp.full_height) * sp.pixel_bytes(true), 0);
      owner.assign(size_t(s0.full_width) * size_t(s0.full_height), -1);
    } else {
      if (s0.full_width != full[0].full_width || s0.full_height != full[0].full_height)
        throw InputError(name, "", "display window " + std::to_string(s0.full_width) + "x" + std::to_string(s0.full_height) +
                                       " differs from " + parts[0].string() + "'s " + std::to_string(full[0].full_width) + "x" +
                                       std::to_string(full[0].full_height));
      bool same = specs.size() == full.size();
      for (size_t sub = 0; same && sub < specs.size(); ++sub) {
        same = specs[sub].nchannels == full[sub].nchannels;
        for (int c = 0; same && c < specs[sub].nchannels; ++c)
          same = specs[sub].channelnames[size_t(c)] == full[sub].channelnames[size_t(c)] &&
                 specs[sub].channelformat(c) == full[sub].channelformat(c);
      }
      if (!same) throw InputError(name, "", "its parts or channels differ from " + parts[0].string() + "'s");
    }
    // Ownership (no overlaps), then each subimage's pixels copied unchanged.
    for (int y = 0; y < s0.height; ++y)
      for (int x = 0; x < s0.width; ++x) {
        const size_t f = size_t(s0.y + y) * size_t(s0.full_width) + size_t(s0.x + x);
        if (owner[f] >= 0)
          throw InputError(name, "", "overlaps " + parts[size_t(owner[f])].string() + " at pixel " +
                                         std::to_string(s0.x + x) + "," + std::to_string(s0.y + y));
        owner[f] = int(k);
      }
    for (size_t sub = 0; sub < specs.size(); ++sub) {
      const OIIO::ImageSpec& sp = specs[sub];
      const size_t pb = sp.pixel_bytes(true);
      std::vector<unsigned char> data(size_t(sp.width) * size_t(sp.height) * pb);
      if (!in->read_image(int(sub), 0, 0, sp.nchannels, OIIO::TypeDesc::UNKNOWN, data.data()))
        throw InputError(name, "", "cannot decode: " + in->geterror());
      for (int y = 0; y < sp.height; ++y)
        std::memcpy(&pixels[sub][(size_t(sp.y + y) * size_t(sp.full_width) + size_t(sp.x)) * pb],
                    &data[size_t(y) * size_t(sp.width) * pb], size_t(sp.width) * pb);
    }
  }
  for (size_t f = 0; f < owner.size(); ++f)
    if (owner[f] < 0)
      throw InputError(out.string(), "", "the parts do not cover the frame: pixel " + std::to_string(f % size_t(full[0].full_width)) +
                                             "," + std::to_string(f / size_t(full[0].full_width)) + " is missing");
  std::vector<OIIO::ImageSpec> specs = full;
  for (auto& sp : specs) {
    sp.x = sp.y = 0;
    sp.width = sp.full_width;
    sp.height = sp.full_height;
    sp.tile_width = sp.tile_height = 0;
  }
  write_atomically(out, [&](const std::filesystem::path& temp) {
    auto o = OIIO::ImageOutput::create(out.string());
    if (!o) throw std::runtime_error(out.string() + ": no image writer (" + OIIO::geterror() + ")");
    const bool multi = specs.size() > 1;
    if (!(multi ? o->open(temp.string(), int(specs.size()), specs.data()) : o->open(temp.string(), specs[0])))
      throw std::runtime_error(out.string() + ": cannot open for writing: " + o->geterror());
    for (size_t sub = 0; sub < specs.size(); ++sub) {
      if (sub > 0 && !o->open(temp.string(), specs[sub], OIIO::ImageOutput::AppendSubimage))
        throw std::runtime_error(out.string() + ": cannot start part " + std::to_string(sub) + ": " + o->geterror());
      if (!o->write_image(OIIO::TypeDesc::UNKNOWN, pixels[sub].data()))
        throw std::runtime_error(out.string() + ": write failed: " + o->geterror());
    }
    if (!o->close()) throw std::runtime_error(out.string() + ": close failed: " + o->geterror());
  });
}

}  // namespace penumbra
