// The glTF loader end to end (io/gltf/loader.cpp and the phases it runs) on files generated
// here: index types, topologies, hierarchy, normals, cameras, lights, and hostile input (each
// must end in an InputError naming the element, or a warning).
#include "io/gltf/loader.h"

#include <catch2/catch.hpp>
#include <fstream>

#include "io/files/error.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using penumbra::test::GltfWriter;
using penumbra::test::write_and_load;

TEST_CASE("u8, u16, u32 and implicit indices all load the same quad", "[io][gltf][quick]") {
  const auto dir = test::temp_dir("index-types");
  for (int kind = 0; kind < 4; ++kind) {
    GltfWriter w;
    int pos = w.positions(test::quad_positions());
    int idx = -1;
    if (kind == 0) idx = w.indices(std::vector<uint8_t>{0, 1, 2, 0, 2, 3});
    if (kind == 1) idx = w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
    if (kind == 2) idx = w.indices(std::vector<uint32_t>{0, 1, 2, 0, 2, 3});
    if (kind == 3) pos = w.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0});
    w.node({{"mesh", w.mesh(pos, idx)}});
    const auto path = dir / ("q" + std::to_string(kind) + ".gltf");
    w.write_embedded(path);
    const LoadedScene l = load_gltf(path);
    REQUIRE(l.scene.meshes.size() == 1);
    const Mesh& m = l.scene.meshes[0];
    REQUIRE(m.indices.size() == 6);
    const Vec3f c = m.positions[m.indices[4]];  // second triangle's middle vertex = (1, 1, 0)
    CHECK(c == Vec3f{1, 1, 0});
    for (const Vec3f& n : m.normals) CHECK(n.z == Approx(1));  // computed: NORMAL absent
  }
}

TEST_CASE("external .bin buffers and GLB load like data URIs", "[io][gltf][quick]") {
  const auto dir = test::temp_dir("containers");
  GltfWriter w;
  w.node({{"mesh",
           w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}))}});
  w.write_external(dir / "ext.gltf", "ext.bin");
  w.write_glb(dir / "bin.glb");
  for (const char* f : {"ext.gltf", "bin.glb"}) {
    const LoadedScene l = load_gltf(dir / f);
    REQUIRE(l.scene.meshes.size() == 1);
    CHECK(l.scene.meshes[0].indices.size() == 6);
    CHECK(l.warnings.empty());
  }
}

TEST_CASE("triangle strips and fans become counter-clockwise triangle lists", "[io][gltf][quick]") {
  GltfWriter w;
  // Strip 0-1-2-3 over the unit quad (zig-zag order), fan 0-1-2-3 around vertex 0.
  const int strip = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
  const int fan = w.positions(test::quad_positions());
  w.node({{"mesh", w.mesh(strip, -1, 5)}});
  w.node({{"mesh", w.mesh(fan, -1, 6)}});
  const LoadedScene l = write_and_load(w, "topologies");
  REQUIRE(l.scene.meshes.size() == 2);
  for (const Mesh& m : l.scene.meshes) {
    REQUIRE(m.indices.size() == 6);
    for (size_t t = 0; t < 2; ++t) {
      const Vec3f a = m.positions[m.indices[t * 3]], b = m.positions[m.indices[t * 3 + 1]],
                  c = m.positions[m.indices[t * 3 + 2]];
      CHECK(cross(b - a, c - a).z > 0);  // front faces +z
    }
  }
}

TEST_CASE("node TRS hierarchy accumulates parent * child", "[io][gltf][quick]") {
  GltfWriter w;
  const int m = w.mesh(w.positions({1, 0, 0, 1, 1, 0, 1, 0, 1}));
  const int child = w.node({{"mesh", m}, {"scale", {2, 2, 2}}, {"translation", {0, 0, 1}}}, false);
  const double s = std::sqrt(0.5);
  w.node({{"children", {child}}, {"rotation", {0, s, 0, s}}, {"translation", {1, 0, 0}}});  // 90 deg about +y
  const LoadedScene l = write_and_load(w, "hierarchy");
  REQUIRE(l.scene.meshes.size() == 1);
  // (1,0,0) -> scale 2 -> (2,0,0) -> +z -> (2,0,1) -> R_y(90): (z, y, -x) = (1,0,-2) -> +x -> (2,0,-2)
  const Vec3f p = l.scene.meshes[0].positions[0];
  CHECK(p.x == Approx(2));
  CHECK(p.y == Approx(0).margin(1e-6));
  CHECK(p.z == Approx(-2));
}

TEST_CASE("mirroring transforms flip the winding so normals stay outward", "[io][gltf][quick]") {
  GltfWriter w;
  const int m =
      w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint8_t>{0, 1, 2, 0, 2, 3}));
  w.node({{"mesh", m}, {"scale", {-1, 1, 1}}});
  const LoadedScene l = write_and_load(w, "mirror");
  const Mesh& mesh = l.scene.meshes.at(0);
  const Vec3f a = mesh.positions[mesh.indices[0]], b = mesh.positions[mesh.indices[1]],
              c = mesh.positions[mesh.indices[2]];
  CHECK(cross(b - a, c - a).z > 0);
  CHECK(mesh.normals[0].z == Approx(1));
}

TEST_CASE("explicit normals transform by the inverse transpose", "[io][gltf][quick]") {
  GltfWriter w;
  const std::vector<float> n{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const int pos = w.positions(test::quad_positions());
  const int nrm = w.accessor(n.data(), n.size() * 4, 5126, 4, "VEC3");
  w.j["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", pos}, {"NORMAL", nrm}}}}}}});
  const double s = std::sqrt(0.5);
  w.node({{"mesh", 0}, {"rotation", {s, 0, 0, s}}, {"scale", {1, 5, 1}}});  // 90 deg about +x
  const LoadedScene l = write_and_load(w, "normals");
  const Vec3f nn = l.scene.meshes.at(0).normals[0];
  CHECK(nn.y == Approx(-1));  // +z rotated 90 degrees about +x is -y; unit length despite scale
  CHECK(length(nn) == Approx(1));
}

TEST_CASE("cameras and punctual lights are placed by their nodes", "[io][gltf][quick]") {
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()))}});
  w.j["cameras"] = {
      {{"type", "perspective"},
       {"name", "persp"},
       {"perspective", {{"yfov", 0.7}, {"znear", 0.1}, {"aspectRatio", 2.0}}}},
      {{"type", "orthographic"}, {"orthographic", {{"xmag", 3}, {"ymag", 1.5}, {"znear", 0}, {"zfar", 50}}}}};
  w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  w.node({{"camera", 1}, {"translation", {1, 2, 3}}});
  w.j["extensionsUsed"] = {"KHR_lights_punctual"};
  w.j["extensions"] = {{"KHR_lights_punctual",
                        {{"lights",
                          {{{"type", "spot"},
                            {"intensity", 20},
                            {"range", 9},
                            {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}},
                           {{"type", "directional"}, {"color", {1, 0.5, 0.25}}}}}}}};
  const double s = std::sqrt(0.5);
  w.node({{"translation", {0, 4, 0}},
          {"rotation", {-s, 0, 0, s}},
          {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  w.node({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  const LoadedScene l = write_and_load(w, "camlights");
  REQUIRE(l.scene.cameras.size() == 2);
  const Camera& p = l.scene.cameras[0];
  CHECK(p.name == "persp");
  CHECK(p.projection == Projection::Perspective);
  CHECK(p.yfov == Approx(0.7));
  CHECK(p.aspect == Approx(2));
  CHECK(p.eye.z == Approx(5));
  CHECK(p.w.z == Approx(1));  // looks down -z
  const Camera& o = l.scene.cameras[1];
  CHECK(o.projection == Projection::Orthographic);
  CHECK(o.ymag == Approx(1.5));
  CHECK(o.zfar == Approx(50));
  REQUIRE(l.scene.lights.size() == 2);
  const Light& spot = l.scene.lights[0];
  CHECK(spot.type == LightType::Spot);
  CHECK(spot.position.y == Approx(4));
  CHECK(spot.direction.y == Approx(-1));  // -z rotated -90 degrees about x points down
  CHECK(spot.range == Approx(9));
  CHECK(spot.outer_cone == Approx(0.5));
  CHECK(l.scene.lights[1].type == LightType::Directional);
  CHECK(l.scene.lights[1].color.z == Approx(0.25));
  CHECK(l.info.camera_instances.size() == 2);
}

TEST_CASE("an index beyond the vertex count is an error naming the primitive", "[io][gltf][hostile][quick]") {
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 7}))}});
  REQUIRE_THROWS_WITH(write_and_load(w, "bad-index"),
                      Contains("meshes[0].primitives[0]: index 7 >= vertex count 4"));
}

TEST_CASE("accessors reading past their bufferView are errors", "[io][gltf][hostile][quick]") {
  GltfWriter w;
  const int pos = w.positions(test::quad_positions());
  w.j["accessors"][pos]["count"] = 5;  // 5 x 12 bytes > 48-byte view
  w.node({{"mesh", w.mesh(pos)}});
  REQUIRE_THROWS_WITH(write_and_load(w, "overrun"), Contains("accessors[0]") && Contains("past the end"));
  w.j["accessors"][pos]["count"] = 4;
  w.j["accessors"][pos]["byteOffset"] = uint64_t(18446744073709551000ull);  // offset near 2^64
  REQUIRE_THROWS_AS(write_and_load(w, "overflow"), InputError);
}

TEST_CASE("node cycles and shared children are errors and deep chains load iteratively",
          "[io][gltf][hostile]") {
  {
    GltfWriter w;
    w.node({{"children", {1}}});
    w.node({{"children", {0}}}, false);
    REQUIRE_THROWS_WITH(write_and_load(w, "cycle"), Contains("nodes[0]: is part of a node cycle"));
  }
  {
    GltfWriter w;
    w.node({{"children", {2}}});
    w.node({{"children", {2}}});
    w.node(nlohmann::json::object(), false);
    REQUIRE_THROWS_WITH(write_and_load(w, "two-parents"), Contains("nodes[2]: has more than one parent"));
  }
  {
    GltfWriter w;
    w.j["nodes"] = {{{"children", {1}}}, {{"children", {2}}}, {{"children", {1}}}};
    w.j["scenes"][0]["nodes"] = {0};
    REQUIRE_THROWS_AS(write_and_load(w, "cycle2"), InputError);
  }
  {
    // 200,000 nodes each the child of the previous: a recursive traversal would overflow.
    GltfWriter w;
    const int m = w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}));
    const int n = 200000;
    w.j["nodes"] = nlohmann::json::array();
    for (int i = 0; i < n; ++i) {
      nlohmann::json node = {{"translation", {0, 0, 0.001}}};
      if (i + 1 < n)
        node["children"] = {i + 1};
      else
        node["mesh"] = m;
      w.j["nodes"].push_back(node);
    }
    w.j["scenes"][0]["nodes"] = {0};
    const LoadedScene l = write_and_load(w, "deep-chain");
    REQUIRE(l.scene.meshes.size() == 1);
    CHECK(l.scene.meshes[0].positions[0].z == Approx(200.0).epsilon(1e-3));
  }
}

TEST_CASE("deeply nested JSON is refused before parsing", "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("nesting");
  std::ofstream(dir / "deep.gltf") << "{\"asset\":{\"version\":\"2.0\"},\"extras\":"
                                   << std::string(100000, '[') << std::string(100000, ']') << "}";
  REQUIRE_THROWS_WITH(load_gltf(dir / "deep.gltf"), Contains("nesting deeper than"));
  CHECK(json_nesting_depth(R"({"a":"[[[[","b":[{}]})", 10) == 3);  // brackets in strings ignored
}

TEST_CASE("URIs may not escape the scene folder unless allowed", "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("escape");
  std::filesystem::create_directories(dir / "scene");
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()))}});
  w.write_external(dir / "scene" / "a.gltf", "../outside.bin");
  REQUIRE_THROWS_WITH(load_gltf(dir / "scene" / "a.gltf"), Contains("outside the scene folder"));
  GltfLoadOptions opt;
  opt.allow_external_uris = true;
  CHECK(load_gltf(dir / "scene" / "a.gltf", opt).scene.meshes.size() == 1);
  // Absolute paths and device files are refused too.
  nlohmann::json j = w.j;
  j["buffers"] = {{{"byteLength", 48}, {"uri", "/dev/zero"}}};
  std::ofstream(dir / "scene" / "dev.gltf") << j.dump();
  REQUIRE_THROWS_AS(load_gltf(dir / "scene" / "dev.gltf", opt), InputError);
}

TEST_CASE("NaN positions drop the primitive with a warning", "[io][gltf][hostile][quick]") {
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, std::nanf(""), 1, 0}))}});
  w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
  const LoadedScene l = write_and_load(w, "nan");
  CHECK(l.scene.meshes.size() == 1);
  bool warned = false;
  for (const auto& msg : l.warnings) warned |= msg.find("meshes[0].primitives[0]") != std::string::npos;
  CHECK(warned);
}

TEST_CASE("bad camera and light parameters are errors naming them", "[io][gltf][hostile][quick]") {
  GltfWriter w;
  w.j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.0}, {"znear", 0.1}}}}};
  REQUIRE_THROWS_WITH(write_and_load(w, "cam0"), Contains("cameras[0]") && Contains("yfov"));
  w.j["cameras"] = {
      {{"type", "orthographic"}, {"orthographic", {{"xmag", 1}, {"ymag", -1}, {"znear", 0}, {"zfar", 1}}}}};
  REQUIRE_THROWS_WITH(write_and_load(w, "cam1"), Contains("cameras[0]") && Contains("ymag"));
  w.j.erase("cameras");
  w.node({{"camera", 3}});
  REQUIRE_THROWS_WITH(write_and_load(w, "cam2"), Contains("nodes[0].camera"));
}

TEST_CASE("every primitive mode loads: LINES, LINE_LOOP, LINE_STRIP as segments, POINTS as points",
          "[io][gltf][quick]") {
  // Four vertices 0..3; each mode's segments as (a, b, b) triangles, points as (i, i, i).
  const std::vector<std::pair<int, std::vector<uint32_t>>> modes = {{0, {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3}},
                                                                    {1, {0, 1, 1, 2, 3, 3}},
                                                                    {2, {0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 0, 0}},
                                                                    {3, {0, 1, 1, 1, 2, 2, 2, 3, 3}}};
  for (const auto& [mode, expected] : modes) {
    GltfWriter w;
    w.node({{"mesh", w.mesh(w.positions(test::quad_positions()), -1, mode)}});
    const LoadedScene l = write_and_load(w, "mode" + std::to_string(mode));
    INFO("mode " << mode);
    REQUIRE(l.scene.meshes.size() == 1);
    const Mesh& m = l.scene.meshes[0];
    CHECK(m.points == (mode == 0));
    CHECK(m.lines == (mode != 0));
    CHECK(m.indices == expected);
    CHECK(m.radii.empty());  // sizes come from the render (point_size, line_width)
    CHECK_FALSE(m.file_radii);
    // Without NORMAL they are unlit (glTF 3.7.2.1).
    REQUIRE(m.material >= 0);
    CHECK(l.scene.materials[size_t(m.material)].unlit);
    CHECK(count_triangles(l.scene) == 0);
  }
}

TEST_CASE("point and line widths from PENUMBRA_points and _WIDTH, scaled by the node", "[io][gltf][quick]") {
  GltfWriter w;
  const int mesh = w.mesh(w.positions(test::quad_positions()), -1, 0);
  w.j["meshes"][size_t(mesh)]["primitives"][0]["extensions"] = {{"PENUMBRA_points", {{"width", 0.5}}}};
  w.node({{"mesh", mesh}, {"scale", {2, 2, 2}}});
  LoadedScene l = write_and_load(w, "width");
  REQUIRE(l.scene.meshes.size() == 1);
  CHECK(l.scene.meshes[0].file_radii);
  CHECK(l.scene.meshes[0].radii == std::vector<float>(4, 0.5f));  // half of 0.5, times 2
  const int widths = w.floats({0.1f, 0.2f, 0.3f, 0.4f}, "SCALAR", 1);
  w.j["meshes"][size_t(mesh)]["primitives"][0]["attributes"]["_WIDTH"] = widths;
  l = write_and_load(w, "width_attribute");
  REQUIRE(l.scene.meshes.size() == 1);
  CHECK(l.scene.meshes[0].radii == std::vector<float>{0.1f, 0.2f, 0.3f, 0.4f});
}

TEST_CASE("malformed points and lines are errors naming the primitive", "[io][gltf][hostile][quick]") {
  {  // LINES with an odd count
    GltfWriter w;
    w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}), -1, 1)}});
    REQUIRE_THROWS_WITH(write_and_load(w, "odd"),
                        Contains("meshes[0].primitives[0]") && Contains("LINES with an odd count"));
  }
  for (int mode : {2, 3}) {  // a loop or strip of one vertex
    GltfWriter w;
    w.node({{"mesh", w.mesh(w.positions({0, 0, 0}), -1, mode)}});
    REQUIRE_THROWS_WITH(write_and_load(w, "one" + std::to_string(mode)),
                        Contains("meshes[0].primitives[0]") && Contains("one vertex"));
  }
  {  // POINTS without POSITION
    GltfWriter w;
    w.j["meshes"].push_back({{"primitives", {{{"attributes", nlohmann::json::object()}, {"mode", 0}}}}});
    w.node({{"mesh", 0}});
    REQUIRE_THROWS_WITH(write_and_load(w, "nopos"),
                        Contains("meshes[0].primitives[0]") && Contains("without a POSITION"));
  }
  for (const nlohmann::json& width : {nlohmann::json(0.0), nlohmann::json(-1.0), nlohmann::json("wide")}) {
    GltfWriter w;
    const int mesh = w.mesh(w.positions(test::quad_positions()), -1, 1);
    w.j["meshes"][size_t(mesh)]["primitives"][0]["extensions"] = {{"PENUMBRA_points", {{"width", width}}}};
    w.node({{"mesh", mesh}});
    INFO(width.dump());
    REQUIRE_THROWS_WITH(write_and_load(w, "width"), Contains("PENUMBRA_points.width"));
  }
  {  // an unknown key, a non-positive per-vertex width
    GltfWriter w;
    const int mesh = w.mesh(w.positions(test::quad_positions()), -1, 0);
    w.j["meshes"][size_t(mesh)]["primitives"][0]["extensions"] = {{"PENUMBRA_points", {{"radius", 1}}}};
    w.node({{"mesh", mesh}});
    REQUIRE_THROWS_WITH(write_and_load(w, "key"),
                        Contains("PENUMBRA_points") && Contains("unknown key 'radius'"));
    w.j["meshes"][size_t(mesh)]["primitives"][0].erase("extensions");
    w.j["meshes"][size_t(mesh)]["primitives"][0]["attributes"]["_WIDTH"] =
        w.floats({0.1f, 0.0f, 0.3f, 0.4f}, "SCALAR", 1);
    REQUIRE_THROWS_WITH(write_and_load(w, "vertex_width"),
                        Contains("attributes._WIDTH") && Contains("vertex 1"));
  }
}

TEST_CASE("unknown required extensions fail", "[io][gltf][quick]") {
  GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions(test::quad_positions()), -1, 1)}});
  w.j["extensionsRequired"] = {"EXT_not_a_real_extension"};
  w.j["extensionsUsed"] = {"EXT_not_a_real_extension"};
  REQUIRE_THROWS_WITH(write_and_load(w, "draco"),
                      Contains("extensionsRequired") && Contains("EXT_not_a_real_extension"));
}

TEST_CASE("missing and non-regular files are clear errors", "[io][gltf][hostile][quick]") {
  REQUIRE_THROWS_WITH(load_gltf("/nonexistent/scene.gltf"),
                      Contains("/nonexistent/scene.gltf") && Contains("not found"));
  REQUIRE_THROWS_WITH(load_gltf(test::temp_dir("dir")), Contains("not a regular file"));
  const auto dir = test::temp_dir("garbage");
  std::ofstream(dir / "x.gltf") << "this is not json";
  REQUIRE_THROWS_AS(load_gltf(dir / "x.gltf"), InputError);
  std::ofstream(dir / "x.glb", std::ios::binary) << std::string("glTF\x02\0\0\0\xff\xff\xff\x7f", 12);
  REQUIRE_THROWS_AS(load_gltf(dir / "x.glb"), InputError);
}
