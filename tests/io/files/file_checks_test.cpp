// Tests for io/file_checks: regular files pass with their size; directories, FIFOs, devices,
// missing and oversized files are InputErrors that say what the path is; scene files in other
// 3D formats are named by extension or signature, and load_gltf refuses them so.
#include "io/files/file_checks.h"

#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <fstream>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {
std::string message_of(const std::filesystem::path& p, uint64_t max = 1 << 20) {
  try {
    check_input_file(p, "--thing", max);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST_CASE("check_input_file: only bounded regular files", "[io][files][quick]") {
  const auto dir = test::temp_dir("file_checks");
  { std::ofstream(dir / "ten.bin") << "0123456789"; }
  CHECK(check_input_file(dir / "ten.bin", "x", 10) == 10);
  CHECK_THAT(message_of(dir / "ten.bin", 9),
             Contains("ten.bin: --thing: is 10 bytes, over the 9 bytes limit"));
  CHECK_THAT(message_of(dir / "missing"), Contains("--thing: file not found"));
  CHECK_THAT(message_of(dir), Contains("is a directory, not a regular file"));
  REQUIRE(::mkfifo((dir / "fifo").c_str(), 0600) == 0);
  CHECK_THAT(message_of(dir / "fifo"), Contains("is a FIFO, not a regular file"));
  CHECK_THAT(message_of("/dev/zero"), Contains("is a character device, not a regular file"));
  std::filesystem::create_symlink(dir / "ten.bin", dir / "link");
  CHECK(check_input_file(dir / "link", "x", 10) == 10);
  CHECK(describe_file_type(dir / "link", false) == "a symbolic link");
  CHECK(describe_file_type(dir / "nope") == "nothing (it does not exist)");
}

TEST_CASE("format_bytes: binary units", "[io][files][quick]") {
  CHECK(format_bytes(512) == "512 bytes");
  CHECK(format_bytes(1536) == "1.5 KiB");
  CHECK(format_bytes(3ull << 30) == "3.0 GiB");
  CHECK(format_bytes(uint64_t(2.2 * double(1ull << 30))) == "2.2 GiB");
}

TEST_CASE("scene_file_format: other 3D formats by extension and by their first bytes", "[io][files][quick]") {
  // By extension, whatever the bytes (case-insensitive).
  CHECK(scene_file_format("a/model.obj", "{", 1) == "a Wavefront OBJ file");
  CHECK(scene_file_format("model.OBJ", "", 0) == "a Wavefront OBJ file");
  CHECK(scene_file_format("m.fbx", "", 0) == "an FBX file");
  for (const char* usd : {"m.usd", "m.usda", "m.usdc", "m.usdz"})
    CHECK(scene_file_format(usd, "", 0) == "a USD file");
  CHECK(scene_file_format("m.ply", "", 0) == "a PLY (Stanford polygon) file");
  CHECK(scene_file_format("m.stl", "", 0) == "an STL file");
  CHECK(scene_file_format("m.abc", "", 0) == "an Alembic file");
  CHECK(scene_file_format("m.blend", "", 0) == "a Blender file");
  CHECK(scene_file_format("m.dae", "", 0) == "a COLLADA file");
  // glTF: a JSON object (after blanks and a byte-order mark) or the GLB magic.
  CHECK(scene_file_format("s.gltf", "{\"asset\":{}}", 12).empty());
  CHECK(scene_file_format("s.gltf", "\xef\xbb\xbf \n {", 8).empty());
  CHECK(scene_file_format("s.glb", std::string_view("glTF\x02\0\0\0", 8), 8).empty());
  // By content for a file named .gltf or .glb.
  CHECK(scene_file_format("s.gltf", "ply\nformat ascii 1.0\n", 21) == "a PLY (Stanford polygon) file");
  CHECK(scene_file_format("s.gltf", "# Blender OBJ\nmtllib a.mtl\nv 0 0 0\n", 35) == "a Wavefront OBJ file");
  CHECK(scene_file_format("s.gltf", "\n\nv 1 2 3\nf 1 2 3\n", 18) == "a Wavefront OBJ file");
  CHECK(scene_file_format("s.glb", "#usda 1.0\n", 10) == "a USD file");
  CHECK(scene_file_format("s.glb", "PXR-USDC", 8) == "a USD file");
  CHECK(scene_file_format("s.glb", "Kaydara FBX Binary  \0", 21) == "an FBX file");
  CHECK(scene_file_format("s.gltf", "solid cube\nfacet normal 0 0 1\n", 30) == "an STL file");
  const std::string stl(84 + 50, '\0');  // binary: 80-byte header, one triangle
  std::string one = stl;
  one[80] = 1;
  CHECK(scene_file_format("s.glb", one, one.size()) == "an STL file");
  CHECK(scene_file_format("s.glb", "BLENDER-v304", 12) == "a Blender file");
  CHECK(scene_file_format("s.glb", "Ogawa", 5) == "an Alembic file");
  CHECK(scene_file_format("s.gltf", "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"\">", 40) == "a COLLADA file");
  CHECK(scene_file_format("s.gltf", "\x89PNG\r\n", 6) == "a PNG image");
  CHECK(scene_file_format("s.gltf", "", 0) == "an empty file");
  CHECK(scene_file_format("s.gltf", "[1, 2]", 6) == "not a glTF file");
  CHECK(scene_file_format("s.gltf", "hello world", 11) == "not a glTF file");
  // Other extensions are read as glTF when the bytes are.
  CHECK(scene_file_format("scene.json", "{}", 2).empty());
}

TEST_CASE("load_gltf refuses another 3D format, naming it, before parsing", "[io][files][quick]") {
  const auto dir = test::temp_dir("scene_formats");
  { std::ofstream(dir / "cube.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"; }
  { std::ofstream(dir / "cube.gltf") << "# exported\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"; }
  { std::ofstream(dir / "cloud.glb") << "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n"; }
  const std::string hint =
      "; Penumbra reads glTF 2.0 (.gltf, .glb) — convert it, e.g. with Blender's glTF exporter";
  CHECK_THROWS_WITH(load_gltf(dir / "cube.obj"),
                    Contains((dir / "cube.obj").string() + ": this is a Wavefront OBJ file" + hint));
  CHECK_THROWS_WITH(load_gltf(dir / "cube.gltf"),
                    Contains((dir / "cube.gltf").string() + ": this is a Wavefront OBJ file" + hint));
  CHECK_THROWS_WITH(load_gltf(dir / "cloud.glb"),
                    Contains("cloud.glb: this is a PLY (Stanford polygon) file" + hint));
  CHECK_THROWS_WITH(load_gltf(dir / "missing.obj"), Contains("missing.obj: file not found"));
  CHECK_THROWS_AS(load_gltf(dir / "cube.obj"), InputError);
}
