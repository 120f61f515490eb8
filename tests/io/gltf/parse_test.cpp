// The parse phase (io/gltf/parse.cpp) under the memory budget: large JSON texts, element
// counts and instance counts are refused before anything is allocated for them.
#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/gltf_hostile.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using nlohmann::json;
using penumbra::test::GltfWriter;
using penumbra::test::names;
using penumbra::test::triangle_scene;
using penumbra::test::write_text;
namespace fs = std::filesystem;

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
