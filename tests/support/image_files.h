// Writes small flat-coloured image files through OpenImageIO, for tests that feed images to the
// glTF loader.
#pragma once

#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <vector>

namespace penumbra::test {

/// A 4 x 4 image of one 8-bit colour, in the format the extension names (.png, .webp, ...);
/// with an alpha channel of `alpha` if alpha >= 0, else 3 channels.
inline void write_flat_image(const std::filesystem::path& file, const unsigned char rgb[3], int alpha = -1) {
  const int nc = alpha >= 0 ? 4 : 3;
  std::vector<unsigned char> px(size_t(16 * nc));
  for (size_t i = 0; i < px.size(); i += size_t(nc)) {
    for (int c = 0; c < 3; ++c) px[i + size_t(c)] = rgb[c];
    if (nc == 4) px[i + 3] = (unsigned char)alpha;
  }
  auto out = OIIO::ImageOutput::create(file.string());
  REQUIRE(out);
  REQUIRE(out->open(file.string(), OIIO::ImageSpec(4, 4, nc, OIIO::TypeDesc::UINT8)));
  REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
  out->close();
}

}  // namespace penumbra::test
