// load_ply: ASCII and binary (both byte orders) files give the same triangles; malformed files
// fail with the file and the element named.
#include "io/mesh/ply_loader.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "io/files/error.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

const char* kHeader =
    "ply\nformat %s 1.0\ncomment a unit square and a triangle\nelement vertex 5\nproperty float x\n"
    "property float y\nproperty float z\nproperty uchar red\nelement face 2\n"
    "property list uchar int vertex_indices\nend_header\n";

std::string header(const char* format) {
  char buf[512];
  std::snprintf(buf, sizeof buf, kHeader, format);
  return buf;
}

void write(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

void check_square(const Scene& s) {
  REQUIRE(s.meshes.size() == 1);
  const Mesh& m = s.meshes[0];
  REQUIRE(m.positions.size() == 5);
  CHECK(m.positions[2].x == 1.0f);
  CHECK(m.positions[2].y == 1.0f);
  CHECK(m.positions[4].z == 0.5f);
  // The quad becomes a fan (0 1 2, 0 2 3), then the triangle.
  CHECK(m.indices == std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 1, 4, 2});
  CHECK(m.normals.size() == 5);
}

}  // namespace

TEST_CASE("load_ply: ASCII, binary little- and big-endian give the same mesh", "[ply]") {
  const auto dir = temp_dir("ply");
  const float v[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 0, 0.5f}};
  write(dir / "a.ply",
        header("ascii") + "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n2 0 0.5 5\n4 0 1 2 3\n3 1 4 2\n");
  check_square(load_ply(dir / "a.ply"));
  for (bool big : {false, true}) {
    std::string body;
    auto put = [&](const void* p, size_t n) {
      std::string b(static_cast<const char*>(p), n);
      if (big) std::reverse(b.begin(), b.end());
      body += b;
    };
    for (const auto& p : v) {
      for (float c : p) put(&c, 4);
      body += char(7);
    }
    for (const std::vector<int32_t>& f : {std::vector<int32_t>{0, 1, 2, 3}, std::vector<int32_t>{1, 4, 2}}) {
      body += char(f.size());
      for (int32_t i : f) put(&i, 4);
    }
    const auto file = dir / (big ? "be.ply" : "le.ply");
    write(file, header(big ? "binary_big_endian" : "binary_little_endian") + body);
    check_square(load_ply(file));
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("load_ply: malformed files name the file and the element", "[ply]") {
  const auto dir = temp_dir("ply-bad");
  const auto f = dir / "bad.ply";
  auto fails_with = [&](const std::string& text, const std::string& msg) {
    write(f, text);
    INFO(text);
    CHECK_THROWS_WITH(load_ply(f), Catch::Contains(f.string()) && Catch::Contains(msg));
  };
  fails_with(header("ascii") + "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n2 0 0.5 5\n4 0 1 2 3\n3 1 9 2\n",
             "face[1]: index 9 >= vertex count 5");
  fails_with(header("ascii") + "0 0 0 1\n1 0 0 2\n1 1 0 3\n", "vertex[3]: unexpected end of file");
  fails_with(header("ascii") + "0 0 0 1\n1 nan 0 2\n1 1 0 3\n0 1 0 4\n2 0 0.5 5\n4 0 1 2 3\n3 1 4 2\n",
             "vertex[1]: non-finite coordinate");
  fails_with(header("ascii") + "0 0 0 1\n1 x 0 2\n", "vertex[1]: 'x' is not a number");
  fails_with(header("ascii") + "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n2 0 0.5 5\n2 0 1\n3 1 4 2\n",
             "face[0]: a face needs at least 3 vertices");
  fails_with("solid cube\n", "not a PLY file");
  fails_with(header("binary_middle_endian"), "header line 2: unknown format 'binary_middle_endian'");
  fails_with("ply\nformat ascii 1.0\nelement vertex 99999999999\n", "count in [0, 2^31]");
  // A header claiming 2^31 vertices in a tiny file: a clean error, not a 24 GiB allocation.
  fails_with(
      "ply\nformat binary_little_endian 1.0\nelement vertex 2147483648\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n",
      "vertex[0]: unexpected end of file");
  fails_with("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
             "unexpected end of file in the header");
  fails_with("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
             "needs x, y and z");
  CHECK_THROWS_WITH(load_ply(dir / "missing.ply"), Catch::Contains("missing.ply: file not found"));
  std::filesystem::remove_all(dir);
}
