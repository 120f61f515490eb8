// File access (io/gltf/file_access.cpp) on files built here: GLB chunks of unknown type, a
// second or misplaced BIN chunk, URIs refused by policy, missing or short files, FIFOs and
// devices refused without blocking, and the list of every file the loader read.
#include <OpenImageIO/imageio.h>
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstring>
#include <fstream>

#include "io/files/error.h"
#include "io/files/hash.h"
#include "io/gltf/loader.h"
#include "support/gltf_hostile.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using nlohmann::json;
using penumbra::test::append_glb_chunk;
using penumbra::test::GltfWriter;
using penumbra::test::has_warning;
using penumbra::test::names;
using penumbra::test::triangle_scene;
using penumbra::test::write_text;
namespace fs = std::filesystem;

TEST_CASE(
    "gltf hardening: GLB chunks of unknown type are ignored with a warning; a second BIN chunk is an error",
    "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("glb-chunks");
  GltfWriter w;
  w.node({{"mesh",
           w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}))}});
  w.write_glb(dir / "plain.glb");
  const LoadedScene plain = load_gltf(dir / "plain.glb");

  w.write_glb(dir / "extra.glb");
  append_glb_chunk(dir / "extra.glb", 0x54584554u, {'e', 'x', 't', 'r', 'a', ' ', ' ', ' '});
  append_glb_chunk(dir / "extra.glb", 0x12345678u, {});
  const LoadedScene extra = load_gltf(dir / "extra.glb");
  REQUIRE(extra.scene.meshes.size() == 1);
  CHECK(extra.scene.meshes[0].positions == plain.scene.meshes[0].positions);
  CHECK(extra.scene.meshes[0].indices == plain.scene.meshes[0].indices);
  CHECK(has_warning(extra, "GLB chunk 2: unknown chunk type 0x54584554 (8 bytes) ignored"));
  CHECK(has_warning(extra, "GLB chunk 3: unknown chunk type 0x12345678 (0 bytes) ignored"));

  w.write_glb(dir / "two-bin.glb");
  append_glb_chunk(dir / "two-bin.glb", 0x004E4942u, {0, 0, 0, 0});
  REQUIRE_THROWS_WITH(load_gltf(dir / "two-bin.glb"),
                      names(dir / "two-bin.glb", "GLB chunk 2") && Contains("a second BIN chunk"));
  // A BIN chunk after an unknown chunk is not the second chunk.
  GltfWriter json_only = w;
  json_only.bin.clear();
  json_only.j.erase("bufferViews");
  json_only.j.erase("accessors");
  json_only.j["meshes"] = json::array();
  json_only.j["nodes"] = json::array();
  json_only.j["scenes"][0]["nodes"] = json::array();
  std::string text = json_only.j.dump();
  while (text.size() % 4) text += ' ';
  std::vector<uint8_t> glb = {'g', 'l', 'T', 'F', 2, 0, 0, 0, 0, 0, 0, 0};
  const uint32_t jl = uint32_t(text.size()), jt = 0x4E4F534Au;
  glb.insert(glb.end(), reinterpret_cast<const uint8_t*>(&jl), reinterpret_cast<const uint8_t*>(&jl) + 4);
  glb.insert(glb.end(), reinterpret_cast<const uint8_t*>(&jt), reinterpret_cast<const uint8_t*>(&jt) + 4);
  glb.insert(glb.end(), text.begin(), text.end());
  const uint32_t total = uint32_t(glb.size());
  std::memcpy(glb.data() + 8, &total, 4);
  std::ofstream(dir / "late-bin.glb", std::ios::binary)
      .write(reinterpret_cast<const char*>(glb.data()), std::streamsize(glb.size()));
  append_glb_chunk(dir / "late-bin.glb", 0x54584554u, {1, 2, 3, 4});
  CHECK_NOTHROW(load_gltf(dir / "late-bin.glb"));  // JSON + unknown: the unknown chunk is ignored
  append_glb_chunk(dir / "late-bin.glb", 0x004E4942u, {0, 0, 0, 0});
  REQUIRE_THROWS_WITH(load_gltf(dir / "late-bin.glb"),
                      names(dir / "late-bin.glb", "GLB chunk 2") && Contains("must be the second chunk"));
}

TEST_CASE("gltf hardening: URIs refused by policy and missing files name the buffer or image",
          "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("uri-policy");
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()))}});
  w.write_external(dir / "scene.gltf", "scene.bin");
  json j = w.j;
  j["buffers"] = {{{"byteLength", 48}, {"uri", "/etc/passwd"}}};
  write_text(dir / "abs.gltf", j.dump());
  REQUIRE_THROWS_WITH(load_gltf(dir / "abs.gltf"), names(dir / "abs.gltf", "buffers[0]") &&
                                                       Contains("URI '/etc/passwd' refused by policy") &&
                                                       Contains("outside the scene folder"));
  j["buffers"] = {{{"byteLength", 48}, {"uri", "scene.bin"}},
                  {{"byteLength", 48}, {"uri", "..%2F..%2Fetc%2Fpasswd"}}};
  write_text(dir / "up.gltf", j.dump());
  REQUIRE_THROWS_WITH(load_gltf(dir / "up.gltf"),
                      names(dir / "up.gltf", "buffers[1]") && Contains("refused by policy"));
  j["buffers"] = {{{"byteLength", 48}, {"uri", "missing.bin"}}};
  write_text(dir / "missing.gltf", j.dump());
  REQUIRE_THROWS_WITH(load_gltf(dir / "missing.gltf"), names(dir / "missing.gltf", "buffers[0]") &&
                                                           Contains("missing.bin") &&
                                                           Contains("file not found"));
  j["buffers"] = {{{"byteLength", 40}, {"uri", "scene.bin"}}};
  write_text(dir / "short.gltf", j.dump());
  REQUIRE_THROWS_WITH(load_gltf(dir / "short.gltf"),
                      names(dir / "short.gltf", "buffers[0]") && Contains("byteLength is 40"));
  // Images: a warning naming the image, and the scene still loads.
  j = w.j;
  j["buffers"] = {{{"byteLength", 48}, {"uri", "scene.bin"}}};
  j["images"] = {{{"uri", "/etc/passwd"}}, {{"uri", "nothere.png"}}};
  write_text(dir / "img.gltf", j.dump());
  const LoadedScene l = load_gltf(dir / "img.gltf");
  CHECK(l.scene.meshes.size() == 1);
  CHECK(has_warning(l, "images[0]: URI '/etc/passwd' refused by policy"));
  CHECK(has_warning(l, "images[1]: URI 'nothere.png' cannot be read"));
  // With --allow-external-uris an absolute path is read (a regular file of the right size).
  std::filesystem::copy_file(dir / "scene.bin", dir / "elsewhere.bin");
  j["buffers"] = {{{"byteLength", 48}, {"uri", (dir / "elsewhere.bin").string()}}};
  j.erase("images");
  write_text(dir / "sub.gltf", j.dump());
  fs::create_directories(dir / "sub");
  fs::rename(dir / "sub.gltf", dir / "sub" / "sub.gltf");
  REQUIRE_THROWS_WITH(load_gltf(dir / "sub" / "sub.gltf"), Contains("refused by policy"));
  GltfLoadOptions allow;
  allow.allow_external_uris = true;
  CHECK(load_gltf(dir / "sub" / "sub.gltf", allow).scene.meshes.size() == 1);
}

TEST_CASE("gltf hardening: a FIFO or a device as the scene or as a buffer is refused without blocking",
          "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("fifo");
  REQUIRE(::mkfifo((dir / "scene.gltf").c_str(), 0600) == 0);
  REQUIRE(::mkfifo((dir / "data.bin").c_str(), 0600) == 0);
  const auto t0 = std::chrono::steady_clock::now();
  REQUIRE_THROWS_WITH(load_gltf(dir / "scene.gltf"),
                      Contains((dir / "scene.gltf").string()) && Contains("is a FIFO"));
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()))}});
  json j = w.j;
  j["buffers"] = {{{"byteLength", 48}, {"uri", "data.bin"}}};
  write_text(dir / "buf.gltf", j.dump());
  REQUIRE_THROWS_WITH(load_gltf(dir / "buf.gltf"),
                      names(dir / "buf.gltf", "buffers[0]") && Contains("is a FIFO"));
  j["images"] = {{{"uri", "data.bin"}}};
  j["buffers"] = {{{"byteLength", 48}, {"uri", "/dev/zero"}}};
  write_text(dir / "zero.gltf", j.dump());
  GltfLoadOptions allow;
  allow.allow_external_uris = true;
  REQUIRE_THROWS_WITH(load_gltf(dir / "zero.gltf", allow),
                      names(dir / "zero.gltf", "buffers[0]") && Contains("character device"));
  REQUIRE_THROWS_WITH(load_gltf("/dev/zero"), Contains("/dev/zero") && Contains("character device"));
  CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5));
}

TEST_CASE("gltf hardening: GltfInfo::source_files lists the scene file, then each external buffer and image",
          "[io][gltf][quick]") {
  const auto dir = test::temp_dir("sources");
  {
    auto out = OIIO::ImageOutput::create("png");
    REQUIRE(out);
    REQUIRE(out->open((dir / "tex.png").string(), OIIO::ImageSpec(2, 2, 3, OIIO::TypeDesc::UINT8)));
    const std::vector<uint8_t> pixels(12, 100);
    REQUIRE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
    out->close();
  }
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()))}});
  w.j["images"] = {{{"uri", "tex.png"}}, {{"uri", "tex.png"}}, {{"uri", "gone.png"}}};
  w.write_external(dir / "scene.gltf", "scene.bin");
  const LoadedScene ext = load_gltf(dir / "scene.gltf");
  const std::vector<fs::path> expected = {dir / "scene.gltf", fs::canonical(dir / "scene.bin"),
                                          fs::canonical(dir / "tex.png")};
  CHECK(ext.info.source_files == expected);  // each file once, in load order; unread files absent
  // The digest of each file's bytes as read, equal to hashing the file now.
  REQUIRE(ext.info.source_sha256.size() == expected.size());
  for (size_t i = 0; i < expected.size(); ++i) CHECK(ext.info.source_sha256[i] == sha256_file(expected[i]));
  CHECK(sha256_of_set(ext.info.source_files, ext.info.source_sha256) == sha256_of_files(expected));

  w.j.erase("images");
  w.write_embedded(dir / "embedded.gltf");
  w.write_glb(dir / "packed.glb");
  CHECK(load_gltf(dir / "embedded.gltf").info.source_files == std::vector<fs::path>{dir / "embedded.gltf"});
  CHECK(load_gltf(dir / "packed.glb").info.source_files == std::vector<fs::path>{dir / "packed.glb"});
}
