// The raw-JSON checks (io/gltf/json_checks.cpp) and the accessor checks behind them, on files
// built here: negative or huge offsets and strides, indices beyond int or their array, unsorted
// sparse indices, enums outside the spec, extension lists, morph weight counts and animation
// paths. Each case must end in an InputError naming the file and the element, or a warning.
#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/gltf_hostile.h"
#include "support/gltf_writer.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using nlohmann::json;
using penumbra::test::GltfWriter;
using penumbra::test::has_warning;
using penumbra::test::names;
using penumbra::test::triangle_scene;
namespace fs = std::filesystem;

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
  // KHR_animation_pointer's "pointer" path is known when the extension is declared; its target
  // then needs the extension's pointer.
  const auto ptr = anim_scene("anim-pointer", "pointer", {"KHR_animation_pointer"});
  REQUIRE_THROWS_WITH(
      load_gltf(ptr, at1),
      names(ptr, "animations[0].channels[0].target.extensions.KHR_animation_pointer.pointer") &&
          Contains("is required"));
  const LoadedScene scale = load_gltf(anim_scene("anim-scale", "scale", nullptr), at1);
  CHECK(test::world_copy(scale.scene, scale.scene.instances.at(0)).positions[1].x == Approx(2));
}
