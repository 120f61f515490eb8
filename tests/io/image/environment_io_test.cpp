// Tests for io/environment_io: maps written through OpenImageIO (EXR and Radiance HDR) load with
// their texels where the map convention puts them, scaled and rotated; bad maps are clear errors.
#include "io/image/environment_io.h"

#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <fstream>
#include <limits>

#include "io/files/error.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {
void write_map(const std::filesystem::path& path, int w, int h, const std::vector<float>& rgb) {
  auto out = OIIO::ImageOutput::create(path.string());
  REQUIRE(out);
  REQUIRE(out->open(path.string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT)));
  REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
  out->close();
}
// A 8 x 4 map whose texel (x, y) holds (x + 1, y + 1, 0.5).
std::vector<float> ramp() {
  std::vector<float> v;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) v.insert(v.end(), {float(x + 1), float(y + 1), 0.5f});
  return v;
}
}  // namespace

TEST_CASE("environment maps load from EXR and HDR with intensity and rotation", "[io][environment][quick]") {
  const auto dir = test::temp_dir("envmap");
  for (const char* name : {"sky.exr", "sky.hdr"}) {
    INFO(name);
    write_map(dir / name, 8, 4, ramp());
    const Environment e = load_environment(dir / name, 2, 0);
    REQUIRE(e.width == 8);
    REQUIRE(e.height == 4);
    // The centre of texel (5, 1): u = 5.5 / 8, v = 1.5 / 4.
    const Vec3f d = env_uv_to_direction(e, {5.5f / 8, 1.5f / 4});
    const Vec3f l = env_eval(e, d);
    CHECK(l.x == Approx(12).epsilon(0.01));  // (5 + 1) x 2 (RGBE keeps ~1% precision)
    CHECK(l.y == Approx(4).epsilon(0.01));
    // Rotated by 90 degrees, the same texel is seen a quarter turn further round.
    const Environment r = load_environment(dir / name, 2, 90);
    CHECK(env_eval(r, {d.z, d.y, -d.x}).x == Approx(l.x));
  }
}

TEST_CASE("bad environment maps are errors naming the file", "[io][environment][hostile][quick]") {
  const auto dir = test::temp_dir("envbad");
  REQUIRE_THROWS_WITH(load_environment(dir / "none.exr", 1, 0),
                      Contains("none.exr") && Contains("not found"));
  { std::ofstream(dir / "junk.exr") << "not an image"; }
  REQUIRE_THROWS_AS(load_environment(dir / "junk.exr", 1, 0), InputError);
  std::vector<float> v = ramp();
  v[3 * 9] = std::numeric_limits<float>::quiet_NaN();  // texel (1, 1)
  write_map(dir / "nan.exr", 8, 4, v);
  REQUIRE_THROWS_WITH(load_environment(dir / "nan.exr", 1, 0), Contains("nan.exr") && Contains("pixel 1,1"));
  v[3 * 9] = -1;
  write_map(dir / "neg.exr", 8, 4, v);
  REQUIRE_THROWS_WITH(load_environment(dir / "neg.exr", 1, 0), Contains(">= 0"));
  write_map(dir / "ok.exr", 8, 4, ramp());
  REQUIRE_THROWS_WITH(load_environment(dir / "ok.exr", -1, 0), Contains("env-intensity"));
  // A map beyond the memory budget is refused before its pixels are decoded.
  CHECK(environment_bytes(8, 4, 3) == 8 * 4 * (12 + 20));
  REQUIRE_THROWS_WITH(load_environment(dir / "ok.exr", 1, 0, 512),
                      Contains("ok.exr") && Contains("memory budget"));
  CHECK(load_environment(dir / "ok.exr", 1, 0, 8 * 4 * 32).width == 8);
}
