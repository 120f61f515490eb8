// Tests for io/exr_merge and render windows: crops and farm tiles of a path-traced frame,
// written as EXR data windows and merged, are byte-identical to the whole frame; bad part sets
// (gaps, overlaps, mismatched frames or channels) are errors naming the part.
#include "io/exr_merge.h"

#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <cstring>

#include "io/error.h"
#include "io/gltf_loader.h"
#include "io/image_output.h"
#include "renderer/render.h"
#include "test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {
// All pixels of an EXR in their native channel types, and its spec.
std::vector<unsigned char> native_pixels(const std::filesystem::path& p, OIIO::ImageSpec& spec) {
  auto in = OIIO::ImageInput::open(p.string());
  REQUIRE(in);
  spec = in->spec();
  std::vector<unsigned char> px(spec.image_bytes(true));
  REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UNKNOWN, px.data()));
  return px;
}

// Renders `window` of the default scene with the path tracer (beauty + sample counts) to `path`.
void render_part(const Scene& s, const Accelerator& accel, const PathLights& lights, PixelWindow window,
                 const std::filesystem::path& path) {
  RenderConfig cfg;
  cfg.width = 40;
  cfg.height = 23;
  cfg.spp = 4;
  cfg.tile_size = 7;
  cfg.adaptive_threshold = 0.1f;
  cfg.adaptive_min_spp = 2;
  cfg.window = window;
  PathImage img = render_path(s, accel, lights, s.cameras.at(0), cfg);
  std::vector<float> samples(img.samples.begin(), img.samples.end());
  ExrOptions opt;
  opt.extra = {{"samples", &samples, ChannelType::Uint}, {"variance", &img.variance}};
  write_exr(img.film, path, opt);
}
}  // namespace

TEST_CASE("merge: tiles and crops reassemble the frame byte for byte", "[io][exr][merge]") {
  const auto dir = test::temp_dir("merge");
  LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  const auto accel = make_scene_accelerator("embree", loaded.scene);
  const AreaLights al = build_area_lights(loaded.scene);
  const Environment env = make_constant_environment({0.1f, 0.1f, 0.1f});
  const PathLights lights{&al, &env};
  render_part(loaded.scene, *accel, lights, {}, dir / "full.exr");
  // Three stripes of uneven height, and a crop plus the L-shaped rest as two more parts.
  render_part(loaded.scene, *accel, lights, {0, 0, 40, 7}, dir / "a.exr");
  render_part(loaded.scene, *accel, lights, {0, 7, 40, 15}, dir / "b.exr");
  render_part(loaded.scene, *accel, lights, {0, 15, 13, 23}, dir / "c.exr");
  render_part(loaded.scene, *accel, lights, {13, 15, 40, 23}, dir / "d.exr");
  OIIO::ImageSpec part_spec;
  native_pixels(dir / "b.exr", part_spec);
  CHECK(part_spec.y == 7);
  CHECK(part_spec.height == 8);
  CHECK(part_spec.full_height == 23);
  merge_exr_parts({dir / "a.exr", dir / "b.exr", dir / "c.exr", dir / "d.exr"}, dir / "merged.exr");
  OIIO::ImageSpec full_spec, merged_spec;
  const auto full = native_pixels(dir / "full.exr", full_spec);
  const auto merged = native_pixels(dir / "merged.exr", merged_spec);
  CHECK(merged_spec.width == 40);
  CHECK(merged_spec.height == 23);
  CHECK(merged_spec.channelnames == full_spec.channelnames);
  REQUIRE(merged.size() == full.size());
  CHECK(std::memcmp(merged.data(), full.data(), full.size()) == 0);

  // Gaps, overlaps and foreign parts are refused, and nothing is written.
  REQUIRE_THROWS_WITH(merge_exr_parts({dir / "a.exr", dir / "c.exr", dir / "d.exr"}, dir / "x.exr"),
                      Contains("pixel 0,7 is missing"));
  REQUIRE_THROWS_WITH(merge_exr_parts({dir / "a.exr", dir / "a.exr"}, dir / "x.exr"), Contains("a.exr: overlaps"));
  write_exr(make_film(8, 8), dir / "small.exr", ExrOptions{});
  REQUIRE_THROWS_WITH(merge_exr_parts({dir / "a.exr", dir / "small.exr"}, dir / "x.exr"), Contains("small.exr: display window"));
  REQUIRE_THROWS_AS(merge_exr_parts({dir / "missing.exr"}, dir / "x.exr"), InputError);
  CHECK_FALSE(std::filesystem::exists(dir / "x.exr"));
  std::filesystem::remove_all(dir);
}
