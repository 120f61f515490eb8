// KHR_gaussian_splatting loading: the attributes as the scene's splat cloud, placed by its node,
// no fallback points, and every check the extension implies, each an
// error naming the accessor or property.
#include "io/gltf/splats.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "io/gltf/loader.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"

using namespace penumbra;
using namespace penumbra::test;
using Catch::Matchers::Contains;

namespace {

constexpr const char* kExt = "KHR_gaussian_splatting";

std::string attr(const char* what) {
  return std::string(kExt) + ":" + what;
}

/// Two splats at (0, 0, 0) and (1, 0, 0), identity rotations, scales 0.1 and 0.2, opacities 0.5
/// and 1, degree-0 colours (1, 0, -1) and (0, 0, 0), in an sRGB display colour space, used by a
/// node translated by (0, 2, 0). `edit` changes the primitive's JSON before it is written.
GltfWriter splat_file(const std::function<void(GltfWriter&, nlohmann::json&)>& edit = {}) {
  GltfWriter w;
  const int pos = w.positions({0, 0, 0, 1, 0, 0});
  nlohmann::json prim = {{"mode", 0}, {"attributes", {{"POSITION", pos}}}};
  prim["attributes"][attr("ROTATION")] = w.floats({0, 0, 0, 1, 0, 0, 0, 1}, "VEC4", 4);
  prim["attributes"][attr("SCALE")] = w.floats({0.1f, 0.1f, 0.1f, 0.2f, 0.2f, 0.2f}, "VEC3", 3);
  prim["attributes"][attr("OPACITY")] = w.floats({0.5f, 1}, "SCALAR", 1);
  prim["attributes"][attr("SH_DEGREE_0_COEF_0")] = w.floats({1, 0, -1, 0, 0, 0}, "VEC3", 3);
  prim["extensions"][kExt] = {{"kernel", "ellipse"}, {"colorSpace", "srgb_rec709_display"}};
  if (edit) edit(w, prim);
  w.j["meshes"].push_back({{"primitives", {prim}}});
  w.j["extensionsUsed"] = {kExt};
  w.node({{"mesh", 0}, {"translation", {0, 2, 0}}});
  return w;
}

}  // namespace

TEST_CASE("splats: a KHR_gaussian_splatting primitive loads as a cloud placed by its node",
          "[gltf][splats][quick]") {
  GltfWriter w = splat_file();
  const LoadedScene l = write_and_load(w, "splats");
  REQUIRE(l.scene.splat_clouds.size() == 1);
  const SplatCloud& c = l.scene.splat_clouds[0];
  CHECK(c.positions.size() == 2);
  CHECK(c.scales[1].y == 0.2f);
  CHECK(c.opacities[0] == 0.5f);
  CHECK(c.sh_degree == 0);
  CHECK(c.color_space == SplatColorSpace::SrgbRec709Display);
  REQUIRE(l.scene.splat_instances.size() == 1);
  CHECK(l.scene.splat_instances[0].to_world.m[1][3] == 2);
  CHECK(l.scene.splat_instances[0].node == 0);
  // Rendered as splats: the extension's fallback points are not made.
  CHECK(l.scene.meshes.empty());
  CHECK(l.scene.instances.empty());
}

TEST_CASE("splats: degrees 1 to 3, quantised rotations normalised, unknown kernels fall back",
          "[gltf][splats][quick]") {
  GltfWriter w = splat_file([](GltfWriter& wr, nlohmann::json& prim) {
    for (int l = 1; l <= 3; ++l)
      for (int n = 0; n < 2 * l + 1; ++n)
        prim["attributes"][attr(("SH_DEGREE_" + std::to_string(l) + "_COEF_" + std::to_string(n)).c_str())] =
            wr.floats({float(l), float(n), 0, 0, 0, 0}, "VEC3", 3);
    // Normalised signed bytes: (0, 0, 127, 127) is a quarter turn about z, of length 1.414 as stored.
    const std::vector<int8_t> q = {0, 0, 127, 127, 0, 0, 0, 127};
    prim["attributes"][attr("ROTATION")] = wr.accessor(q.data(), q.size(), 5120, 2, "VEC4");
    wr.j["accessors"].back()["normalized"] = true;
    prim["extensions"][kExt]["kernel"] = "customShape";
  });
  const LoadedScene l = write_and_load(w, "degrees");
  REQUIRE(l.scene.splat_clouds.size() == 1);
  const SplatCloud& c = l.scene.splat_clouds[0];
  CHECK(c.sh_degree == 3);
  REQUIRE(c.sh.size() == 2 * 16);
  CHECK(c.sh[1].x == 1);   // degree 1, coefficient 0
  CHECK(c.sh[15].y == 6);  // degree 3, coefficient 6
  CHECK(c.rotations[0].z == Approx(std::sqrt(0.5f)));
  CHECK(c.rotations[0].w == Approx(std::sqrt(0.5f)));
  bool warned = false;
  for (const auto& msg : l.warnings) warned |= msg.find("customShape") != std::string::npos;
  CHECK(warned);
}

TEST_CASE("splats: malformed splats are errors naming the accessor and the splat",
          "[gltf][splats][hostile][quick]") {
  struct Case {
    const char* name;
    std::function<void(GltfWriter&, nlohmann::json&)> edit;
    std::vector<std::string> message;
  };
  const std::vector<Case> cases = {
      {"negative scale",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("SCALE")] = w.floats({0.1f, 0.1f, 0.1f, 0.2f, -0.2f, 0.2f}, "VEC3", 3);
       },
       {"attributes." + attr("SCALE") + "[1]", "not a finite number >= 0"}},
      {"opacity",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("OPACITY")] = w.floats({1.5f, 1}, "SCALAR", 1);
       },
       {"attributes." + attr("OPACITY") + "[0]", "not in [0, 1]"}},
      {"quaternion",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("ROTATION")] = w.floats({0, 0, 0, 2, 0, 0, 0, 1}, "VEC4", 4);
       },
       {"attributes." + attr("ROTATION") + "[0]", "unit quaternion"}},
      {"zero quaternion",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("ROTATION")] = w.floats({0, 0, 0, 1, 0, 0, 0, 0}, "VEC4", 4);
       },
       {"attributes." + attr("ROTATION") + "[1]", "unit quaternion"}},
      {"nan sh",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("SH_DEGREE_0_COEF_0")] = w.floats({1, 0, NAN, 0, 0, 0}, "VEC3", 3);
       },
       {"attributes." + attr("SH_DEGREE_0_COEF_0") + "[0]", "NaN"}},
      {"partial degree",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("SH_DEGREE_1_COEF_0")] = w.floats({0, 0, 0, 0, 0, 0}, "VEC3", 3);
         p["attributes"][attr("SH_DEGREE_1_COEF_1")] = w.floats({0, 0, 0, 0, 0, 0}, "VEC3", 3);
       },
       {"degree 1 has 2 of its 3 coefficients"}},
      {"skipped degree",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("SH_DEGREE_2_COEF_0")] = w.floats({0, 0, 0, 0, 0, 0}, "VEC3", 3);
       },
       {attr("SH_DEGREE_2_COEF_0"), "degree 1"}},
      {"no opacity",
       [](GltfWriter&, nlohmann::json& p) { p["attributes"].erase(attr("OPACITY")); },
       {"no " + attr("OPACITY") + " (required)"}},
      {"no colour space",
       [](GltfWriter&, nlohmann::json& p) { p["extensions"][kExt].erase("colorSpace"); },
       {"no colorSpace"}},
      {"unknown colour space",
       [](GltfWriter&, nlohmann::json& p) { p["extensions"][kExt]["colorSpace"] = "acescg"; },
       {"colorSpace", "'acescg' is not known"}},
      {"not points", [](GltfWriter&, nlohmann::json& p) { p["mode"] = 1; }, {"needs POINTS"}},
      {"count",
       [](GltfWriter& w, nlohmann::json& p) {
         p["attributes"][attr("OPACITY")] = w.floats({1}, "SCALAR", 1);
       },
       {"attributes." + attr("OPACITY"), "count differs"}},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    GltfWriter w = splat_file(c.edit);
    try {
      write_and_load(w, "bad");
      FAIL("loaded");
    } catch (const std::exception& e) {
      const std::string what = e.what();
      CHECK_THAT(what, Contains("meshes[0].primitives[0]"));
      for (const std::string& part : c.message) CHECK_THAT(what, Contains(part));
    }
  }
}

TEST_CASE("splats: a cloud on an animated node follows it (posing loads the file anew)",
          "[gltf][splats][animation][quick]") {
  GltfWriter w = splat_file();
  w.channel(0, "translation", {0, 1}, {0, 2, 0, 3, 2, 0}, "VEC3", 3);
  GltfLoadOptions at0;
  at0.time = 0;
  at0.keep_animation = true;
  LoadedScene l = write_and_load(w, "splats_anim", at0);
  REQUIRE(l.animation);
  REQUIRE(l.scene.splat_instances.size() == 1);
  CHECK(l.scene.splat_instances[0].to_world.m[0][3] == 0);
  // Posing cannot move the clouds in place: it declines, and the file loaded at the time moves them.
  CHECK_FALSE(pose_gltf_scene(*l.animation, 1.0, l.scene));
  GltfLoadOptions at1 = at0;
  at1.time = 1;
  const LoadedScene moved = write_and_load(w, "splats_anim1", at1);
  CHECK(moved.scene.splat_instances[0].to_world.m[0][3] == Approx(3));
}
