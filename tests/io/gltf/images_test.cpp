// Images and samplers (io/gltf/images.cpp): unreadable images are warnings naming the image, an
// image bufferView past its buffer is an error, and an image is charged to the memory budget
// from its header before it is decoded.
#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/gltf_hostile.h"
#include "support/gltf_writer.h"
#include "support/image_files.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using penumbra::test::crc32;
using penumbra::test::GltfWriter;
using penumbra::test::names;
using penumbra::test::read_bytes;
namespace fs = std::filesystem;

TEST_CASE(
    "gltf: unreadable images are warnings naming the image; an image bufferView past its buffer is an error",
    "[io][texture][quick]") {
  const auto dir = test::temp_dir("badimages");
  auto file_with = [&](nlohmann::json images, int view_bytes) {
    test::GltfWriter w;
    const int pos = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const std::vector<float> uv = {0, 0, 1, 0, 0, 1};
    const int tc = w.accessor(uv.data(), 24, 5126, 3, "VEC2");
    w.j["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 0}, {"byteLength", view_bytes}});
    w.j["images"] = images;
    w.j["textures"] = nlohmann::json::array();
    w.j["materials"] = nlohmann::json::array();
    for (size_t i = 0; i < images.size(); ++i) {
      w.j["textures"].push_back({{"source", i}});
      w.j["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", i}}}}}});
      const int m = w.mesh(pos);
      w.j["meshes"][size_t(m)]["primitives"][0]["attributes"]["TEXCOORD_0"] = tc;
      w.j["meshes"][size_t(m)]["primitives"][0]["material"] = i;
      w.node({{"mesh", m}});
    }
    w.write_embedded(dir / "t.gltf");
    return dir / "t.gltf";
  };
  const int view = 2;  // the bufferView added above (after POSITION's and TEXCOORD_0's)
  const auto ok = file_with({{{"uri", "missing.png"}},
                             {{"uri", "../../etc/passwd"}},
                             {{"bufferView", view}, {"mimeType", "image/png"}}},
                            24);
  const LoadedScene ls = load_gltf(ok);
  CHECK(ls.scene.textures.empty());
  for (const char* needle :
       {"images[0]: image data could not be read from 'missing.png'",
        "images[1]: image data could not be read", "images[2]: not a PNG, JPEG or WebP image"}) {
    bool found = false;
    for (const auto& w : ls.warnings) found = found || w.find(needle) != std::string::npos;
    CHECK(found);
  }
  CHECK_THROWS_WITH(load_gltf(file_with({{{"bufferView", view}}}, 60000)),
                    Catch::Contains("bufferViews[2]: byteOffset 0 + byteLength 60000 exceeds buffer 0 of "));
}

TEST_CASE("gltf hardening: an image is charged to the budget from its header, before it is decoded",
          "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("budget-image");
  {
    auto out = OIIO::ImageOutput::create("png");
    REQUIRE(out);
    const OIIO::ImageSpec spec(4, 4, 3, OIIO::TypeDesc::UINT8);
    REQUIRE(out->open((dir / "small.png").string(), spec));
    const std::vector<uint8_t> pixels(4 * 4 * 3, 200);
    REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    out->close();
  }
  // The same file claiming 16000 x 16000 in its IHDR chunk (its pixel data cannot decode).
  std::vector<uint8_t> png = read_bytes(dir / "small.png");
  REQUIRE(std::memcmp(png.data() + 12, "IHDR", 4) == 0);
  for (size_t off : {size_t(16), size_t(20)}) {
    png[off] = 0, png[off + 1] = 0, png[off + 2] = 0x3e, png[off + 3] = 0x80;  // 16000 big-endian
  }
  const uint32_t crc = crc32(png.data() + 12, 17);
  for (int k = 0; k < 4; ++k) png[29 + size_t(k)] = uint8_t(crc >> (24 - 8 * k));
  std::ofstream(dir / "huge.png", std::ios::binary)
      .write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));

  GltfWriter w;
  const int pos = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const std::vector<float> uv = {0, 0, 1, 0, 0, 1};
  const int tc = w.accessor(uv.data(), 24, 5126, 3, "VEC2");
  const int m = w.mesh(pos);
  w.j["meshes"][size_t(m)]["primitives"][0]["attributes"]["TEXCOORD_0"] = tc;
  w.j["meshes"][size_t(m)]["primitives"][0]["material"] = 0;
  w.node({{"mesh", m}});
  w.j["images"] = {{{"uri", "huge.png"}}};
  w.j["textures"] = {{{"source", 0}}};
  w.j["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  w.write_external(dir / "scene.gltf", "scene.bin");
  GltfLoadOptions opt;
  opt.max_memory_bytes = uint64_t(1) << 30;
  REQUIRE_THROWS_WITH(load_gltf(dir / "scene.gltf", opt),
                      names(dir / "scene.gltf", "images[0]") &&
                          Contains("decoding the 16000x16000 image needs") &&
                          Contains("over the 1.0 GiB budget"));
  w.j["images"] = {{{"uri", "small.png"}}};
  w.write_external(dir / "scene.gltf", "scene.bin");
  CHECK(load_gltf(dir / "scene.gltf", opt).scene.textures.size() == 1);
}

namespace {
// One textured triangle whose texture is `texture` over `images`.
fs::path textured_file(const fs::path& dir, nlohmann::json images, nlohmann::json texture,
                       std::vector<std::string> used) {
  test::GltfWriter w;
  const int pos = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const std::vector<float> uv = {0, 0, 1, 0, 0, 1};
  const int tc = w.accessor(uv.data(), 24, 5126, 3, "VEC2");
  w.j["images"] = images;
  w.j["textures"] = {texture};
  w.j["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  const int m = w.mesh(pos);
  w.j["meshes"][size_t(m)]["primitives"][0]["attributes"]["TEXCOORD_0"] = tc;
  w.j["meshes"][size_t(m)]["primitives"][0]["material"] = 0;
  w.node({{"mesh", m}});
  w.j["extensionsUsed"] = used;
  w.write_embedded(dir / "t.gltf");
  return dir / "t.gltf";
}
}  // namespace

TEST_CASE("EXT_texture_webp reads the WebP source; KHR_texture_basisu uses the fallback source or warns",
          "[io][texture][quick]") {
  const auto dir = test::temp_dir("texture_extensions");
  const unsigned char red[3] = {255, 0, 0}, blue[3] = {0, 0, 255};
  test::write_flat_image(dir / "red.png", red);
  test::write_flat_image(dir / "blue.webp", blue);
  // A KTX2 file: its 12-byte identifier and nothing a decoder could use.
  std::ofstream(dir / "t.ktx2", std::ios::binary) << std::string("\xABKTX 20\xBB\r\n\x1A\n", 12) << "payload";
  const nlohmann::json images = {{{"uri", "red.png"}}, {{"uri", "blue.webp"}}, {{"uri", "t.ktx2"}}};
  auto texel = [](const LoadedScene& l) {
    REQUIRE(l.scene.textures.size() == 1);
    return sample_texture(l.scene.textures[0], {0.5f, 0.5f}, 0);
  };
  // WebP preferred over the PNG fallback.
  LoadedScene l = load_gltf(
      textured_file(dir, images, {{"source", 0}, {"extensions", {{"EXT_texture_webp", {{"source", 1}}}}}},
                    {"EXT_texture_webp"}));
  CHECK(l.warnings.empty());
  CHECK(texel(l).z == Approx(1));
  CHECK(texel(l).x == Approx(0));
  // Basis Universal: the KTX2 image is not decoded, the core source is the fallback.
  l = load_gltf(textured_file(dir, images,
                              {{"source", 0}, {"extensions", {{"KHR_texture_basisu", {{"source", 2}}}}}},
                              {"KHR_texture_basisu"}));
  CHECK(l.warnings.empty());
  CHECK(texel(l).x == Approx(1));
  // Without a fallback: a warning naming the texture and the extension, and no texture.
  l = load_gltf(textured_file(dir, images, {{"extensions", {{"KHR_texture_basisu", {{"source", 2}}}}}},
                              {"KHR_texture_basisu"}));
  CHECK(l.scene.textures.empty());
  REQUIRE(l.warnings.size() == 1);
  CHECK_THAT(l.warnings[0], Contains("textures[0]") && Contains("KHR_texture_basisu") && Contains("factors"));
  // A KTX2 image used as a plain source: a warning that says what it is.
  l = load_gltf(textured_file(dir, images, {{"source", 2}}, {}));
  REQUIRE(l.warnings.size() == 1);
  CHECK_THAT(l.warnings[0], Contains("images[2]") && Contains("KTX2"));
}
