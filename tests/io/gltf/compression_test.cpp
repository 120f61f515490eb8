// Geometry compression (io/gltf/compression.h) through real encoders: the project's default
// scene packed by gltfpack with meshoptimizer compression and with KHR_mesh_quantization, and
// transcoded by Draco's glTF transcoder, loads as the same surface as the plain file; a mesh
// encoded by draco_encoder loads as the triangles it was made from; the corpus' Draco and quantized Ducks
// match the plain Duck; and corrupted, truncated or oversized streams end in an InputError naming the
// element.
#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>
#include <regex>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/test_util.h"

using namespace penumbra;
namespace fs = std::filesystem;

namespace {

// World-space bounds, total area and count of the triangles of non-zero area a scene places.
struct Surface {
  Bounds3f bounds;
  double area = 0;
  uint64_t triangles = 0;
  std::vector<Vec3f> centroids;
};

Surface surface_of(const Scene& scene) {
  Surface s;
  for (const Instance& inst : scene.instances) {
    if (inst.mesh < 0) continue;
    const Mesh& m = scene.meshes[size_t(inst.mesh)];
    auto world = [&](uint32_t i) {
      return inst.identity ? m.positions[i] : apply_point(inst.to_world, m.positions[i]);
    };
    for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
      const Vec3f a = world(m.indices[t]), b = world(m.indices[t + 1]), c = world(m.indices[t + 2]);
      s.bounds = merge(merge(merge(s.bounds, a), b), c);
      const double area = 0.5 * double(length(cross(b - a, c - a)));
      if (!(area > 0)) continue;  // encoders drop degenerate triangles
      s.area += area;
      s.centroids.push_back((a + b + c) / 3.0f);
      ++s.triangles;
    }
  }
  return s;
}

// The two surfaces agree: the same count of non-degenerate triangles, bounds within tol x
// extent, area within 0.5%.
void check_same_surface(const Surface& a, const Surface& b, float tol) {
  CHECK(a.triangles == b.triangles);
  const float extent = max_component(a.bounds.extent());
  for (int k = 0; k < 3; ++k) {
    CHECK(std::fabs(a.bounds.lo[k] - b.bounds.lo[k]) <= tol * extent);
    CHECK(std::fabs(a.bounds.hi[k] - b.bounds.hi[k]) <= tol * extent);
  }
  CHECK(b.area == Approx(a.area).epsilon(5e-3));
}

std::vector<unsigned char> read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

void write_bytes(const fs::path& p, const std::vector<unsigned char>& b) {
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

std::string base64(const unsigned char* data, size_t n) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < n; i += 3) {
    const uint32_t v = uint32_t(data[i]) << 16 | (i + 1 < n ? uint32_t(data[i + 1]) << 8 : 0) |
                       (i + 2 < n ? uint32_t(data[i + 2]) : 0);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < n ? k[(v >> 6) & 63] : '=';
    out += i + 2 < n ? k[v & 63] : '=';
  }
  return out;
}

// A glTF whose one primitive is the Draco stream `stream` with `points` vertices and `faces`
// triangles (POSITION attribute id `id`).
std::string draco_gltf(const std::vector<char>& stream, int id, size_t points, size_t faces) {
  const std::string data = base64(reinterpret_cast<const unsigned char*>(stream.data()), stream.size());
  return R"({"asset":{"version":"2.0"},"extensionsUsed":["KHR_draco_mesh_compression"],
"extensionsRequired":["KHR_draco_mesh_compression"],
"buffers":[{"byteLength":)" +
         std::to_string(stream.size()) + R"(,"uri":"data:application/octet-stream;base64,)" + data + R"("}],
"bufferViews":[{"buffer":0,"byteLength":)" +
         std::to_string(stream.size()) + R"(}],
"accessors":[{"componentType":5126,"count":)" +
         std::to_string(points) + R"(,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},
{"componentType":5125,"count":)" +
         std::to_string(faces * 3) + R"(,"type":"SCALAR"}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,
"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{"POSITION":)" +
         std::to_string(id) + R"(}}}}]}],
"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
}

// A 6 x 6 height field over [-1, 1]^2: 36 vertices, 50 triangles.
Vec3f field_point(int i, int j) {
  const float x = -1 + 2 * i / 5.0f, y = -1 + 2 * j / 5.0f;
  return {x, y, 0.3f * std::sin(3 * x) * std::cos(2 * y)};
}

std::vector<Vec3f> soup() {
  std::vector<Vec3f> tris;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      for (Vec3f v : {field_point(i, j), field_point(i + 1, j), field_point(i + 1, j + 1)}) tris.push_back(v);
      for (Vec3f v : {field_point(i, j), field_point(i + 1, j + 1), field_point(i, j + 1)}) tris.push_back(v);
    }
  return tris;
}

bool have_tool(const char* name) {
  return std::system((std::string("command -v ") + name + " > /dev/null 2>&1").c_str()) == 0;
}

// The height field as an indexed OBJ encoded by draco_encoder with 16-bit positions.
std::vector<char> encode_field(const fs::path& dir) {
  std::ofstream obj(dir / "field.obj");
  obj.precision(9);
  for (int i = 0; i <= 5; ++i)
    for (int j = 0; j <= 5; ++j) {
      const Vec3f p = field_point(i, j);
      obj << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
  auto id = [](int i, int j) { return i * 6 + j + 1; };
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      obj << "f " << id(i, j) << ' ' << id(i + 1, j) << ' ' << id(i + 1, j + 1) << '\n';
      obj << "f " << id(i, j) << ' ' << id(i + 1, j + 1) << ' ' << id(i, j + 1) << '\n';
    }
  obj.close();
  const std::string cmd = "draco_encoder -i '" + (dir / "field.obj").string() + "' -o '" +
                          (dir / "field.drc").string() + "' -qp 16 > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const std::vector<unsigned char> b = read_bytes(dir / "field.drc");
  return {b.begin(), b.end()};
}

}  // namespace

TEST_CASE("compression: gltfpack's meshopt and quantized files load as the plain scene",
          "[io][gltf][compression]") {
  if (!have_tool("gltfpack"))
    return test::skip("gltfpack not installed (scripts/install-deps.sh installs it)");
  const fs::path src = test::source_dir() / "scenes" / "default.gltf";
  const Surface plain = surface_of(load_gltf(src).scene);
  const fs::path dir = test::temp_dir("compression_gltfpack");
  struct Variant {
    const char* name;
    const char* flags;
    const char* extension;
  };
  for (const Variant& v : {Variant{"meshopt.glb", "-c -noq", "EXT_meshopt_compression"},
                           Variant{"meshopt.gltf", "-cc -noq", "EXT_meshopt_compression"},
                           Variant{"quantized.glb", "", "KHR_mesh_quantization"},
                           Variant{"both.glb", "-c", "EXT_meshopt_compression"}}) {
    INFO(v.name);
    const fs::path out = dir / v.name;
    const std::string cmd =
        "gltfpack -i '" + src.string() + "' -o '" + out.string() + "' " + v.flags + " > /dev/null 2>&1";
    REQUIRE(std::system(cmd.c_str()) == 0);
    const LoadedScene l = load_gltf(out);
    const auto& used = l.info.extensions_used;
    CHECK(std::find(used.begin(), used.end(), v.extension) != used.end());
    for (const auto& w : l.warnings) CHECK(w.find("not supported") == std::string::npos);
    // Quantization moves vertices by up to 2^-14 of the extent (gltfpack's default 14 bits).
    check_same_surface(plain, surface_of(l.scene), 1e-3f);
  }
}

TEST_CASE("compression: Draco's glTF transcoder output loads as the plain scene", "[io][gltf][compression]") {
  if (!have_tool("draco_transcoder"))
    return test::skip("draco_transcoder not installed (scripts/install-deps.sh installs it)");
  const fs::path src = test::source_dir() / "scenes" / "default.gltf";
  const Surface plain = surface_of(load_gltf(src).scene);
  const fs::path out = test::temp_dir("compression_transcoder") / "draco.gltf";
  const std::string cmd =
      "draco_transcoder -i '" + src.string() + "' -o '" + out.string() + "' > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const LoadedScene l = load_gltf(out);
  const auto& used = l.info.extensions_used;
  CHECK(std::find(used.begin(), used.end(), "KHR_draco_mesh_compression") != used.end());
  check_same_surface(plain, surface_of(l.scene), 1e-3f);
}

TEST_CASE("compression: a Draco-encoded mesh loads as the triangles it was made from",
          "[io][gltf][compression]") {
  if (!have_tool("draco_encoder"))
    return test::skip("draco_encoder not installed (scripts/install-deps.sh installs it)");
  const fs::path dir = test::temp_dir("compression_draco");
  const std::vector<char> stream = encode_field(dir);
  const int id = 0;  // draco_encoder's POSITION attribute
  const size_t points = 36, faces = 50;
  std::ofstream(dir / "draco.gltf") << draco_gltf(stream, id, points, faces);
  const LoadedScene l = load_gltf(dir / "draco.gltf");
  const Surface s = surface_of(l.scene);
  REQUIRE(s.triangles == 50);
  // Every decoded triangle is one of the soup's, within 16-bit quantization of the extent 2.
  const std::vector<Vec3f> tris = soup();
  for (const Vec3f& c : s.centroids) {
    float best = kInfinity;
    for (size_t t = 0; t < tris.size(); t += 3)
      best = std::min(best, length((tris[t] + tris[t + 1] + tris[t + 2]) / 3.0f - c));
    CHECK(best < 1e-4f);
  }

  SECTION("a truncated stream is an error naming the primitive") {
    std::vector<char> cut(stream.begin(), stream.begin() + std::ptrdiff_t(stream.size() / 2));
    std::ofstream(dir / "cut.gltf") << draco_gltf(cut, id, points, faces);
    REQUIRE_THROWS_WITH(load_gltf(dir / "cut.gltf"),
                        Catch::Contains("meshes[0].primitives[0].extensions.KHR_draco_mesh_compression") &&
                            Catch::Contains("Draco"));
  }
  SECTION("counts that differ from the stream are errors naming the accessor use") {
    std::ofstream(dir / "count.gltf") << draco_gltf(stream, id, points + 1, faces);
    REQUIRE_THROWS_WITH(load_gltf(dir / "count.gltf"),
                        Catch::Contains("attributes.POSITION") && Catch::Contains("differs"));
    std::ofstream(dir / "faces.gltf") << draco_gltf(stream, id, points, faces + 2);
    REQUIRE_THROWS_WITH(load_gltf(dir / "faces.gltf"),
                        Catch::Contains("indices") && Catch::Contains("differs"));
    std::ofstream(dir / "id.gltf") << draco_gltf(stream, id + 7, points, faces);
    REQUIRE_THROWS_WITH(load_gltf(dir / "id.gltf"), Catch::Contains("no attribute with id"));
  }
  SECTION("a Draco primitive without indices, or not a triangle list, is an error") {
    std::string text = draco_gltf(stream, id, points, faces);
    const std::string no_indices = std::regex_replace(text, std::regex(R"(,"indices":1)"), "");
    std::ofstream(dir / "noidx.gltf") << no_indices;
    REQUIRE_THROWS_WITH(load_gltf(dir / "noidx.gltf"), Catch::Contains("needs an indices accessor"));
    const std::string strip =
        std::regex_replace(text, std::regex(R"("indices":1)"), R"("indices":1,"mode":5)");
    std::ofstream(dir / "strip.gltf") << strip;
    REQUIRE_THROWS_WITH(load_gltf(dir / "strip.gltf"),
                        Catch::Contains("primitives[0].mode") && Catch::Contains("triangle list"));
  }
  SECTION("the decoded data is charged to the memory budget") {
    GltfLoadOptions opt;
    opt.max_memory_bytes = 64 * 1024;
    std::ofstream(dir / "huge.gltf") << draco_gltf(stream, id, 100000000, faces);
    REQUIRE_THROWS_WITH(load_gltf(dir / "huge.gltf", opt), Catch::Contains("budget"));
  }
}

TEST_CASE("compression: a corrupted meshopt stream is an error naming its bufferView",
          "[io][gltf][compression]") {
  if (!have_tool("gltfpack"))
    return test::skip("gltfpack not installed (scripts/install-deps.sh installs it)");
  const fs::path dir = test::temp_dir("compression_meshopt_bad");
  const fs::path out = dir / "m.gltf";
  const std::string cmd = "gltfpack -i '" + (test::source_dir() / "scenes" / "default.gltf").string() +
                          "' -o '" + out.string() + "' -c -noq > /dev/null 2>&1";
  REQUIRE(std::system(cmd.c_str()) == 0);
  const fs::path bin = dir / "m.bin";
  std::vector<unsigned char> bytes = read_bytes(bin);
  REQUIRE(bytes.size() > 64);
  std::fill(bytes.begin(), bytes.begin() + 64, 0xff);  // the first stream's header and first blocks
  write_bytes(bin, bytes);
  REQUIRE_THROWS_WITH(load_gltf(out), Catch::Contains("bufferViews[0].extensions.EXT_meshopt_compression") &&
                                          Catch::Contains("malformed"));
  bytes.resize(16);  // every stream now reads past its buffer
  write_bytes(bin, bytes);
  REQUIRE_THROWS_AS(load_gltf(out), InputError);
}

TEST_CASE("compression: the corpus' Draco and quantized Ducks match the plain Duck",
          "[io][gltf][compression][corpus]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const Surface plain = surface_of(load_gltf(*corpus / "valid/Duck/glTF-Binary/Duck.glb").scene);
  for (const char* f : {"extensions/Duck/glTF-Draco/Duck.gltf", "extensions/Duck/glTF-Quantized/Duck.gltf"}) {
    INFO(f);
    check_same_surface(plain, surface_of(load_gltf(*corpus / f).scene), 2e-3f);
  }
}
