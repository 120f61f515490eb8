// Tests for io/exr_merge and render windows: crops and farm tiles of a path-traced frame,
// written as EXR data windows and merged, are byte-identical to the whole frame; bad part sets
// (gaps, overlaps, mismatched frames or channels, parts of other scenes or settings, FIFOs and
// devices) are errors naming the part.
#include "io/image/exr_merge.h"

#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>

#include "io/farm/render_settings.h"
#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "io/image/image_output.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "support/fifo_test_util.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {
const std::string kScene = "5ca1ab1e";
const RenderSettings kSettings{{{"camera", "Main"}, {"spp", "4"}, {"width", "40"}}};

// The Penumbra metadata a tile of scene `scene` rendered with `settings` carries.
std::vector<std::pair<std::string, std::string>> tile_metadata(const std::string& scene = kScene,
                                                               const RenderSettings& settings = kSettings) {
  return {{kSceneHashAttribute, scene}, {kSettingsAttribute, canonical_text(settings)}};
}

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
  opt.metadata = tile_metadata();
  write_exr(img.film, path, opt);
}

// A stripe of samples-per-pixel counts with the statistics a path-traced part records.
void write_counted_part(const std::filesystem::path& path, int y0, int y1, uint32_t spp, int passes,
                        float seconds) {
  Film film = make_film(8, y1 - y0);
  film.origin_y = y0;
  film.full_height = 6;
  const uint64_t samples = uint64_t(spp) * 8 * uint64_t(y1 - y0);
  ExrOptions opt;
  opt.metadata = tile_metadata();
  opt.metadata.push_back({kSamplesAttribute, std::to_string(samples)});
  opt.metadata.push_back({kMeanSppAttribute, format_mean_spp(samples, 8 * uint64_t(y1 - y0))});
  opt.metadata.push_back({kPassesAttribute, std::to_string(passes)});
  opt.float_metadata.push_back({kRenderSecondsAttribute, seconds});
  write_exr(film, path, opt);
}

std::string string_metadata(const OIIO::ImageSpec& spec, const char* name) {
  const OIIO::ParamValue* p = spec.find_attribute(name, OIIO::TypeDesc::STRING);
  return p ? p->get_string() : "(none)";
}
}  // namespace

TEST_CASE("merge: sample counts, passes and times add up over the parts", "[io][exr][merge]") {
  const auto dir = test::temp_dir("merge-stats");
  // 8x6 pixels: rows 0-1 at 16 spp in 3 passes, rows 2-5 at 5 spp in 2 passes.
  write_counted_part(dir / "top.exr", 0, 2, 16, 3, 1.5f);
  write_counted_part(dir / "bottom.exr", 2, 6, 5, 2, 0.25f);
  merge_exr_parts({dir / "top.exr", dir / "bottom.exr"}, dir / "frame.exr");
  OIIO::ImageSpec spec;
  native_pixels(dir / "frame.exr", spec);
  CHECK(string_metadata(spec, kSamplesAttribute) == std::to_string(16 * 16 + 5 * 32));
  CHECK(string_metadata(spec, kMeanSppAttribute) == "8.667");  // 416 samples / 48 pixels
  CHECK(string_metadata(spec, kPassesAttribute) == "3");
  CHECK(spec.get_float_attribute(kRenderSecondsAttribute) == 1.75f);
  // A part without them (cut by another tool): the first part's figures would be wrong, so none.
  Film plain = make_film(8, 4);
  plain.origin_y = 2;
  plain.full_height = 6;
  write_exr(plain, dir / "plain.exr", {});
  merge_exr_parts({dir / "top.exr", dir / "plain.exr"}, dir / "forced.exr", {.force = true});
  native_pixels(dir / "forced.exr", spec);
  CHECK(string_metadata(spec, kSamplesAttribute) == "(none)");
  CHECK(string_metadata(spec, kMeanSppAttribute) == "(none)");
  CHECK(string_metadata(spec, kPassesAttribute) == "(none)");
  CHECK(spec.find_attribute(kRenderSecondsAttribute) == nullptr);
}

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
  REQUIRE_THROWS_WITH(merge_exr_parts({dir / "a.exr", dir / "a.exr"}, dir / "x.exr"),
                      Contains("a.exr: overlaps"));
  ExrOptions small;
  small.metadata = tile_metadata();
  write_exr(make_film(8, 8), dir / "small.exr", small);
  REQUIRE_THROWS_WITH(merge_exr_parts({dir / "a.exr", dir / "small.exr"}, dir / "x.exr"),
                      Contains("small.exr: display window"));
  REQUIRE_THROWS_AS(merge_exr_parts({dir / "missing.exr"}, dir / "x.exr"), InputError);
  CHECK_FALSE(std::filesystem::exists(dir / "x.exr"));
  std::filesystem::remove_all(dir);
}

namespace {
// Rows [y0, y1) of a 6x4 frame whose pixel (x, y) holds x + 10 y in every channel, with
// `metadata`.
void write_stripe(const std::filesystem::path& path, int y0, int y1,
                  const std::vector<std::pair<std::string, std::string>>& metadata) {
  Film film = make_film(6, y1 - y0);
  film.origin_y = y0;
  film.full_height = 4;
  for (int y = 0; y < film.height; ++y)
    for (int x = 0; x < 6; ++x)
      for (int c = 0; c < 4; ++c) film.pixel(x, y)[c] = float(x + 10 * (y0 + y));
  ExrOptions opt;
  opt.half = false;
  opt.metadata = metadata;
  write_exr(film, path, opt);
}

std::string merge_error(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out,
                        const MergeOptions& options = {}) {
  try {
    merge_exr_parts(parts, out, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "merged";
}
}  // namespace

TEST_CASE("merge: parts of another scene or other settings are refused naming the part and what differs",
          "[io][exr][merge][quick]") {
  const auto dir = test::temp_dir("merge-identity");
  write_stripe(dir / "top.exr", 0, 2, tile_metadata());
  write_stripe(dir / "bottom.exr", 2, 4, tile_metadata());
  merge_exr_parts({dir / "top.exr", dir / "bottom.exr"}, dir / "ok.exr");
  OIIO::ImageSpec spec;
  const auto merged = native_pixels(dir / "ok.exr", spec);
  REQUIRE(merged.size() == 6 * 4 * 4 * sizeof(float));
  CHECK(reinterpret_cast<const float*>(merged.data())[(3 * 6 + 5) * 4] == 35.0f);
  CHECK(spec.get_string_attribute(kSceneHashAttribute) == kScene);
  CHECK(spec.get_string_attribute(kSettingsAttribute) == canonical_text(kSettings));

  write_stripe(dir / "other-scene.exr", 2, 4, tile_metadata("deadbeef"));
  CHECK_THAT(merge_error({dir / "top.exr", dir / "other-scene.exr"}, dir / "x.exr"),
             Contains("other-scene.exr: is from another scene") && Contains("'deadbeef'") &&
                 Contains("'" + kScene + "'") && Contains("--force"));

  RenderSettings other = kSettings;
  other.entries["spp"] = "64";
  other.entries["seed"] = "3";
  write_stripe(dir / "other-settings.exr", 2, 4, tile_metadata(kScene, other));
  const std::string message = merge_error({dir / "top.exr", dir / "other-settings.exr"}, dir / "x.exr");
  CHECK_THAT(message,
             Contains("other-settings.exr: was rendered with other settings than") && Contains("top.exr"));
  CHECK_THAT(message, Contains("  spp: " + (dir / "top.exr").string() + " '4', " +
                               (dir / "other-settings.exr").string() + " '64'"));
  CHECK_THAT(message, Contains("  seed: ") && Contains("(not set)") && Contains("--force"));
  CHECK_THAT(message, !Contains("camera") && !Contains("width"));

  write_stripe(dir / "broken.exr", 2, 4, {{kSceneHashAttribute, kScene}, {kSettingsAttribute, "spp=4"}});
  CHECK_THAT(merge_error({dir / "top.exr", dir / "broken.exr"}, dir / "x.exr"),
             Contains("broken.exr: penumbra:settings: malformed") && Contains("--force"));

  // With --force the metadata is not compared; the geometric checks still apply.
  merge_exr_parts({dir / "top.exr", dir / "other-scene.exr"}, dir / "forced.exr", MergeOptions{true});
  CHECK_THAT(merge_error({dir / "top.exr", dir / "other-settings.exr", dir / "bottom.exr"}, dir / "x.exr",
                         MergeOptions{true}),
             Contains("bottom.exr: overlaps"));
  CHECK_FALSE(std::filesystem::exists(dir / "x.exr"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("merge: parts without Penumbra metadata are refused, and accepted with force",
          "[io][exr][merge][quick]") {
  const auto dir = test::temp_dir("merge-foreign");
  write_stripe(dir / "top.exr", 0, 2, tile_metadata());
  write_stripe(dir / "foreign.exr", 2, 4, {});
  write_stripe(dir / "no-settings.exr", 2, 4, {{kSceneHashAttribute, kScene}});
  write_stripe(dir / "no-scene.exr", 2, 4, {{kSettingsAttribute, canonical_text(kSettings)}});
  CHECK_THAT(merge_error({dir / "top.exr", dir / "foreign.exr"}, dir / "x.exr"),
             Contains("foreign.exr: has no penumbra:scene_sha256") &&
                 Contains("use --force to merge parts from other tools"));
  CHECK_THAT(merge_error({dir / "foreign.exr", dir / "top.exr"}, dir / "x.exr"),
             Contains("foreign.exr: has no"));
  CHECK_THAT(merge_error({dir / "top.exr", dir / "no-settings.exr"}, dir / "x.exr"),
             Contains("no-settings.exr: has no penumbra:settings"));
  CHECK_THAT(merge_error({dir / "top.exr", dir / "no-scene.exr"}, dir / "x.exr"),
             Contains("no-scene.exr: has no penumbra:scene_sha256"));
  CHECK_FALSE(std::filesystem::exists(dir / "x.exr"));
  merge_exr_parts({dir / "foreign.exr", dir / "top.exr"}, dir / "forced.exr", MergeOptions{.force = true});
  OIIO::ImageSpec spec;
  const auto merged = native_pixels(dir / "forced.exr", spec);
  CHECK(reinterpret_cast<const float*>(merged.data())[(1 * 6 + 2) * 4] == 12.0f);
  CHECK(reinterpret_cast<const float*>(merged.data())[(2 * 6 + 2) * 4] == 22.0f);
  std::filesystem::remove_all(dir);
}

TEST_CASE("merge: /dev/zero, a FIFO, a directory and a non-EXR file among the parts are refused at once",
          "[io][exr][merge][quick]") {
  const auto dir = test::temp_dir("merge-special");
  write_stripe(dir / "top.exr", 0, 2, tile_metadata());
  write_stripe(dir / "bottom.exr", 2, 4, tile_metadata());
  CHECK_THAT(merge_error({dir / "top.exr", "/dev/zero"}, dir / "x.exr"),
             Contains("/dev/zero") && Contains("character device"));
  CHECK_THAT(merge_error({dir / "top.exr", dir}, dir / "x.exr"), Contains("directory"));
  test::make_fifo(dir / "fifo.exr");
  // The FIFO is last: it is refused before the other parts are opened.
  const std::string message = test::message_without_blocking(
      [&] {
        merge_exr_parts({dir / "top.exr", dir / "bottom.exr", dir / "fifo.exr"}, dir / "x.exr");
      },
      dir / "fifo.exr");
  CHECK_THAT(message, Contains("fifo.exr") && Contains("FIFO"));
  std::ofstream(dir / "text.exr") << "not an image";
  CHECK_THAT(merge_error({dir / "top.exr", dir / "text.exr"}, dir / "x.exr"),
             Contains("text.exr: is not an OpenEXR file"));
  CHECK_FALSE(std::filesystem::exists(dir / "x.exr"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("merge: a frame over the memory bound is refused before it is allocated",
          "[io][exr][merge][quick]") {
  const auto dir = test::temp_dir("merge-memory");
  write_stripe(dir / "top.exr", 0, 2, tile_metadata());
  write_stripe(dir / "bottom.exr", 2, 4, tile_metadata());
  MergeOptions tight;
  tight.max_memory_bytes = 6 * 4 * 16 - 1;  // not even the frame's channels fit
  CHECK_THAT(merge_error({dir / "top.exr", dir / "bottom.exr"}, dir / "x.exr", tight),
             Contains("top.exr") && Contains("limit"));
  tight.max_memory_bytes = 1024;  // the frame, its pixel owners and one decoded part
  merge_exr_parts({dir / "top.exr", dir / "bottom.exr"}, dir / "x.exr", tight);
  std::filesystem::remove_all(dir);
}

TEST_CASE("merge: EXR headers claiming more than the file holds are refused before decoding",
          "[io][exr][merge][quick]") {
  const auto dir = test::temp_dir("merge-header");
  const auto attribute = [](const std::string& name, const std::string& type, int32_t size,
                            const std::string& value) {
    std::string a = name + '\0' + type + '\0';
    a.append(reinterpret_cast<const char*>(&size), 4);
    return a + value;
  };
  const std::string start("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  const auto write = [&](const std::string& file, const std::string& bytes) {
    std::ofstream(dir / file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return dir / file;
  };
  const auto huge = write("huge.exr", start + attribute(kSceneHashAttribute, "string", 0x7fffffff, "abc"));
  CHECK_THAT(merge_error({huge}, dir / "x.exr"),
             Contains("huge.exr: invalid OpenEXR header") &&
                 Contains("'penumbra:scene_sha256' claims 2147483647 bytes"));
  const int32_t box[4] = {0, 0, 1 << 30, 3};
  const auto wide = write(
      "wide.exr",
      start + attribute("dataWindow", "box2i", 16, std::string(reinterpret_cast<const char*>(box), 16)) +
          '\0');
  CHECK_THAT(merge_error({wide}, dir / "x.exr"),
             Contains("wide.exr: invalid OpenEXR header: dataWindow of 1073741825x4"));
  const auto long_box =
      write("long-box.exr", start + attribute("displayWindow", "box2i", 24, std::string(24, '\0')) + '\0');
  CHECK_THAT(merge_error({long_box}, dir / "x.exr"),
             Contains("long-box.exr: invalid OpenEXR header: attribute 'displayWindow' of type box2i has 24 "
                      "bytes, not 16"));
  const auto channels =
      write("channels.exr", start + attribute("channels", "chlist", 4, std::string("R\0\0\0")) + '\0');
  CHECK_THAT(merge_error({channels}, dir / "x.exr"),
             Contains("channels.exr: invalid OpenEXR header: attribute 'channels'"));
  const std::string half_r("R\0\1\0\0\0\0\0\0\0\1\0\0\0\1\0\0\0\0", 19);
  std::string unknown_type = half_r, subsampled = half_r;
  unknown_type[2] = 3;
  subsampled[10] = 2;
  const auto channel_type =
      write("type.exr", start + attribute("channels", "chlist", 19, unknown_type) + '\0');
  CHECK_THAT(merge_error({channel_type}, dir / "x.exr"),
             Contains("type.exr: invalid OpenEXR header: attribute "
                      "'channels': channel 'R' has unknown pixel type 3"));
  const auto channel_sampling =
      write("sampling.exr", start + attribute("channels", "chlist", 19, subsampled) + '\0');
  CHECK_THAT(merge_error({channel_sampling}, dir / "x.exr"), Contains("channel 'R' is subsampled"));
  const int32_t preview_size[2] = {60000, 60000};
  const auto preview = write(
      "preview.exr",
      start +
          attribute("preview", "preview", 8, std::string(reinterpret_cast<const char*>(preview_size), 8)) +
          '\0');
  CHECK_THAT(merge_error({preview}, dir / "x.exr"),
             Contains("preview.exr: invalid OpenEXR header: attribute 'preview'"));
  const int32_t string_size = 1 << 30;
  const auto strings = write(
      "strings.exr",
      start +
          attribute("views", "stringvector", 4, std::string(reinterpret_cast<const char*>(&string_size), 4)) +
          '\0');
  CHECK_THAT(merge_error({strings}, dir / "x.exr"),
             Contains("strings.exr: invalid OpenEXR header: attribute 'views'"));
  const auto cut = write("cut.exr", start + "channels");
  CHECK_THAT(merge_error({cut}, dir / "x.exr"), Contains("cut.exr: invalid OpenEXR header: cut off"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("merge: multi-part and tiled stripes pass the header walk and merge", "[io][exr][merge][quick]") {
  const auto dir = test::temp_dir("merge-multipart");
  for (const bool multipart : {true, false})
    for (int y0 : {0, 3}) {
      Film film = make_film(5, 3);
      film.origin_y = y0;
      film.full_height = 6;
      std::vector<float> depth(15, float(y0));
      ExrOptions opt;
      opt.multipart = multipart;
      opt.compression = multipart ? "dwaa" : "piz";
      opt.extra = {{"Z", &depth}};
      opt.metadata = tile_metadata();
      opt.matrix_metadata = {{"worldToCamera", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
      write_exr(film, dir / (std::to_string(multipart) + "-" + std::to_string(y0) + ".exr"), opt);
    }
  merge_exr_parts({dir / "1-0.exr", dir / "1-3.exr"}, dir / "multi.exr");
  merge_exr_parts({dir / "0-0.exr", dir / "0-3.exr"}, dir / "single.exr");
  auto in = OIIO::ImageInput::open((dir / "multi.exr").string());
  REQUIRE(in);
  CHECK(in->seek_subimage(1, 0));
  // A tiled file written by OpenImageIO itself (with --force: no Penumbra metadata).
  OIIO::ImageSpec spec(5, 6, 4, OIIO::TypeDesc::HALF);
  spec.tile_width = spec.tile_height = 4;
  spec.attribute("compression", "zip");
  std::vector<float> px(5 * 6 * 4, 0.5f);
  auto out = OIIO::ImageOutput::create((dir / "tiled.exr").string());
  REQUIRE(out);
  REQUIRE(out->open((dir / "tiled.exr").string(), spec));
  REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
  REQUIRE(out->close());
  merge_exr_parts({dir / "tiled.exr"}, dir / "from-tiles.exr", MergeOptions{true});
  std::filesystem::remove_all(dir);
}
