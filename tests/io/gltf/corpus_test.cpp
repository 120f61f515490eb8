// The glTF loader on the shared corpus of third-party files: valid models load with the
// triangle, camera and light counts the files hold (corpus README and the files' JSON);
// every model using material, compression and texture extensions loads and path traces with
// no warning about an extension Penumbra supports; every invalid file ends in an InputError or
// loads with warnings, never anything else.
#include <catch2/catch.hpp>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"
#include "support/test_util.h"

using namespace penumbra;
namespace fs = std::filesystem;

namespace {
std::vector<fs::path> gltf_files(const fs::path& root) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file() && (e.path().extension() == ".gltf" || e.path().extension() == ".glb"))
      out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}
}  // namespace

TEST_CASE("corpus: valid models load with the expected counts", "[io][corpus][heavy]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  struct Expect {
    const char* file;
    uint64_t triangles;
    size_t cameras, lights;
  };
  const Expect expected[] = {
      {"Box/glTF-Binary/Box.glb", 12, 0, 0},
      {"Box/glTF-Embedded/Box.gltf", 12, 0, 0},
      {"Triangle/glTF/Triangle.gltf", 1, 0, 0},
      {"TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf", 1, 0, 0},
      {"Cameras/glTF/Cameras.gltf", 2, 2, 0},
      {"SimpleMeshes/glTF/SimpleMeshes.gltf", 2, 0, 0},
      {"SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf", 12, 0, 0},
      {"MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf", 16, 0, 0},
      {"LightsPunctualLamp/glTF/LightsPunctualLamp.gltf", 6000, 0, 5},
      {"CornellBox-Vinc3r/glTF/cornellBox-2.80-Eevee-gltf.gltf", 4410, 0, 0},
      {"DamagedHelmet/glTF-Binary/DamagedHelmet.glb", 15452, 0, 0},
      {"Suzanne/glTF/Suzanne.gltf", 3936, 0, 0},
      {"Duck/glTF-Binary/Duck.glb", 4212, 1, 0},
  };
  for (const auto& e : expected) {
    INFO(e.file);
    const LoadedScene l = load_gltf(*corpus / "valid" / e.file);
    CHECK(count_triangles(l.scene) == e.triangles);
    CHECK(l.scene.cameras.size() == e.cameras);
    CHECK(l.scene.lights.size() == e.lights);
  }
  // MultipleScenes: scene 0 and scene 1 hold different nodes.
  const fs::path ms = *corpus / "valid/MultipleScenes/glTF/MultipleScenes.gltf";
  GltfLoadOptions opt;
  opt.scene = 1;
  CHECK(load_gltf(ms).info.scene_count == 2);
  CHECK(count_triangles(load_gltf(ms, opt).scene) > 0);
  opt.scene = 2;
  CHECK_THROWS_AS(load_gltf(ms, opt), InputError);
}

TEST_CASE("corpus: every valid file loads", "[io][corpus]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  for (const auto& f : gltf_files(*corpus / "valid")) {
    INFO(f.string());
    LoadedScene l;
    REQUIRE_NOTHROW(l = load_gltf(f));
    CHECK(count_triangles(l.scene) > 0);
  }
}

TEST_CASE("corpus: every extensions/ model loads and renders with no warning for a supported extension",
          "[io][corpus]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const std::vector<std::string> supported = supported_gltf_extensions();
  const auto files = gltf_files(*corpus / "extensions");
  CHECK(files.size() >= 16);
  for (const auto& f : files) {
    INFO(f.string());
    LoadedScene l;
    REQUIRE_NOTHROW(l = load_gltf(f));
    CHECK(count_triangles(l.scene) > 0);
    // A warning may only concern an extension Penumbra supports in part (and name it).
    for (const auto& w : l.warnings) {
      INFO("warning: " << w);
      bool partial = false;
      for (const auto& [e, missing] : partial_gltf_extensions())
        partial = partial || w.find(e) != std::string::npos;
      CHECK(partial);
    }
    // Every used extension is one Penumbra supports.
    for (const auto& e : l.info.extensions_used)
      CHECK(std::find(supported.begin(), supported.end(), e) != supported.end());
    // A small path-traced image is finite everywhere and not black.
    RenderConfig cfg;
    cfg.width = 32;
    cfg.height = 24;
    cfg.spp = 2;
    const Camera cam = frame_bounds(compute_bounds(l.scene), 32.0f / 24);
    if (l.scene.lights.empty()) l.scene.lights.push_back(default_key_light(cam));
    const auto accel = make_scene_accelerator("embree", l.scene);
    const AreaLights area = build_area_lights(l.scene);
    const Environment env = make_constant_environment({0.5f, 0.5f, 0.5f});
    const PathImage img = render_path(l.scene, *accel, PathLights{&area, &env}, cam, cfg);
    double sum = 0;
    for (float v : img.film.rgba) {
      REQUIRE(std::isfinite(v));
      sum += v;
    }
    CHECK(sum > 0);
  }
}

TEST_CASE("corpus: every invalid file ends in a clear error or warnings, never a crash",
          "[io][corpus][hostile]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  int errors = 0, loaded = 0;
  for (const auto& f : gltf_files(*corpus / "invalid")) {
    INFO(f.string());
    try {
      const LoadedScene l = load_gltf(f);
      ++loaded;
    } catch (const InputError& e) {
      ++errors;
      CHECK(std::string(e.what()).find(f.string()) == 0);  // the message starts with the file
    } catch (const std::exception& e) {
      FAIL("unexpected exception type: " << e.what());
    }
  }
  CHECK(errors > 80);  // most of the corpus is structurally broken
  CHECK(errors + loaded > 150);
}

TEST_CASE("corpus: materials, alpha modes and textures load as the files say",
          "[io][corpus][texture][heavy]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  auto find = [](const Scene& s, const std::string& name) -> const Material& {
    for (const auto& m : s.materials)
      if (m.name == name) return m;
    FAIL("no material " << name);
    return s.materials[0];
  };
  {
    const LoadedScene ls = load_gltf(*corpus / "valid/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb");
    const Scene& s = ls.scene;
    CHECK(s.materials.size() == 6);
    CHECK(find(s, "MatBlend").alpha_mode == AlphaMode::Blend);
    CHECK(find(s, "MatCutoff25").alpha_mode == AlphaMode::Mask);
    CHECK(find(s, "MatCutoff25").alpha_cutoff == Approx(0.25));
    CHECK(find(s, "MatCutoff75").alpha_cutoff == Approx(0.75));
    CHECK(find(s, "MatCutoffDefault").alpha_cutoff == Approx(0.5));
    CHECK(find(s, "MatOpaque").alpha_mode == AlphaMode::Opaque);
    CHECK(find(s, "MatOpaque").double_sided);
    const Material& bed = find(s, "MatBed");
    CHECK_FALSE(bed.double_sided);
    CHECK(bed.base_color_tex.texture >= 0);
    CHECK(bed.normal_tex.texture >= 0);
    CHECK(bed.occlusion_tex.texture >= 0);
    // Texture 1 serves both occlusion and metallic-roughness (both linear): stored once.
    CHECK(bed.metallic_roughness_tex.texture == bed.occlusion_tex.texture);
    // The blend material's texture is the 4-channel PNG: straight alpha, a ramp from 0 to 1.
    const Texture& t = s.textures[size_t(find(s, "MatBlend").base_color_tex.texture)];
    float lo = 1, hi = 0;
    for (size_t i = 3; i < t.levels[0].texels.size(); i += 4) {
      lo = std::min(lo, t.levels[0].texels[i] / 65535.0f);
      hi = std::max(hi, t.levels[0].texels[i] / 65535.0f);
    }
    CHECK(lo == 0);
    CHECK(hi == 1);
    CHECK(ls.info.image_count == 4);
  }
  {
    const LoadedScene ls = load_gltf(*corpus / "valid/DamagedHelmet/glTF-Binary/DamagedHelmet.glb");
    const Material& m = ls.scene.materials.at(0);
    for (const TextureRef* r :
         {&m.base_color_tex, &m.metallic_roughness_tex, &m.normal_tex, &m.occlusion_tex, &m.emissive_tex})
      CHECK(r->texture >= 0);
    CHECK(ls.scene.textures.size() == 5);
    CHECK(ls.scene.textures[0].levels[0].width == 2048);
    CHECK(ls.scene.textures[0].levels.size() == 12);  // 2048 .. 1
    REQUIRE(ls.scene.meshes.size() == 1);
    CHECK(ls.scene.meshes[0].tangents.size() == ls.scene.meshes[0].positions.size());  // generated
  }
  {
    const LoadedScene ls =
        load_gltf(*corpus / "valid/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb");
    float strongest = 0;
    for (const auto& m : ls.scene.materials) strongest = std::max(strongest, max_component(m.emissive));
    CHECK(strongest > 1);  // KHR_materials_emissive_strength scales beyond the [0,1] factor
  }
  {
    const LoadedScene ls = load_gltf(*corpus / "valid/BoxVertexColors/glTF-Binary/BoxVertexColors.glb");
    bool any = false;
    for (const auto& m : ls.scene.meshes) any = any || !m.colors.empty();
    CHECK(any);
  }
}
