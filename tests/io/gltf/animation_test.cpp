// Animation at a time (io/gltf/animation.cpp): node TRS channels (LINEAR, slerp, STEP, CUBICSPLINE),
// morph-target weights, skinning and KHR_animation_pointer channels, on small generated files with
// hand-computed answers; the corpus InterpolationTest against its own keyframes.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/gltf_writer.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using nlohmann::json;

namespace {

/// The world-space mesh a node places (its first instance).
Mesh mesh_of_node(const Scene& s, int node) {
  for (const auto& inst : s.instances)
    if (inst.node == node) return test::world_copy(s, inst);
  FAIL("no mesh for node " << node);
  return {};
}

// A file with one triangle mesh (with a +z morph target) used by several animated nodes, and a
// skinned copy driven by two joints.
std::filesystem::path animated_file() {
  test::GltfWriter w;
  const int pos = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int morph = w.positions({0, 0, 1, 0, 0, 1, 0, 0, 1});
  const int mesh = w.morph_mesh(pos, morph);
  // Skinned mesh: vertex 0 on joint 0, vertex 1 on joint 1, vertex 2 half and half.
  const int skinned =
      w.skinned_mesh(pos, {0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0});

  const int a = w.node({{"mesh", mesh}});                              // 0: translation
  const int b = w.node({{"mesh", mesh}});                              // 1: rotation
  const int c = w.node({{"mesh", mesh}});                              // 2: cubic scale
  const int d = w.node({{"mesh", mesh}, {"translation", {0, 0, 5}}});  // 3: morph weights
  const int e = w.node({{"mesh", mesh}});                              // 4: step translation
  const int j0 = w.node({{"name", "j0"}});                             // 5
  const int j1 = w.node({{"name", "j1"}});                             // 6
  const int sk = w.node({{"mesh", skinned}, {"skin", 0}, {"translation", {10, 0, 0}}});  // 7
  w.j["skins"] = json::array({{{"joints", {j0, j1}}}});
  w.channel(a, "translation", {0, 2}, {0, 0, 0, 4, 0, 0}, "VEC3", 3);
  const float s45 = float(std::sqrt(0.5));
  w.channel(b, "rotation", {0, 1}, {0, 0, 0, 1, 0, 0, s45, s45}, "VEC4", 4);
  // Cubic scale: keys t = 0, 1 with values 1 and 3, out-tangent 0 at the first, in-tangent 0
  // at the second: p(0.5) = 0.5 x 1 + 0.5 x 3 = 2.
  w.channel(c, "scale", {0, 1}, {0, 0, 0, 1, 1, 1, 0, 0, 0, 0, 0, 0, 3, 3, 3, 0, 0, 0}, "VEC3", 3,
            "CUBICSPLINE");
  w.channel(d, "weights", {0, 2}, {0, 1}, "SCALAR", 1);
  w.channel(e, "translation", {0, 1}, {0, 0, 0, 0, 7, 0}, "VEC3", 3, "STEP");
  w.channel(j1, "translation", {0, 1}, {0, 0, 0, 0, 0, 2}, "VEC3", 3);
  (void)sk;
  const auto dir = test::temp_dir("anim");
  w.write_embedded(dir / "anim.gltf");
  return dir / "anim.gltf";
}

GltfLoadOptions at(double t) {
  GltfLoadOptions o;
  o.time = t;
  return o;
}
}  // namespace

TEST_CASE("animation: node channels are evaluated at --time", "[io][animation][quick]") {
  const auto file = animated_file();
  const LoadedScene ls = load_gltf(file, at(0.5));
  const Scene& s = ls.scene;
  // LINEAR translation: (4,0,0) x 0.5/2.
  CHECK(mesh_of_node(s, 0).positions[0].x == Approx(1));
  // Slerp halfway to 90 degrees about z: vertex (1,0,0) -> (cos 45, sin 45, 0).
  CHECK(mesh_of_node(s, 1).positions[1].x == Approx(std::sqrt(0.5)));
  CHECK(mesh_of_node(s, 1).positions[1].y == Approx(std::sqrt(0.5)));
  // CUBICSPLINE scale 2: vertex (1,0,0) -> (2,0,0).
  CHECK(mesh_of_node(s, 2).positions[1].x == Approx(2));
  // Morph weight 0.25 lifts every vertex by 0.25 on top of the node's z = 5.
  CHECK(mesh_of_node(s, 3).positions[0].z == Approx(5.25));
  // STEP holds the first key until t = 1.
  CHECK(mesh_of_node(s, 4).positions[0].y == 0);
  // Skin: joint 1 at z = 1; the node's own translation (10,0,0) is ignored.
  const Mesh& sk = mesh_of_node(s, 7);
  CHECK(sk.positions[0].x == Approx(0));
  CHECK(sk.positions[0].z == Approx(0));
  CHECK(sk.positions[1].z == Approx(1));
  CHECK(sk.positions[2].z == Approx(0.5));
  CHECK(sk.positions[2].y == Approx(1));

  const LoadedScene later = load_gltf(file, at(1.0));
  CHECK(mesh_of_node(later.scene, 4).positions[0].y == Approx(7));  // STEP reaches its second key
  CHECK(mesh_of_node(later.scene, 7).positions[1].z == Approx(2));
  // Past the end every channel holds its last key.
  const LoadedScene end = load_gltf(file, at(50));
  CHECK(mesh_of_node(end.scene, 0).positions[0].x == Approx(4));
  CHECK(mesh_of_node(end.scene, 3).positions[0].z == Approx(6));
  // Without a time: the static pose (node TRS, mesh weights 0).
  const LoadedScene still = load_gltf(file);
  CHECK(mesh_of_node(still.scene, 0).positions[0].x == 0);
  CHECK(mesh_of_node(still.scene, 3).positions[0].z == Approx(5));
}

TEST_CASE("animation: malformed channels are errors naming the animation element", "[io][animation][quick]") {
  const auto dir = test::temp_dir("anim-bad");
  auto expect_error = [&](const std::function<void(test::GltfWriter&, int)>& damage,
                          const std::string& needle) {
    test::GltfWriter w;
    const int n = w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
    damage(w, n);
    w.write_embedded(dir / "bad.gltf");
    try {
      load_gltf(dir / "bad.gltf", at(0.5));
      FAIL("no error for " << needle);
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Catch::Contains(needle));
    }
  };
  expect_error(
      [](test::GltfWriter& w, int n) {
        w.channel(n, "translation", {0, 1}, {0, 0, 0}, "VEC3", 3);
      },
      "animations[0].samplers[0].output");
  expect_error(
      [](test::GltfWriter& w, int n) {
        w.channel(n, "translation", {1, 0}, {0, 0, 0, 1, 1, 1}, "VEC3", 3);
      },
      "non-decreasing");
  expect_error(
      [](test::GltfWriter& w, int n) {
        w.channel(n + 5, "translation", {0, 1}, {0, 0, 0, 1, 1, 1}, "VEC3", 3);
      },
      "animations[0].channels[0].target.node");
  expect_error(
      [](test::GltfWriter& w, int n) {
        w.channel(n, "scale", {0, 1}, {1, 1, 1, 2, 2, 2}, "VEC3", 3, "QUADRATIC");
      },
      "interpolation");
  expect_error([](test::GltfWriter& w, int n) { w.j["nodes"][size_t(n)]["skin"] = 3; }, "nodes[0].skin");
}

TEST_CASE("animation: corpus InterpolationTest matches its keyframes and midpoints",
          "[io][corpus][animation]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("../shared/corpus not found (set PENUMBRA_CORPUS)");
  const auto file = *corpus / "valid/InterpolationTest/glTF-Binary/InterpolationTest.glb";
  // Key times and values below are the file's own animation data (its accessors); each cube's
  // bounds centre is its node's translation, its extent proportional to its scale.
  auto centre_y = [](const LoadedScene& ls, int node) {
    Bounds3f b;
    for (Vec3f p : mesh_of_node(ls.scene, node).positions) b = merge(b, p);
    return b.center().y;
  };
  auto extent_x = [](const LoadedScene& ls, int node) {
    Bounds3f b;
    for (Vec3f p : mesh_of_node(ls.scene, node).positions) b = merge(b, p);
    return b.extent().x;
  };
  const double k0 = 0.0, k1 = 0.4166666567325592, k2 = 0.8333333134651184;
  // "Linear Translation" (node 10): y keys 6.621, 10, 6 at k0, k1, k2.
  CHECK(centre_y(load_gltf(file, at(k1)), 10) == Approx(10).margin(1e-4));
  CHECK(centre_y(load_gltf(file, at((k1 + k2) / 2)), 10) == Approx(8).margin(1e-4));
  // "Step Translation" (node 8): keys at 0, 0.4583, 0.8333 with y 6.665, 10, 6.
  CHECK(centre_y(load_gltf(file, at(0.3)), 8) == Approx(6.665).margin(1e-3));
  CHECK(centre_y(load_gltf(file, at(0.6)), 8) == Approx(10).margin(1e-4));
  // "CubicSpline Translation" (node 9): values 6.64 and 10 with zero tangents: the midpoint
  // of the Hermite curve is their mean.
  CHECK(centre_y(load_gltf(file, at((k0 + k1) / 2)), 9) == Approx((6.64 + 10) / 2).margin(0.01));
  // "Linear Scale" (node 3): scale 1 at 1/24 s, 0.5 at 0.41667 s; halfway 0.75.
  const double s0 = 0.0416666679084301;
  const float full = extent_x(load_gltf(file, at(s0)), 3);
  CHECK(extent_x(load_gltf(file, at((s0 + k1) / 2)), 3) == Approx(0.75 * full).epsilon(1e-4));
  CHECK(extent_x(load_gltf(file, at(k1)), 3) == Approx(0.5 * full).epsilon(1e-4));
}

TEST_CASE("animation: KHR_animation_pointer animates material, light, camera and node properties at --time",
          "[io][animation][quick]") {
  test::GltfWriter w;
  const int mesh = w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  w.j["meshes"][size_t(mesh)]["primitives"][0]["material"] = 0;
  w.j["materials"] = {
      {{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 1}}, {"roughnessFactor", 1.0}}},
       {"extensions", {{"KHR_materials_clearcoat", {{"clearcoatFactor", 0.0}}}}}}};
  w.j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}};
  w.j["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 1.0}}};
  const int n = w.node({{"mesh", mesh}});
  w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  w.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  w.j["extensionsUsed"] = {"KHR_animation_pointer", "KHR_lights_punctual", "KHR_materials_clearcoat"};
  REQUIRE(n == 0);  // the pointers below name nodes[0]
  auto pointer = [&](const std::string& p, const std::vector<float>& values, const char* type, size_t width) {
    w.channel(-1, "pointer", {0, 2}, values, type, width);
    auto& ch = w.j["animations"][0]["channels"].back();
    ch["target"].erase("node");
    ch["target"]["extensions"]["KHR_animation_pointer"]["pointer"] = p;
  };
  pointer("/materials/0/pbrMetallicRoughness/baseColorFactor", {1, 1, 1, 1, 0, 0.5f, 1, 1}, "VEC4", 4);
  pointer("/materials/0/pbrMetallicRoughness/roughnessFactor", {1, 0}, "SCALAR", 1);
  pointer("/materials/0/extensions/KHR_materials_clearcoat/clearcoatFactor", {0, 1}, "SCALAR", 1);
  pointer("/extensions/KHR_lights_punctual/lights/0/intensity", {1, 9}, "SCALAR", 1);
  pointer("/cameras/0/perspective/yfov", {0.5f, 1.0f}, "SCALAR", 1);
  pointer("/nodes/0/translation", {0, 0, 0, 4, 0, 0}, "VEC3", 3);
  const auto dir = test::temp_dir("pointer");
  w.write_embedded(dir / "p.gltf");
  // Halfway (t = 1): every property is the mean of its two keys.
  GltfLoadOptions opt;
  opt.time = 1.0;
  LoadedScene l = load_gltf(dir / "p.gltf", opt);
  CHECK(l.warnings.empty());
  const Material& m = l.scene.materials.at(0);
  CHECK(m.base_color.x == Approx(0.5));
  CHECK(m.base_color.y == Approx(0.75));
  CHECK(m.roughness == Approx(0.5));
  CHECK(m.clearcoat == Approx(0.5));
  REQUIRE(l.scene.lights.size() == 1);
  CHECK(l.scene.lights[0].intensity == Approx(5));
  REQUIRE(l.scene.cameras.size() == 1);
  CHECK(l.scene.cameras[0].yfov == Approx(0.75));
  CHECK(mesh_of_node(l.scene, n).positions[0].x == Approx(2));
  // Without a time the file's static values stand.
  l = load_gltf(dir / "p.gltf");
  CHECK(l.scene.materials.at(0).roughness == 1);
  CHECK(l.scene.lights.at(0).intensity == 1);
  // A property Penumbra does not animate is a warning; an element that does not exist an error.
  pointer("/materials/0/doubleSided", {0, 1}, "SCALAR", 1);
  w.write_embedded(dir / "p.gltf");
  l = load_gltf(dir / "p.gltf", opt);
  REQUIRE(l.warnings.size() == 1);
  CHECK_THAT(l.warnings[0],
             Catch::Contains("KHR_animation_pointer.pointer") && Catch::Contains("doubleSided"));
  w.j["animations"][0]["channels"].back()["target"]["extensions"]["KHR_animation_pointer"]["pointer"] =
      "/materials/3/pbrMetallicRoughness/metallicFactor";
  w.write_embedded(dir / "p.gltf");
  REQUIRE_THROWS_WITH(
      load_gltf(dir / "p.gltf", opt),
      Catch::Contains("animations[0].channels[6].target.extensions.KHR_animation_pointer.pointer") &&
          Catch::Contains("'3'"));
}
