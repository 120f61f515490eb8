// io/gltf_loader against hostile values the glTF 2.0 spec rules out: negative or huge offsets
// and indices, unsorted sparse indices, enum values outside the spec, misplaced or extra GLB
// chunks, URIs refused by policy, FIFOs and the memory budget. Each file is built here; each
// case must end in an InputError naming the file and the element, or in a warning.
#include <OpenImageIO/imageio.h>
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cstring>
#include <fstream>
#include <functional>

#include "support/gltf_writer.h"
#include "io/error.h"
#include "io/gltf/loader.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using nlohmann::json;
using penumbra::test::GltfWriter;
namespace fs = std::filesystem;

namespace {

// The file name and the element, as every InputError from the loader starts.
Catch::Matchers::StdString::ContainsMatcher names(const fs::path& file, const std::string& element) {
  return Contains(file.string() + ": " + element + ":");
}

fs::path write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A one-triangle scene (data URI buffer) whose JSON `edit` then modifies.
template <class Edit>
fs::path triangle_scene(const std::string& test, Edit edit, GltfWriter* writer = nullptr) {
  GltfWriter local;
  GltfWriter& w = writer ? *writer : local;
  w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
  edit(w);
  const auto path = test::temp_dir(test) / "scene.gltf";
  w.write_embedded(path);
  return path;
}

bool has_warning(const LoadedScene& l, const std::string& needle) {
  for (const auto& w : l.warnings)
    if (w.find(needle) != std::string::npos) return true;
  return false;
}

std::vector<uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Appends a chunk to a GLB file and fixes the header's total length.
void append_glb_chunk(const fs::path& path, uint32_t type, const std::vector<uint8_t>& data) {
  std::vector<uint8_t> b = read_bytes(path);
  const uint32_t length = uint32_t(data.size());
  b.insert(b.end(), reinterpret_cast<const uint8_t*>(&length), reinterpret_cast<const uint8_t*>(&length) + 4);
  b.insert(b.end(), reinterpret_cast<const uint8_t*>(&type), reinterpret_cast<const uint8_t*>(&type) + 4);
  b.insert(b.end(), data.begin(), data.end());
  const uint32_t total = uint32_t(b.size());
  std::memcpy(b.data() + 8, &total, 4);
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

uint32_t crc32(const uint8_t* p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

}  // namespace

TEST_CASE("gltf hardening: negative or huge byteOffset and byteStride are errors naming the element",
          "[io][gltf][hostile][quick]") {
  auto edit_and_load = [](const std::string& test, auto edit) {
    return load_gltf(triangle_scene(test, edit));
  };
  // tinygltf reads a negative byteOffset or byteStride as absent (0): checked on the JSON.
  const std::pair<const char*, std::function<void(GltfWriter&)>> cases[] = {
      {"bufferViews[0].byteOffset", [](GltfWriter& w) { w.j["bufferViews"][0]["byteOffset"] = -4; }},
      {"bufferViews[0].byteStride", [](GltfWriter& w) { w.j["bufferViews"][0]["byteStride"] = -12; }},
      {"bufferViews[0].byteStride", [](GltfWriter& w) { w.j["bufferViews"][0]["byteStride"] = 1 << 20; }},
      {"bufferViews[0].byteOffset", [](GltfWriter& w) { w.j["bufferViews"][0]["byteOffset"] = 1e300; }},
      {"accessors[0].byteOffset", [](GltfWriter& w) { w.j["accessors"][0]["byteOffset"] = -12; }},
      {"accessors[0]", [](GltfWriter& w) { w.j["accessors"][0]["byteOffset"] = uint64_t(1) << 62; }},
      {"bufferViews[0]", [](GltfWriter& w) { w.j["bufferViews"][0]["byteOffset"] = uint64_t(1) << 62; }},
  };
  int n = 0;
  for (const auto& [element, edit] : cases) {
    INFO(element);
    const std::string test = "offsets" + std::to_string(n++);
    REQUIRE_THROWS_AS(edit_and_load(test, edit), InputError);
    REQUIRE_THROWS_WITH(edit_and_load(test, edit), names(test::temp_dir(test) / "scene.gltf", element));
  }
  // Sparse byteOffsets are held as int by tinygltf: negative and beyond INT_MAX are refused.
  for (const auto& [part, offset] :
       {std::pair{"indices", int64_t(-1)}, std::pair{"values", int64_t(1) << 40}}) {
    const auto file = triangle_scene("sparse-offset", [&, part = part, offset = offset](GltfWriter& w) {
      const std::vector<uint8_t> idx = {1};
      const std::vector<float> val = {0, 0, 1};
      const int i = w.accessor(idx.data(), 1, 5121, 1, "SCALAR"),
                v = w.accessor(val.data(), 12, 5126, 1, "VEC3");
      json& pos = w.j["accessors"][0];
      pos["sparse"] = {
          {"count", 1},
          {"indices", {{"bufferView", w.j["accessors"][i]["bufferView"]}, {"componentType", 5121}}},
          {"values", {{"bufferView", w.j["accessors"][v]["bufferView"]}}}};
      pos["sparse"][part]["byteOffset"] = offset;
    });
    REQUIRE_THROWS_WITH(load_gltf(file),
                        names(file, std::string("accessors[0].sparse.") + part + ".byteOffset"));
  }
}

TEST_CASE("gltf hardening: index properties beyond int or beyond their array are errors naming the element",
          "[io][gltf][hostile][quick]") {
  const std::pair<const char*, std::function<void(GltfWriter&)>> cases[] = {
      {"bufferViews[0].buffer", [](GltfWriter& w) { w.j["bufferViews"][0]["buffer"] = uint64_t(1) << 40; }},
      {"nodes[0].mesh", [](GltfWriter& w) { w.j["nodes"][0]["mesh"] = uint64_t(1) << 62; }},
      {"nodes[0].mesh", [](GltfWriter& w) { w.j["nodes"][0]["mesh"] = -2; }},
      {"nodes[0].camera", [](GltfWriter& w) { w.j["nodes"][0]["camera"] = uint64_t(1) << 32; }},
      {"nodes[0].skin", [](GltfWriter& w) { w.j["nodes"][0]["skin"] = 0; }},
      {"nodes[0].children[0]", [](GltfWriter& w) { w.j["nodes"][0]["children"] = {int64_t(1) << 33}; }},
      {"accessors[0].bufferView", [](GltfWriter& w) { w.j["accessors"][0]["bufferView"] = 4294967296ull; }},
      {"meshes[0].primitives[0].attributes.POSITION",
       [](GltfWriter& w) { w.j["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 4294967296ull; }},
      {"meshes[0].primitives[0].indices",
       [](GltfWriter& w) { w.j["meshes"][0]["primitives"][0]["indices"] = 9; }},
      {"meshes[0].primitives[0].material",
       [](GltfWriter& w) { w.j["meshes"][0]["primitives"][0]["material"] = uint64_t(1) << 31; }},
      {"scenes[0].nodes[0]", [](GltfWriter& w) { w.j["scenes"][0]["nodes"] = {uint64_t(1) << 40}; }},
      {"scene", [](GltfWriter& w) { w.j["scene"] = 4294967297ull; }},
      {"textures[0].source",
       [](GltfWriter& w) {
         w.j["textures"] = {{{"source", uint64_t(1) << 31}}};
       }},
      {"textures[0].sampler",
       [](GltfWriter& w) {
         w.j["textures"] = {{{"sampler", 0}}};
       }},
      {"materials[0].pbrMetallicRoughness.baseColorTexture.index",
       [](GltfWriter& w) {
         w.j["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 1ull << 33}}}}}}};
       }},
      {"materials[0].normalTexture.index",
       [](GltfWriter& w) {
         w.j["materials"] = {{{"normalTexture", {{"index", -1}}}}};
       }},
      {"skins[0].joints[0]",
       [](GltfWriter& w) {
         w.j["skins"] = {{{"joints", {uint64_t(1) << 40}}}};
       }},
      {"skins[0].inverseBindMatrices",
       [](GltfWriter& w) {
         w.j["skins"] = {{{"joints", {0}}, {"inverseBindMatrices", 7}}};
       }},
      {"animations[0].channels[0].sampler",
       [](GltfWriter& w) {
         w.j["animations"] = {
             {{"samplers", {{{"input", 0}, {"output", 0}}}},
              {"channels",
               {{{"sampler", uint64_t(1) << 32}, {"target", {{"node", 0}, {"path", "scale"}}}}}}}};
       }},
      {"animations[0].channels[0].target.node",
       [](GltfWriter& w) {
         w.j["animations"] = {
             {{"samplers", {{{"input", 0}, {"output", 0}}}},
              {"channels", {{{"sampler", 0}, {"target", {{"node", 5}, {"path", "scale"}}}}}}}};
       }},
      {"animations[0].samplers[0].output",
       [](GltfWriter& w) {
         w.j["animations"] = {
             {{"samplers", {{{"input", 0}, {"output", uint64_t(1) << 40}}}},
              {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "scale"}}}}}}}};
       }},
  };
  int n = 0;
  for (const auto& [element, edit] : cases) {
    INFO(element);
    const auto file = triangle_scene("indices" + std::to_string(n++), edit);
    REQUIRE_THROWS_WITH(load_gltf(file), names(file, element));
  }
  // The value and the array size are in the message.
  const auto file =
      triangle_scene("index-message", [](GltfWriter& w) { w.j["bufferViews"][0]["buffer"] = 1ull << 40; });
  REQUIRE_THROWS_WITH(load_gltf(file),
                      Contains("bufferViews[0].buffer: index 1099511627776 does not fit a 32-bit integer"));
}

TEST_CASE("gltf hardening: sparse accessor indices must strictly increase", "[io][gltf][hostile][quick]") {
  auto sparse_scene = [](const std::string& test, std::vector<uint8_t> indices) {
    return triangle_scene(test, [&](GltfWriter& w) {
      const std::vector<float> values(indices.size() * 3, 0.5f);
      const int i = w.accessor(indices.data(), indices.size(), 5121, indices.size(), "SCALAR");
      const int v = w.accessor(values.data(), values.size() * 4, 5126, indices.size(), "VEC3");
      w.j["accessors"][0]["sparse"] = {
          {"count", indices.size()},
          {"indices", {{"bufferView", w.j["accessors"][i]["bufferView"]}, {"componentType", 5121}}},
          {"values", {{"bufferView", w.j["accessors"][v]["bufferView"]}}}};
    });
  };
  const LoadedScene ok = load_gltf(sparse_scene("sparse-ok", {0, 2}));
  REQUIRE(ok.scene.meshes.size() == 1);
  CHECK(ok.scene.meshes[0].positions[2].x == 0.5f);
  for (const auto& bad : {std::vector<uint8_t>{2, 1}, std::vector<uint8_t>{1, 1}}) {
    const auto file = sparse_scene("sparse-bad", bad);
    REQUIRE_THROWS_WITH(load_gltf(file),
                        names(file, "accessors[0].sparse.indices") && Contains("strictly increase"));
  }
}

TEST_CASE("gltf hardening: sampler filters and wrap modes outside the spec's enums are errors",
          "[io][gltf][hostile][quick]") {
  const std::pair<const char*, int> cases[] = {
      {"minFilter", 99999}, {"magFilter", 9984}, {"wrapS", 0}, {"wrapT", -33071}};
  for (const auto& [field, value] : cases) {
    const auto file = triangle_scene("sampler", [&, field = field, value = value](GltfWriter& w) {
      w.j["samplers"] = {{{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 10497}, {"wrapT", 33071}}};
      w.j["samplers"][0][field] = value;
    });
    INFO(field);
    REQUIRE_THROWS_WITH(load_gltf(file),
                        names(file, std::string("samplers[0].") + field) && Contains("allowed values"));
  }
  const auto file = triangle_scene("sampler-ok", [](GltfWriter& w) {
    w.j["samplers"] = {{{"magFilter", 9728}, {"minFilter", 9984}, {"wrapS", 33648}, {"wrapT", 33071}}};
  });
  CHECK_NOTHROW(load_gltf(file));
}

TEST_CASE("gltf hardening: extensionsRequired and extensionsUsed must be arrays of strings",
          "[io][gltf][hostile][quick]") {
  for (const char* key : {"extensionsRequired", "extensionsUsed"}) {
    INFO(key);
    const auto file =
        triangle_scene("ext-string", [&](GltfWriter& w) { w.j[key] = "KHR_draco_mesh_compression"; });
    REQUIRE_THROWS_WITH(load_gltf(file), names(file, key) && Contains("must be an array"));
    const auto file2 = triangle_scene("ext-number", [&](GltfWriter& w) {
      w.j[key] = {"KHR_materials_unlit", 7};
    });
    REQUIRE_THROWS_WITH(load_gltf(file2), names(file2, std::string(key) + "[1]"));
  }
}

TEST_CASE("gltf hardening: morph weights must have one entry per morph target",
          "[io][gltf][hostile][quick]") {
  auto morph_scene = [](const std::string& test, json mesh_weights, json node_weights) {
    GltfWriter w;
    return triangle_scene(
        test,
        [&](GltfWriter& g) {
          const int d0 = g.positions({0, 0, 1, 0, 0, 1, 0, 0, 1}),
                    d1 = g.positions({0, 1, 0, 0, 1, 0, 0, 1, 0});
          g.j["meshes"][0]["primitives"][0]["targets"] = {{{"POSITION", d0}}, {{"POSITION", d1}}};
          if (!mesh_weights.is_null()) g.j["meshes"][0]["weights"] = mesh_weights;
          if (!node_weights.is_null()) g.j["nodes"][0]["weights"] = node_weights;
        },
        &w);
  };
  const LoadedScene ok = load_gltf(morph_scene("morph-ok", {0.5, 0.0}, {0.0, 2.0}));
  REQUIRE(ok.scene.meshes.size() == 1);
  CHECK(ok.scene.meshes[0].positions[0].y == Approx(2));  // node weights override the mesh's
  const auto f1 = morph_scene("morph-mesh", {0.5}, nullptr);
  REQUIRE_THROWS_WITH(load_gltf(f1), names(f1, "meshes[0].weights") && Contains("2 morph targets"));
  const auto f2 = morph_scene("morph-node", nullptr, {1, 2, 3});
  REQUIRE_THROWS_WITH(load_gltf(f2), names(f2, "nodes[0].weights") && Contains("has 3 entries"));
  // Primitives of one mesh must agree on the number of targets.
  const auto f3 = triangle_scene("morph-prims", [](GltfWriter& w) {
    const int d = w.positions({0, 0, 1, 0, 0, 1, 0, 0, 1});
    json p = w.j["meshes"][0]["primitives"][0];
    p["targets"] = {{{"POSITION", d}}};
    w.j["meshes"][0]["primitives"].push_back(p);
  });
  REQUIRE_THROWS_WITH(load_gltf(f3), names(f3, "meshes[0].primitives[1].targets"));
}

TEST_CASE("gltf hardening: an unknown animation channel path is an error naming it",
          "[io][gltf][hostile][quick]") {
  auto anim_scene = [](const std::string& test, const std::string& path, json used) {
    return triangle_scene(test, [&](GltfWriter& w) {
      const std::vector<float> t = {0, 1}, s = {1, 1, 1, 2, 2, 2};
      const int in = w.accessor(t.data(), 8, 5126, 2, "SCALAR"),
                out = w.accessor(s.data(), 24, 5126, 2, "VEC3");
      w.j["animations"] = {{{"samplers", {{{"input", in}, {"output", out}}}},
                            {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", path}}}}}}}};
      if (!used.is_null()) w.j["extensionsUsed"] = used;
    });
  };
  const auto bad = anim_scene("anim-path", "opacity", nullptr);
  REQUIRE_THROWS_WITH(load_gltf(bad),
                      names(bad, "animations[0].channels[0].target.path") && Contains("opacity"));
  GltfLoadOptions at1;
  at1.time = 1.0;
  REQUIRE_THROWS_WITH(load_gltf(bad, at1), names(bad, "animations[0].channels[0].target.path"));
  // KHR_animation_pointer's "pointer" path is known when the extension is declared: ignored.
  const LoadedScene ptr = load_gltf(anim_scene("anim-pointer", "pointer", {"KHR_animation_pointer"}), at1);
  CHECK(has_warning(ptr, "animations[0].channels[0].target.path"));
  const LoadedScene scale = load_gltf(anim_scene("anim-scale", "scale", nullptr), at1);
  CHECK(scale.scene.meshes.at(0).positions[1].x == Approx(2));
}

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

TEST_CASE(
    "gltf hardening: the memory budget refuses large JSON, node counts and instance counts before allocating",
    "[io][gltf][hostile][quick]") {
  const auto dir = test::temp_dir("budget");
  {
    // 200 MiB of JSON text (a sparse file: nothing is read beyond its first bytes).
    const auto path = write_text(dir / "big.gltf", "{\"asset\":{\"version\":\"2.0\"},\"extras\":\"");
    fs::resize_file(path, uint64_t(200) << 20);
    GltfLoadOptions opt;
    opt.max_memory_bytes = uint64_t(64) << 20;
    REQUIRE_THROWS_WITH(load_gltf(path, opt),
                        Contains(path.string() + ": the JSON text (200.0 MiB) needs about") &&
                            Contains("GiB parsed, over the 64.0 MiB budget"));
  }
  {
    // 10^6 nodes (3 MB of text) under 256 MiB: refused naming the nodes; 10^4 load within it.
    GltfLoadOptions opt;
    opt.max_memory_bytes = uint64_t(256) << 20;
    for (int n : {1000000, 10000}) {
      std::string text = R"({"asset":{"version":"2.0"},"nodes":[{})";
      for (int i = 1; i < n; ++i) text += ",{}";
      text += "]}";
      const auto path = write_text(dir / ("nodes" + std::to_string(n) + ".gltf"), text);
      if (n == 1000000)
        REQUIRE_THROWS_WITH(load_gltf(path, opt), names(path, "nodes") && Contains("1000000 nodes need") &&
                                                      Contains("over the 256.0 MiB budget"));
      else
        CHECK(load_gltf(path, opt).info.node_count == n);
    }
  }
  {
    // EXT_mesh_gpu_instancing: 10^7 instances from an accessor without a bufferView (all zeros),
    // refused before the translations are decoded.
    const auto path = triangle_scene("budget-instances", [](GltfWriter& w) {
      w.j["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
      w.j["accessors"].push_back({{"componentType", 5126}, {"count", 10000000}, {"type", "VEC3"}});
      w.j["nodes"][0]["extensions"] = {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", 1}}}}}};
    });
    CHECK(fs::file_size(path) < 1024);
    GltfLoadOptions opt;
    opt.max_memory_bytes = uint64_t(3) << 30;
    REQUIRE_THROWS_WITH(
        load_gltf(path, opt),
        Contains(path.string() + ": nodes[0].extensions.EXT_mesh_gpu_instancing: 10000000 instances need ") &&
            Contains("GiB, over the 3.0 GiB budget with the rest of the scene"));
  }
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

  w.j.erase("images");
  w.write_embedded(dir / "embedded.gltf");
  w.write_glb(dir / "packed.glb");
  CHECK(load_gltf(dir / "embedded.gltf").info.source_files == std::vector<fs::path>{dir / "embedded.gltf"});
  CHECK(load_gltf(dir / "packed.glb").info.source_files == std::vector<fs::path>{dir / "packed.glb"});
}
