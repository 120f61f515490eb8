// Tests for io/image/exr_denoise: an EXR with the halves layers denoised into a new file whose
// R, G, B are the denoiser's output on exactly the file's halves, with the noisy beauty kept
// (or the reverse), every other channel, the alpha, the window and the parts kept; files
// without the layers, with NaN or infinite values, already denoised or over the memory limit
// are refused naming the file and the element, and nothing is written.
#include "io/image/exr_denoise.h"

#include <OpenImageIO/half.h>
#include <OpenImageIO/imageio.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <map>

#include "io/files/error.h"
#include "io/image/image_output.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {

constexpr int kW = 24, kH = 18;

// A noisy frame: a red/grey albedo edge with independent noise per half, the halves layers in
// float, a Z layer and a half beauty that is the halves' mean.
struct Frame {
  Film film;
  std::vector<float> halves[2][kDenoiseChannelsPerHalf];  // per half, per channel: one float per pixel
  std::vector<float> z;
  DenoiseInput input;
};

Frame make_frame(int origin_x = 0, int origin_y = 0) {
  Frame f;
  f.film = make_film(kW, kH);
  f.film.origin_x = origin_x;
  f.film.origin_y = origin_y;
  f.film.full_width = kW + origin_x;
  f.film.full_height = kH + origin_y;
  const size_t n = size_t(kW) * kH;
  f.input.width = kW;
  f.input.height = kH;
  uint32_t rng = 12345;
  const auto noise = [&] {
    rng = rng * 1664525u + 1013904223u;
    return float(rng >> 8) / float(1 << 24) - 0.5f;
  };
  for (int h = 0; h < 2; ++h) {
    for (auto& ch : f.halves[h]) ch.resize(n);
    f.input.color[h].resize(n * 3);
    f.input.features[h].resize(n * kDenoiseFeatures);
  }
  f.z.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const bool red = int(i % kW) < kW / 2;
    const float albedo[3] = {red ? 0.8f : 0.5f, red ? 0.1f : 0.5f, red ? 0.1f : 0.5f};
    for (int h = 0; h < 2; ++h) {
      float v[kDenoiseChannelsPerHalf];
      for (int c = 0; c < 3; ++c) {
        v[c] = albedo[c] * (1 + noise());
        v[3 + c] = albedo[c];
      }
      v[6] = 0, v[7] = 0, v[8] = 1;
      v[9] = i % 7 == 0 ? std::numeric_limits<float>::infinity() : 3.0f;  // some misses
      for (int k = 0; k < kDenoiseChannelsPerHalf; ++k) {
        f.halves[h][k][i] = v[k];
        if (k < 3)
          f.input.color[h][i * 3 + size_t(k)] = v[k];
        else
          f.input.features[h][i * kDenoiseFeatures + size_t(k - 3)] = v[k];
      }
    }
    for (int c = 0; c < 3; ++c)
      f.film.rgba[i * 4 + size_t(c)] = 0.5f * (f.halves[0][c][i] + f.halves[1][c][i]);
    f.film.rgba[i * 4 + 3] = i % 5 == 0 ? 0.5f : 1.0f;
    f.z[i] = 2.0f + float(i % 3);
  }
  return f;
}

// Writes the frame; `skip` names a halves channel to leave out.
void write_frame(const Frame& f, const std::filesystem::path& path, bool multipart = false,
                 const std::string& skip = "") {
  ExrOptions o;
  o.multipart = multipart;
  o.extra.push_back({"Z", &f.z});
  for (int h = 0; h < 2; ++h)
    for (int k = 0; k < kDenoiseChannelsPerHalf; ++k)
      if (denoise_channel_name(h, k) != skip)
        o.extra.push_back({denoise_channel_name(h, k), &f.halves[h][k]});
  write_exr(f.film, path, o);
}

// Every channel of every part of an EXR by name, as floats, with its window.
struct Channels {
  std::map<std::string, std::vector<float>> values;
  std::map<std::string, OIIO::TypeDesc> types;
  int x = 0, y = 0, parts = 0;
  std::string attribute(const std::string& name) const {
    return attributes.count(name) ? attributes.at(name) : "";
  }
  std::map<std::string, std::string> attributes;
};

Channels read_channels(const std::filesystem::path& p) {
  Channels out;
  auto in = OIIO::ImageInput::open(p.string());
  REQUIRE(in);
  for (int sub = 0; in->seek_subimage(sub, 0); ++sub) {
    const OIIO::ImageSpec& s = in->spec();
    out.x = s.x;
    out.y = s.y;
    out.parts = sub + 1;
    std::vector<float> px(size_t(s.width) * size_t(s.height) * size_t(s.nchannels));
    REQUIRE(in->read_image(sub, 0, 0, s.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    for (int c = 0; c < s.nchannels; ++c) {
      auto& v = out.values[s.channelnames[size_t(c)]];
      for (size_t i = 0; i < size_t(s.width) * size_t(s.height); ++i)
        v.push_back(px[i * size_t(s.nchannels) + size_t(c)]);
      out.types[s.channelnames[size_t(c)]] = s.channelformat(c);
    }
    for (const char* a : {kDenoiserAttribute, kDenoiseMainAttribute})
      if (const OIIO::ParamValue* pv = s.find_attribute(a)) out.attributes[a] = pv->get_string();
  }
  return out;
}

std::string error_of(const std::filesystem::path& in, const std::filesystem::path& out,
                     const ExrDenoiseOptions& o = {}) {
  try {
    (void)denoise_exr(in, out, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_CASE("exr denoise: the denoiser's output on the file's halves, the noisy beauty kept", "[io][denoise]") {
  const auto dir = test::temp_dir("exr-denoise");
  const Frame f = make_frame();
  const std::vector<float> expected = denoise_nfor(f.input, DenoiseConfig{});
  for (const bool multipart : {false, true}) {
    INFO("multipart " << multipart);
    write_frame(f, dir / "in.exr", multipart);
    const Channels before = read_channels(dir / "in.exr");
    const Film main = denoise_exr(dir / "in.exr", dir / "out.exr", {});
    const Channels after = read_channels(dir / "out.exr");
    CHECK(after.parts == before.parts + (multipart ? 1 : 0));
    CHECK(after.attribute(kDenoiserAttribute) == "nfor");
    CHECK(after.attribute(kDenoiseMainAttribute) == "denoised");
    const size_t n = size_t(kW) * kH;
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const char* ch[3] = {"R", "G", "B"};
        // Written as half, like the beauty.
        REQUIRE(after.values.at(ch[c])[i] == float(half(expected[i * 3 + size_t(c)])));
        REQUIRE(main.rgba[i * 4 + size_t(c)] == expected[i * 3 + size_t(c)]);
        REQUIRE(after.values.at(std::string("noisy.") + ch[c])[i] == before.values.at(ch[c])[i]);
      }
    CHECK(after.values.at("A") == before.values.at("A"));
    CHECK(after.values.at("noisy.A") == before.values.at("A"));
    CHECK(after.types.at("noisy.R") == OIIO::TypeDesc::HALF);
    for (const auto& [name, v] : before.values)
      if (name != "R" && name != "G" && name != "B") CHECK(after.values.at(name) == v);
    // The denoised edge is cleaner than the noisy one: less deviation from the albedo's level.
    double err_noisy = 0, err_denoised = 0;
    for (size_t i = 0; i < n; ++i) {
      const float truth = int(i % kW) < kW / 2 ? 0.8f : 0.5f;
      err_noisy += std::pow(before.values.at("R")[i] - truth, 2);
      err_denoised += std::pow(after.values.at("R")[i] - truth, 2);
    }
    CHECK(err_denoised * 4 < err_noisy);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("exr denoise: the noisy beauty as the main layer, crops keep their window", "[io][denoise]") {
  const auto dir = test::temp_dir("exr-denoise-main");
  const Frame f = make_frame(5, 7);
  write_frame(f, dir / "in.exr");
  ExrDenoiseOptions o;
  o.noisy_main = true;
  const Film main = denoise_exr(dir / "in.exr", dir / "out.exr", o);
  const Channels before = read_channels(dir / "in.exr"), after = read_channels(dir / "out.exr");
  CHECK(after.x == 5);
  CHECK(after.y == 7);
  CHECK(main.origin_x == 5);
  CHECK(after.attribute(kDenoiseMainAttribute) == "noisy");
  for (const char* c : {"R", "G", "B", "A"}) CHECK(after.values.at(c) == before.values.at(c));
  const std::vector<float> expected = denoise_nfor(f.input, DenoiseConfig{});
  for (size_t i = 0; i < size_t(kW) * kH; ++i)
    REQUIRE(after.values.at("denoised.G")[i] == float(half(expected[i * 3 + 1])));
  CHECK(after.values.at("denoised.A") == before.values.at("A"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("exr denoise: missing layers, bad values, a denoised file and the memory limit are refused",
          "[io][denoise]") {
  const auto dir = test::temp_dir("exr-denoise-bad");
  const auto out = dir / "out.exr";
  Frame f = make_frame();
  write_frame(f, dir / "no-normal.exr", false, "odd_N.Y");
  CHECK_THAT(error_of(dir / "no-normal.exr", out),
             Contains("no-normal.exr") && Contains("lacks the layers the denoiser needs: odd_N"));
  write_frame(f, dir / "no-colour.exr", true, "even.R");
  CHECK_THAT(error_of(dir / "no-colour.exr", out), Contains("lacks the layers") && Contains("even"));
  Frame nan = f;
  nan.halves[0][1][kW * 2 + 3] = std::nanf("");
  write_frame(nan, dir / "nan.exr");
  CHECK_THAT(error_of(dir / "nan.exr", out), Contains("nan.exr: even.G") && Contains("pixel 3,2"));
  Frame inf = f;
  inf.halves[1][0][5] = std::numeric_limits<float>::infinity();
  write_frame(inf, dir / "inf.exr");
  CHECK_THAT(error_of(dir / "inf.exr", out), Contains("odd.R") && Contains("pixel 5,0"));
  Frame minus_inf = f;
  minus_inf.halves[1][9][6] = -std::numeric_limits<float>::infinity();
  write_frame(minus_inf, dir / "minus-inf.exr");
  CHECK_THAT(error_of(dir / "minus-inf.exr", out), Contains("odd_Z.Z") && Contains("a depth may be +inf"));
  CHECK_FALSE(std::filesystem::exists(out));

  write_frame(f, dir / "good.exr");
  REQUIRE(error_of(dir / "good.exr", dir / "denoised.exr") == "accepted");
  CHECK_THAT(error_of(dir / "denoised.exr", out), Contains("denoised.exr") && Contains("already denoised"));
  ExrDenoiseOptions small;
  small.max_memory_bytes = 1 << 16;
  CHECK_THAT(error_of(dir / "good.exr", out, small), Contains("good.exr") && Contains("limit"));
  std::ofstream(dir / "junk.exr") << "not an image";
  CHECK_THAT(error_of(dir / "junk.exr", out), Contains("junk.exr"));
  CHECK_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

TEST_CASE("exr denoise: through a temporary, the noisy frame is never left behind", "[io][denoise]") {
  const auto dir = test::temp_dir("exr-denoise-through");
  const Frame f = make_frame();
  std::string sha;
  const Film main = denoise_through_file(
      dir / "frame.exr", [&](const std::filesystem::path& noisy) { write_frame(f, noisy); }, {}, &sha);
  CHECK(sha.size() == 64);
  CHECK(main.width == kW);
  write_frame(f, dir / "noisy.exr");
  (void)denoise_exr(dir / "noisy.exr", dir / "direct.exr", {});
  CHECK(read_channels(dir / "frame.exr").values == read_channels(dir / "direct.exr").values);
  // A failing write leaves nothing.
  CHECK_THROWS(denoise_through_file(
      dir / "failed.exr", [&](const std::filesystem::path& noisy) { write_frame(f, noisy, false, "odd.B"); },
      {}));
  size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
  CHECK(files == 3);  // frame, noisy, direct
  std::filesystem::remove_all(dir);
}
