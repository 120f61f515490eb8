// Tests for io/image_output and io/atomic_file: EXR and PNG round trips through OpenImageIO,
// the OCIO sRGB view, and atomic writes.
#include "io/image/image_output.h"

#include <OpenImageIO/imageio.h>

#include <array>
#include <catch2/catch.hpp>
#include <fstream>

#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "support/test_util.h"

using namespace penumbra;

namespace {
Film ramp(int w, int h) {
  Film f = make_film(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = f.pixel(x, y);
      p[0] = float(x) / float(w);
      p[1] = float(y) / float(h) * 4.0f;  // HDR values above 1
      p[2] = 0.5f;
      p[3] = x < w / 2 ? 1.0f : 0.25f;
    }
  return f;
}

std::vector<float> read_all(const std::filesystem::path& p, OIIO::ImageSpec& spec) {
  auto in = OIIO::ImageInput::open(p.string());
  REQUIRE(in);
  spec = in->spec();
  std::vector<float> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
  REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  return px;
}

size_t files_in(const std::filesystem::path& dir) {
  return size_t(
      std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()));
}
}  // namespace

TEST_CASE("EXR round trip: RGBA channels, size, half and float precision", "[io][image][quick]") {
  const auto dir = test::temp_dir("exr");
  const Film f = ramp(37, 21);
  for (bool half : {true, false}) {
    ExrOptions opt;
    opt.half = half;
    opt.metadata = {{"penumbra:test", "yes"}};
    const auto path = dir / (half ? "h.exr" : "f.exr");
    write_exr(f, path, opt);
    OIIO::ImageSpec spec;
    const auto px = read_all(path, spec);
    CHECK(spec.width == 37);
    CHECK(spec.height == 21);
    REQUIRE(spec.nchannels == 4);
    CHECK(spec.channelnames == std::vector<std::string>{"R", "G", "B", "A"});
    CHECK(spec.alpha_channel == 3);
    CHECK(spec.format == (half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT));
    CHECK(spec.get_string_attribute("penumbra:test") == "yes");
    for (size_t i = 0; i < px.size(); ++i) {
      if (half)
        REQUIRE(px[i] == Approx(f.rgba[i]).epsilon(1e-3).margin(1e-4));
      else
        REQUIRE(px[i] == f.rgba[i]);
    }
  }
  CHECK(files_in(dir) == 2);  // no temporaries left behind
}

TEST_CASE("display PNG: 8-bit RGB through the shipped config's sRGB view", "[io][image][ocio][quick]") {
  const auto dir = test::temp_dir("png");
  Film f = make_film(4, 1);
  const float values[4] = {0.0f, 0.5f, 1.0f, 0.25f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 4; ++c) f.pixel(x, 0)[c] = c == 3 ? 1.0f : values[x];
  DisplayOptions opt;
  write_display_image(f, dir / "a.png", opt);
  OIIO::ImageSpec spec;
  const auto px = read_all(dir / "a.png", spec);
  CHECK(spec.nchannels == 3);
  CHECK(spec.format == OIIO::TypeDesc::UINT8);
  auto srgb = [](double l) { return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1 / 2.4) - 0.055; };
  for (int x = 0; x < 4; ++x)
    CHECK(px[size_t(x) * 3] == Approx(std::round(srgb(values[x]) * 255) / 255).margin(1.0 / 255));
  // +1 stop of exposure makes 0.25 display like 0.5.
  opt.exposure = 1;
  write_display_image(f, dir / "b.png", opt);
  const auto px2 = read_all(dir / "b.png", spec);
  CHECK(px2[9] == Approx(px[3]).margin(1.0 / 255));
}

TEST_CASE("a missing OCIO config or view is an input error and nothing is written",
          "[io][image][ocio][quick]") {
  const auto dir = test::temp_dir("ocio-bad");
  const Film f = ramp(4, 4);
  DisplayOptions opt;
  opt.ocio_config = (dir / "nope.ocio").string();
  CHECK_THROWS_AS(write_display_image(f, dir / "x.png", opt), InputError);
  opt.ocio_config.clear();
  opt.view = "No Such View";
  CHECK_THROWS_AS(write_display_image(f, dir / "x.png", opt), InputError);
  CHECK(files_in(dir) == 0);
  // The up-front check: same failures, with the valid choices listed, and a bad extension.
  using Catch::Matchers::Contains;
  CHECK_THROWS_WITH(check_display_output(dir / "x.png", opt),
                    Contains("no view 'No Such View'") && Contains("Standard, Filmic, Raw"));
  opt.view.clear();
  CHECK_NOTHROW(check_display_output(dir / "x.PNG", opt));
  CHECK_NOTHROW(check_display_output(dir / "x.tiff", opt));
  CHECK_THROWS_WITH(check_display_output(dir / "x.bmp", opt),
                    Contains("x.bmp") && Contains("unsupported display image format"));
  opt.display = "P3";
  CHECK_THROWS_WITH(check_display_output(dir / "x.png", opt),
                    Contains("no display 'P3'") && Contains("sRGB"));
  CHECK(files_in(dir) == 0);
}

TEST_CASE("atomic writes leave the old file intact and no temporary on failure", "[io][image][quick]") {
  const auto dir = test::temp_dir("atomic");
  const auto dest = dir / "out.exr";
  std::ofstream(dest) << "previous";
  CHECK_THROWS(write_atomically(dest, [](const std::filesystem::path& temp) {
    std::ofstream(temp) << "half-written";
    throw std::runtime_error("interrupted");
  }));
  std::ifstream in(dest);
  std::string content;
  in >> content;
  CHECK(content == "previous");
  CHECK(files_in(dir) == 1);
  // A write into a folder that does not exist fails without creating anything.
  CHECK_THROWS(write_exr(ramp(2, 2), dir / "missing" / "x.exr", {}));
  CHECK(files_in(dir) == 1);
}

TEST_CASE("EXR AOV channels are written as exact 32-bit floats after R, G, B, A", "[io][exr][aov]") {
  const auto dir = penumbra::test::temp_dir("exr-aov");
  const Film f = ramp(16, 8);
  std::vector<float> nodes(16 * 8), tris(16 * 8);
  for (size_t i = 0; i < nodes.size(); ++i) {
    nodes[i] = float(i) + 4097.0f;  // not representable in half
    tris[i] = float(i % 5);
  }
  ExrOptions opt;
  opt.extra = {{"cost.nodes", &nodes}, {"cost.triangles", &tris}};
  write_exr(f, dir / "aov.exr", opt);
  OIIO::ImageSpec spec;
  const auto px = read_all(dir / "aov.exr", spec);
  REQUIRE(spec.nchannels == 6);
  CHECK(spec.channelnames[4] == "cost.nodes");
  CHECK(spec.channelnames[5] == "cost.triangles");
  CHECK(spec.channelformat(0) == OIIO::TypeDesc::HALF);
  CHECK(spec.channelformat(4) == OIIO::TypeDesc::FLOAT);
  for (size_t i = 0; i < nodes.size(); ++i) {
    REQUIRE(px[i * 6 + 4] == nodes[i]);
    REQUIRE(px[i * 6 + 5] == tris[i]);
  }
  CHECK(px[(3 * 16 + 5) * 6 + 2] == 0.5f);  // the beauty is still there
  std::vector<float> wrong(7);
  opt.extra = {{"bad", &wrong}};
  CHECK_THROWS_WITH(write_exr(f, dir / "bad.exr", opt), Catch::Contains("channel bad does not match"));
  CHECK_FALSE(std::filesystem::exists(dir / "bad.exr"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("heat maps: zero is the ramp's dark end, the maximum its yellow end, a legend below",
          "[io][heatmap]") {
  const auto dir = penumbra::test::temp_dir("heatmap");
  const int w = 100, h = 40;
  std::vector<float> v(size_t(w) * h, 0.0f);
  for (int y = 0; y < h; ++y) v[size_t(y) * w + 99] = 250;  // the last column is the maximum
  v[0] = std::nanf("");                                     // non-finite counts as 0
  write_heatmap(v, w, h, dir / "heat.png", "bvh: nodes");
  OIIO::ImageSpec spec;
  const auto px = read_all(dir / "heat.png", spec);
  CHECK(spec.width == w);
  CHECK(spec.height > h);  // legend strip
  CHECK(spec.nchannels == 3);
  auto at = [&](int x, int y, int c) {
    return std::lround(px[(size_t(y) * size_t(spec.width) + size_t(x)) * 3 + size_t(c)] * 255);
  };
  CHECK(at(10, 10, 0) == 68);  // viridis at 0
  CHECK(at(10, 10, 2) == 84);
  CHECK(at(0, 0, 0) == 68);
  CHECK(at(99, 10, 0) == 253);  // viridis at 1
  CHECK(at(99, 10, 1) == 231);
  // The legend has dark text pixels on white.
  int dark = 0;
  for (int y = h; y < spec.height; ++y)
    for (int x = 0; x < w; ++x) dark += at(x, y, 0) == 0 && at(x, y, 1) == 0 && at(x, y, 2) == 0;
  CHECK(dark > 50);
  CHECK_THROWS(write_heatmap(std::vector<float>(3), w, h, dir / "bad.png", "x"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("EXR layers: strided vectors, uint ids, half colour and matrix metadata round-trip",
          "[io][exr][aov][quick]") {
  const auto dir = penumbra::test::temp_dir("exr-layers");
  const Film f = ramp(8, 4);
  std::vector<float> normal(8 * 4 * 3), ids(8 * 4), albedo(8 * 4 * 3);
  for (size_t i = 0; i < ids.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      normal[i * 3 + size_t(c)] = float(c) - 0.123456789f + float(i);
      albedo[i * 3 + size_t(c)] = 0.25f * float(c);
    }
    ids[i] = float(100000 + i * 7);  // beyond half's integers
  }
  ExrOptions opt;
  for (int c = 0; c < 3; ++c)
    opt.extra.push_back({std::string("N.") + "XYZ"[c], &normal, ChannelType::Float, 3, c});
  for (int c = 0; c < 3; ++c)
    opt.extra.push_back({std::string("albedo.") + "RGB"[c], &albedo, ChannelType::Half, 3, c});
  opt.extra.push_back({"id.object", &ids, ChannelType::Uint});
  const std::array<float, 16> m = {1, 2, 3, 0, 4, 5, 6, 0, 7, 8, 9, 0, 10, 11, 12, 1};
  opt.matrix_metadata.push_back({"worldToCamera", m});
  opt.float_metadata.push_back({"penumbra:near", 0.5f});
  write_exr(f, dir / "layers.exr", opt);
  OIIO::ImageSpec spec;
  const auto px = read_all(dir / "layers.exr", spec);
  auto channel = [&](const std::string& name) {
    const int k = spec.channelindex(name);
    REQUIRE(k >= 0);
    return k;
  };
  const int nx = channel("N.X"), nz = channel("N.Z"), ar = channel("albedo.B"), id = channel("id.object");
  CHECK(spec.channelformat(nx) == OIIO::TypeDesc::FLOAT);
  CHECK(spec.channelformat(ar) == OIIO::TypeDesc::HALF);
  CHECK(spec.channelformat(id) == OIIO::TypeDesc::UINT);
  const size_t nc = size_t(spec.nchannels);
  for (size_t i = 0; i < ids.size(); ++i) {
    REQUIRE(px[i * nc + size_t(nx)] == normal[i * 3]);
    REQUIRE(px[i * nc + size_t(nz)] == normal[i * 3 + 2]);
    REQUIRE(px[i * nc + size_t(ar)] == 0.5f);
  }
  // Integer ids read back raw (a float read would normalise them).
  auto in = OIIO::ImageInput::open((dir / "layers.exr").string());
  REQUIRE(in);
  std::vector<uint32_t> raw(ids.size());
  REQUIRE(in->read_image(0, 0, id, id + 1, OIIO::TypeDesc::UINT, raw.data()));
  for (size_t i = 0; i < ids.size(); ++i) REQUIRE(raw[i] == uint32_t(ids[i]));
  in->close();
  const OIIO::ParamValue* p = spec.find_attribute("worldToCamera");
  REQUIRE(p);
  CHECK(p->type() == OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::MATRIX44));
  const float* got = static_cast<const float*>(p->data());
  for (int k = 0; k < 16; ++k) CHECK(got[k] == m[size_t(k)]);
  CHECK(spec.get_float_attribute("penumbra:near") == 0.5f);
  std::filesystem::remove_all(dir);
}

TEST_CASE("display: the shipped Filmic view rolls highlights off; looks act in scene-linear",
          "[io][image][ocio][quick]") {
  const std::vector<float> values = {0.0f, 0.01f, 0.05f, 0.18f, 0.5f, 1.0f, 2.0f, 4.0f, 16.0f, 64.0f};
  auto through = [&](const std::string& view, const std::string& look) {
    std::vector<float> rgb;
    for (float v : values) rgb.insert(rgb.end(), {v, v, v});
    DisplayOptions opt;
    opt.view = view;
    opt.look = look;
    apply_display_transform(rgb, int(values.size()), 1, opt);
    std::vector<float> g;
    for (size_t i = 0; i < values.size(); ++i) g.push_back(rgb[i * 3 + 1]);
    return g;
  };
  const auto standard = through("Standard", ""), filmic = through("Filmic", "");
  for (size_t i = 1; i < values.size(); ++i) CHECK(filmic[i] >= filmic[i - 1]);  // monotone
  CHECK(standard[6] == Approx(1));  // Standard clips everything above 1 ...
  CHECK(filmic[6] < 0.95f);         // ... Filmic keeps 2, 4 and 16 apart
  CHECK(filmic[8] > filmic[7] + 0.01f);
  CHECK(filmic[3] > 0.25f);  // mid grey stays mid-tone
  CHECK(filmic[3] < 0.55f);
  // Looks: contrast pivots on mid grey; +1 EV equals doubling the input.
  const auto contrast = through("Standard", "High Contrast");
  CHECK(contrast[3] == Approx(standard[3]).margin(1e-4));
  CHECK(contrast[4] > standard[4] + 0.01f);
  CHECK(contrast[2] < standard[2] - 0.01f);
  // Plus 1 EV shows 0.18 as Standard shows 0.36.
  std::vector<float> grey = {0.36f, 0.36f, 0.36f};
  apply_display_transform(grey, 1, 1, DisplayOptions{});
  CHECK(through("Standard", "Plus 1 EV")[3] == Approx(grey[1]).margin(1e-4));
  DisplayOptions bad;
  bad.look = "Bleach";
  CHECK_THROWS_WITH(check_display_output("x.png", bad),
                    Catch::Contains("no look 'Bleach' (available: High Contrast"));
}
