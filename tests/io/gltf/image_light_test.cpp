// EXT_lights_image_based (io/gltf/image_light.cpp): a scene's image-based light becomes the
// environment, with its faces, RGBD unpacking, intensity and rotation; malformed lights are
// errors naming the element.
#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/gltf_writer.h"
#include "support/image_files.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

// A one-triangle file whose scene uses image-based light 0 over six faces (+X face red, the
// others black; face 0 RGBD with alpha `alpha` if >= 0).
fs::path ibl_file(const fs::path& dir, nlohmann::json light, int alpha = -1) {
  const unsigned char red[3] = {255, 0, 0}, black[3] = {0, 0, 0};
  nlohmann::json images = nlohmann::json::array();
  for (int f = 0; f < 6; ++f) {
    const std::string name = "face" + std::to_string(f) + ".png";
    test::write_flat_image(dir / name, f == 0 ? red : black, f == 0 ? alpha : -1);
    images.push_back({{"uri", name}});
  }
  test::GltfWriter w;
  w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
  w.j["images"] = images;
  light["specularImageSize"] = 4;
  light["irradianceCoefficients"] = nlohmann::json::array();
  if (!light.contains("specularImages")) light["specularImages"] = {{0, 1, 2, 3, 4, 5}};
  w.j["extensions"]["EXT_lights_image_based"]["lights"] = {light};
  w.j["scenes"][0]["extensions"]["EXT_lights_image_based"]["light"] = 0;
  w.j["extensionsUsed"] = {"EXT_lights_image_based"};
  w.write_embedded(dir / "ibl.gltf");
  return dir / "ibl.gltf";
}

}  // namespace

TEST_CASE("EXT_lights_image_based: the scene's light is the environment, unpacked, scaled and turned",
          "[io][gltf][env][quick]") {
  const auto dir = test::temp_dir("ibl");
  LoadedScene l = load_gltf(ibl_file(dir, {{"name", "studio"}, {"intensity", 2.0}}));
  CHECK(l.warnings.empty());
  REQUIRE(l.environment);
  CHECK(l.info.image_light == "studio");
  const Vec3f px = env_eval(*l.environment, {1, 0, 0});
  CHECK(px.x == Approx(2));  // sRGB 255 = linear 1, times the intensity
  CHECK(px.y == 0);
  CHECK(env_eval(*l.environment, {-1, 0, 0}).x == 0);
  // RGBD: a 4-channel face's colour is divided by its alpha (128/255 here).
  l = load_gltf(ibl_file(dir, nlohmann::json::object(), 128));
  CHECK(env_eval(*l.environment, {1, 0, 0}).x == Approx(255.0 / 128).epsilon(1e-3));
  // Rotated by +90 degrees about +Y: the +X face is seen towards -Z.
  l = load_gltf(ibl_file(dir, {{"rotation", {0, 0.7071068, 0, 0.7071068}}}));
  CHECK(env_eval(*l.environment, {0, 0, -1}).x == Approx(1));
  CHECK(env_eval(*l.environment, {1, 0, 0}).x == 0);
}

TEST_CASE("EXT_lights_image_based: malformed lights are errors naming the element",
          "[io][gltf][env][quick]") {
  const auto dir = test::temp_dir("ibl_bad");
  REQUIRE_THROWS_WITH(
      load_gltf(ibl_file(dir, {{"specularImages", {{0, 1, 2}}}})),
      Contains("extensions.EXT_lights_image_based.lights[0].specularImages") && Contains("6"));
  REQUIRE_THROWS_WITH(load_gltf(ibl_file(dir, {{"specularImages", {{0, 1, 2, 3, 4, 9}}}})),
                      Contains("specularImages[0][5]") && Contains("out of range"));
  REQUIRE_THROWS_WITH(load_gltf(ibl_file(dir, {{"intensity", -1}})), Contains("lights[0].intensity"));
  REQUIRE_THROWS_WITH(load_gltf(ibl_file(dir, {{"rotation", {0, 0, 0, 0}}})), Contains("unit quaternion"));
}
