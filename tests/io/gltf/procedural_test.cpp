// The PENUMBRA_procedural material extension (io/gltf/procedural.cpp): every field and its
// default, the mapping against its closed form, the extension lists, one test per class of bad
// value (each error names the file, the JSON path, the field and the material), and object space
// following the node of a mesh whether it is moved into world space or instanced.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/files/error.h"
#include "io/gltf/gltf_writer.h"
#include "io/gltf/loader.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/materials/material.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using penumbra::test::GltfWriter;
using json = nlohmann::json;

namespace {

const std::string kExt = "materials[1].extensions.PENUMBRA_procedural";

/// A file with materials "plain" and "marble", the second carrying `ext`, used by a triangle.
LoadedScene load_procedural(json ext, bool required = false) {
  static int n = 0;
  GltfWriter w;
  w.j["materials"] = json::array({{{"name", "plain"}}, {{"name", "marble"}}});
  w.j["materials"][1]["extensions"]["PENUMBRA_procedural"] = std::move(ext);
  w.j["extensionsUsed"] = {"PENUMBRA_procedural"};
  if (required) w.j["extensionsRequired"] = {"PENUMBRA_procedural"};
  const int pos = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int mesh = w.mesh(pos);
  w.j["meshes"][size_t(mesh)]["primitives"][0]["material"] = 1;
  w.node({{"mesh", mesh}});
  return test::write_and_load(w, "procedural-" + std::to_string(n++));
}

const ProceduralTexture& texture_of(const LoadedScene& l) {
  REQUIRE(l.scene.materials.size() == 2);
  REQUIRE(l.scene.materials[0].procedural == -1);
  REQUIRE(l.scene.materials[1].procedural == 0);
  REQUIRE(l.scene.procedurals.size() == 1);
  return l.scene.procedurals[0];
}

std::string error_of(json ext) {
  try {
    load_procedural(std::move(ext));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void require_error(json ext, const std::string& path, const std::string& reason) {
  const std::string e = error_of(std::move(ext));
  INFO(e);
  CHECK_THAT(e, Contains("scene.gltf: " + kExt + path + ": "));
  CHECK_THAT(e, Contains(reason));
  CHECK_THAT(e, Contains("(material 'marble')"));
}

bool near(Vec3f a, Vec3f b, float eps = 1e-5f) {
  return length(a - b) <= eps;
}

/// A file with a 2x2 quad (mesh 0, facing +z) on a root node with `node` fields, its material
/// "bands" of object-space sine bands along X, 0.7 periods per unit, replacing the base colour.
GltfWriter banded_quad(json node) {
  GltfWriter w;
  w.j["materials"] = json::array(
      {{{"name", "bands"},
        {"extensions",
         {{"PENUMBRA_procedural",
           {{"scale", 0.7}, {"pattern", {{"type", "wave"}}}, {"baseColor", {{"compose", "replace"}}}}}}}}});
  const int pos = w.positions({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0});
  const int idx = w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
  const int mesh = w.mesh(pos, idx);
  w.j["meshes"][size_t(mesh)]["primitives"][0]["material"] = 0;
  node["mesh"] = mesh;
  w.node(std::move(node));
  return w;
}

}  // namespace

TEST_CASE("procedural extension: an empty object gives the documented defaults", "[io][procedural][quick]") {
  const LoadedScene l = load_procedural(json::object(), true);
  const ProceduralTexture& t = texture_of(l);
  const ProceduralTexture d;
  CHECK(t.space == ProceduralSpace::Object);
  CHECK(t.texcoord == 0);
  CHECK(t.filter);
  CHECK(is_identity(t.mapping));
  CHECK(t.kind == PatternKind::Noise);
  CHECK(t.seed == 0);
  CHECK(t.table.perm == make_perlin_table(0).perm);
  CHECK(t.fractal.kind == FractalKind::Fbm);
  CHECK(t.fractal.detail == d.fractal.detail);
  CHECK(t.fractal.roughness == d.fractal.roughness);
  CHECK(t.fractal.lacunarity == d.fractal.lacunarity);
  CHECK(t.fractal.distortion == 0);
  CHECK_FALSE(t.drives_base_color);
  CHECK_FALSE(t.roughness.enabled);
  CHECK_FALSE(t.metallic.enabled);
  CHECK_FALSE(t.emission_strength.enabled);
  CHECK(t.bump_height == 0);
}

TEST_CASE("procedural extension: every field of a noise pattern and every output is read",
          "[io][procedural][quick]") {
  const json ext = {
      {"space", "uv"},
      {"texCoord", 1},
      {"translation", {1, 2, 3}},
      {"rotation", {0, 0, 90}},
      {"scale", {2, 3, 4}},
      {"filter", false},
      {"pattern",
       {{"type", "noise"},
        {"seed", 4000000000u},
        {"fractal", "ridged"},
        {"detail", 2.5},
        {"roughness", 0.25},
        {"lacunarity", 3},
        {"offset", 0.75},
        {"gain", 1.5},
        {"distortion", 0.5}}},
      {"baseColor",
       {{"ramp", {{{"position", 0.1}, {"color", {1, 0, 0}}}, {{"position", 0.9}, {"color", {0, 0, 1}}}}},
        {"interpolation", "smoothstep"},
        {"compose", "replace"}}},
      {"roughness", {{"range", {0.2, 0.6}}, {"compose", "replace"}}},
      {"metallic", {{"range", {0.5, 1}}}},
      {"emissiveStrength", {{"range", {0, 20}}, {"compose", "replace"}}},
      {"bump", {{"height", 0.01}}}};
  const LoadedScene l = load_procedural(ext);
  const ProceduralTexture& t = texture_of(l);
  CHECK(t.space == ProceduralSpace::Uv);
  CHECK(t.texcoord == 1);
  CHECK_FALSE(t.filter);
  // translation x Rz(90) x scale: x -> (2x) along +Y, y -> (3y) along -X.
  CHECK(near(apply_point(t.mapping, {1, 0, 0}), {1, 2 + 2, 3}));
  CHECK(near(apply_point(t.mapping, {0, 1, 0}), {1 - 3, 2, 3}));
  CHECK(near(apply_point(t.mapping, {0, 0, 1}), {1, 2, 3 + 4}));
  CHECK(t.seed == 4000000000u);
  CHECK(t.table.perm == make_perlin_table(4000000000u).perm);
  CHECK(t.fractal.kind == FractalKind::Ridged);
  CHECK(t.fractal.detail == 2.5f);
  CHECK(t.fractal.roughness == 0.25f);
  CHECK(t.fractal.lacunarity == 3);
  CHECK(t.fractal.offset == 0.75f);
  CHECK(t.fractal.gain == 1.5f);
  CHECK(t.fractal.distortion == 0.5f);
  REQUIRE(t.drives_base_color);
  REQUIRE(t.base_color.stops.size() == 2);
  CHECK(t.base_color.stops[0].position == Approx(0.1f));
  CHECK(t.base_color.stops[1].color == Vec3f{0, 0, 1});
  CHECK(t.base_color.interpolation == RampInterpolation::Smoothstep);
  CHECK(t.base_color_compose == Compose::Replace);
  CHECK(t.roughness.enabled);
  CHECK(t.roughness.min == Approx(0.2f));
  CHECK(t.roughness.max == Approx(0.6f));
  CHECK(t.roughness.compose == Compose::Replace);
  CHECK(t.metallic.enabled);
  CHECK(t.metallic.compose == Compose::Multiply);
  CHECK(t.emission_strength.max == 20);
  CHECK(t.bump_height == Approx(0.01f));
}

TEST_CASE("procedural extension: voronoi and wave patterns read their own fields",
          "[io][procedural][quick]") {
  {
    const ProceduralTexture t = texture_of(load_procedural({{"space", "world"},
                                                            {"scale", 5},
                                                            {"pattern",
                                                             {{"type", "voronoi"},
                                                              {"feature", "f2-f1"},
                                                              {"metric", "chebyshev"},
                                                              {"randomness", 0.5},
                                                              {"output", "cellRandom"}}},
                                                            {"baseColor", {{"interpolation", "constant"}}}}));
    CHECK(t.space == ProceduralSpace::World);
    CHECK(near(apply_point(t.mapping, {1, 1, 1}), {5, 5, 5}));
    CHECK(t.kind == PatternKind::Voronoi);
    CHECK(t.voronoi.feature == WorleyFeature::F2MinusF1);
    CHECK(t.voronoi.metric == WorleyMetric::Chebyshev);
    CHECK(t.voronoi.randomness == 0.5f);
    CHECK(t.voronoi_output == VoronoiOutput::CellRandom);
    // A base colour without a ramp keeps the default black-to-white ramp.
    CHECK(t.drives_base_color);
    CHECK(t.base_color.stops.size() == 2);
    CHECK(t.base_color.interpolation == RampInterpolation::Constant);
  }
  {
    const ProceduralTexture t = texture_of(load_procedural({{"pattern",
                                                             {{"type", "wave"},
                                                              {"wave", "rings"},
                                                              {"profile", "saw"},
                                                              {"phaseDistortion", 2},
                                                              {"fractal", "turbulence"}}}}));
    CHECK(t.kind == PatternKind::Wave);
    CHECK(t.wave.type == WaveType::Rings);
    CHECK(t.wave.axis == 2);  // rings default to the Z axis
    CHECK(t.wave.profile == WaveProfile::Saw);
    CHECK(t.wave.distortion == 2);
    CHECK(t.fractal.kind == FractalKind::Turbulence);
    const ProceduralTexture b = texture_of(load_procedural({{"pattern", {{"type", "wave"}, {"axis", "y"}}}}));
    CHECK(b.wave.type == WaveType::Bands);
    CHECK(b.wave.axis == 1);
    CHECK(b.wave.profile == WaveProfile::Sine);
  }
}

TEST_CASE("procedural extension: the extension is supported when required", "[io][procedural][quick]") {
  const auto ext = supported_gltf_extensions();
  CHECK(std::find(ext.begin(), ext.end(), "PENUMBRA_procedural") != ext.end());
  CHECK_NOTHROW(load_procedural({{"pattern", {{"type", "voronoi"}}}}, true));
}

TEST_CASE("procedural extension: bad values name the material and the field", "[io][procedural][quick]") {
  require_error({{"colour", 1}}, ".colour", "unknown key");
  require_error("marble", "", "must be an extension object");
  require_error({{"space", "screen"}}, ".space", "'screen' is not one of \"object\", \"world\", \"uv\"");
  require_error({{"texCoord", 1}}, ".texCoord", "applies only to space \"uv\"");
  require_error({{"space", "uv"}, {"texCoord", 2}}, ".texCoord", "must be in [0, 1]");
  require_error({{"scale", 0}}, ".scale", "must be non-zero");
  require_error({{"scale", {1, 0, 1}}}, ".scale[1]", "must be non-zero");
  require_error({{"scale", {1e-39, 1e6, 1e6}}}, ".scale", "must be within [1e-6, 1e6] in magnitude");
  require_error({{"scale", 2e6}}, ".scale", "must be within [1e-6, 1e6] in magnitude");
  require_error({{"translation", {0, 2e6, 0}}}, ".translation", "must be within 1e6 in magnitude");
  require_error({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}, {"scale", 2}}, ".matrix",
                "cannot be given together with scale");
  require_error({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1}}}, ".matrix", "must be affine");
  require_error({{"matrix", {1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}}, ".matrix", "is singular");
  require_error({{"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 3e6, 0, 0, 1}}}, ".matrix",
                "entries must be within 1e6");
  require_error({{"rotation", {0, "90", 0}}}, ".rotation[1]", "must be a number");
  require_error({{"translation", {0, 1e39, 0}}}, ".translation[1]", "beyond the 32-bit float range");
  require_error({{"filter", 1}}, ".filter", "must be true or false");
  require_error({{"pattern", {{"type", "marble"}}}}, ".pattern.type", "is not one of");
  require_error({{"pattern", {{"detail", 20}}}}, ".pattern.detail", "must be in [0, 15] (got 20)");
  require_error({{"pattern", {{"roughness", -1}}}}, ".pattern.roughness", "must be in [0, 1]");
  require_error({{"pattern", {{"lacunarity", 1}}}}, ".pattern.lacunarity", "must be in [1.01, 16]");
  require_error({{"pattern", {{"seed", -3}}}}, ".pattern.seed", "must be an integer in [0, 4294967295]");
  require_error({{"pattern", {{"seed", 1.5}}}}, ".pattern.seed", "must be an integer");
  require_error({{"pattern", {{"type", "noise"}, {"metric", "manhattan"}}}}, ".pattern.metric",
                "does not apply to pattern type \"noise\"");
  require_error({{"pattern", {{"type", "voronoi"}, {"detail", 3}}}}, ".pattern.detail",
                "does not apply to pattern type \"voronoi\"");
  require_error({{"pattern", {{"gain", 2}}}}, ".pattern.gain",
                "applies to \"ridged\" fractal only (this one is \"fbm\")");
  require_error({{"pattern", {{"fractal", "ridged"}, {"distortion", 20}}}}, ".pattern.distortion",
                "must be in [0, 16]");
  require_error({{"pattern", {{"type", "voronoi"}, {"randomness", 2}}}}, ".pattern.randomness",
                "must be in [0, 1]");
  require_error({{"pattern", {{"type", "wave"}, {"axis", "w"}}}}, ".pattern.axis", "is not one of");
  require_error({{"baseColor", {{"ramp", json::array()}}}}, ".baseColor.ramp",
                "must be an array of 1 to 64 stops");
  require_error({{"baseColor", {{"ramp", {{{"position", 0.5}}}}}}}, ".baseColor.ramp[0]",
                "needs a position and a color");
  require_error({{"baseColor", {{"ramp", {{{"position", 0.5}, {"color", {2, 0, 0}}}}}}}},
                ".baseColor.ramp[0].color", "components must be in [0, 1]");
  require_error(
      {{"baseColor",
        {{"ramp", {{{"position", 0.6}, {"color", {1, 0, 0}}}, {{"position", 0.4}, {"color", {0, 1, 0}}}}}}}},
      ".baseColor.ramp[1].position", "must not decrease");
  require_error({{"baseColor", {{"compose", "add"}}}}, ".baseColor.compose",
                "is not one of \"multiply\", \"replace\"");
  require_error({{"roughness", {{"range", {0, 2}}}}}, ".roughness.range", "values must be in [0, 1]");
  require_error({{"metallic", {{"range", {0.5}}}}}, ".metallic.range", "must be an array of 2 numbers");
  require_error({{"emissiveStrength", {{"range", {-1, 2}}}}}, ".emissiveStrength.range[0]", "must be >= 0");
  require_error({{"bump", {{"height", NAN}}}}, ".bump.height", "must be a number");
  require_error({{"bump", {{"depth", 1}}}}, ".bump.depth", "unknown key");
}

TEST_CASE("procedural extension: object space is the node's frame, for flattened and instanced meshes",
          "[io][procedural][quick]") {
  // Sine bands along object X, 0.7 periods per unit, on a 2x2 quad placed by a node that moves
  // it by +3 in x and scales it by 2: at world x the pattern is 0.5 + 0.5 sin(2 pi 0.7 (x - 3) / 2).
  for (bool instanced : {false, true}) {
    GltfWriter w = banded_quad({{"translation", {3, 0, 0}}, {"scale", {2, 2, 2}}});
    if (instanced) w.node({{"mesh", 0}, {"translation", {40, 0, 0}}});
    const LoadedScene l =
        test::write_and_load(w, std::string("procedural-object-") + (instanced ? "i" : "f"));
    REQUIRE(l.scene.instances.size() == (instanced ? 2u : 1u));
    CHECK(l.scene.instances[0].identity == !instanced);
    const auto accel = make_scene_accelerator("embree", l.scene);
    for (float x : {1.4f, 2.2f, 3.3f, 4.5f}) {
      Ray r;
      r.org = {x, 0.3f, 5};
      r.dir = {0, 0, -1};
      Hit h;
      REQUIRE(intersect_visible(l.scene, *accel, r, h, false));
      const MaterialPoint mp = eval_material(l.scene, make_interaction(l.scene, r, h));
      INFO("instanced " << instanced << " x " << x);
      CHECK(mp.base_color.x == Approx(0.5f + 0.5f * std::sin(2 * kPi * 0.7f * (x - 3) / 2)).margin(1e-4));
    }
  }
}

TEST_CASE("procedural extension: write_gltf keeps a flattened mesh's node frame for object space",
          "[io][procedural][writer][quick]") {
  // The quad of the object-space test under a mirroring, scaling node: written and loaded back,
  // the pattern, the positions and which side faces +z are the same.
  GltfWriter w = banded_quad({{"translation", {3, 0, 0}}, {"scale", {-2, 2, 2}}});
  const LoadedScene first = test::write_and_load(w, "procedural-writer-frame");
  const auto dir = test::temp_dir("procedural-writer-frame-out");
  write_gltf(first.scene, dir / "again.gltf");
  const LoadedScene again = load_gltf(dir / "again.gltf");
  REQUIRE(again.scene.meshes.size() == 1);
  const Mesh &a = first.scene.meshes[0], &b = again.scene.meshes[0];
  REQUIRE(a.positions.size() == b.positions.size());
  for (size_t i = 0; i < a.positions.size(); ++i) CHECK(length(a.positions[i] - b.positions[i]) < 1e-5f);
  const auto accel_a = make_scene_accelerator("embree", first.scene);
  const auto accel_b = make_scene_accelerator("embree", again.scene);
  for (float x : {1.4f, 2.2f, 3.3f, 4.5f}) {
    Ray r;
    r.org = {x, 0.3f, 5};
    r.dir = {0, 0, -1};
    Hit ha, hb;
    REQUIRE(intersect_visible(first.scene, *accel_a, r, ha, false));
    REQUIRE(intersect_visible(again.scene, *accel_b, r, hb, false));
    const SurfaceInteraction sa = make_interaction(first.scene, r, ha),
                             sb = make_interaction(again.scene, r, hb);
    CHECK(sa.back_face == sb.back_face);
    CHECK(eval_material(again.scene, sb).base_color.x ==
          Approx(eval_material(first.scene, sa).base_color.x).margin(1e-4));
    CHECK(eval_material(again.scene, sb).base_color.x ==
          Approx(0.5f + 0.5f * std::sin(2 * kPi * 0.7f * (x - 3) / -2)).margin(1e-4));
  }
}
