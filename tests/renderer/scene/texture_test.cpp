// Tests for renderer/texture: wrap modes, texel filters, the MIP pyramid and level selection
// against analytic footprints.
#include "renderer/scene/texture.h"

#include <catch2/catch.hpp>

using namespace penumbra;

namespace {
// A w x h texture whose red channel is x / (w-1) and green y / (h-1) (a ramp per axis).
Texture ramp(int w, int h, TextureSampler s = {}) {
  std::vector<float> px(size_t(w) * size_t(h) * 4);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = &px[(size_t(y) * size_t(w) + size_t(x)) * 4];
      p[0] = w > 1 ? float(x) / float(w - 1) : 0;
      p[1] = h > 1 ? float(y) / float(h - 1) : 0;
      p[2] = 0.25f;
      p[3] = 1;
    }
  return make_texture("ramp", w, h, px, s);
}
constexpr float kEps = 1.0f / 65535 * 2;  // unorm16 storage
}  // namespace

TEST_CASE("texture: nearest lookup hits texel centres; (0,0) is the image's top-left", "[texture][quick]") {
  TextureSampler s;
  s.mag = TextureFilter::Nearest;
  const Texture t = ramp(4, 2, s);
  // Texel (i, j) covers u in [i/4, (i+1)/4), v in [j/2, (j+1)/2).
  CHECK(sample_texture(t, {0.01f, 0.01f}, -kInfinity).x == Approx(0).margin(kEps));
  CHECK(sample_texture(t, {0.3f, 0.01f}, -kInfinity).x == Approx(1.0 / 3).margin(kEps));
  CHECK(sample_texture(t, {0.99f, 0.99f}, -kInfinity).x == Approx(1).margin(kEps));
  CHECK(sample_texture(t, {0.99f, 0.99f}, -kInfinity).y == Approx(1).margin(kEps));
  CHECK(sample_texture(t, {0.5f, 0.4f}, -kInfinity).y == Approx(0).margin(kEps));  // row 0 = top
}

TEST_CASE("texture: bilinear interpolates between texel centres", "[texture][quick]") {
  TextureSampler s;
  s.wrap_s = s.wrap_t = TextureWrap::ClampToEdge;
  const Texture t = ramp(5, 5, s);
  // Texel centres at (i + 0.5)/5; halfway between centres 1 and 2 (u = 0.4) red = 1.5/4.
  CHECK(sample_texture(t, {0.4f, 0.5f}, 0).x == Approx(1.5 / 4).margin(kEps));
  CHECK(sample_texture(t, {0.5f, 0.5f}, 0).x == Approx(0.5).margin(kEps));
  // Clamp: beyond the edge, the edge texel.
  CHECK(sample_texture(t, {-3.0f, 0.5f}, 0).x == Approx(0).margin(kEps));
  CHECK(sample_texture(t, {7.5f, 0.5f}, 0).x == Approx(1).margin(kEps));
}

TEST_CASE("texture: repeat, clamp and mirrored repeat", "[texture][quick]") {
  for (TextureWrap wrap : {TextureWrap::Repeat, TextureWrap::ClampToEdge, TextureWrap::MirroredRepeat}) {
    TextureSampler s;
    s.mag = TextureFilter::Nearest;
    s.wrap_s = wrap;
    const Texture t = ramp(4, 1, s);
    const float u = 1.1f;  // texel 4 = one past the end
    const float got = sample_texture(t, {u, 0.5f}, -kInfinity).x;
    if (wrap == TextureWrap::Repeat) CHECK(got == Approx(0).margin(kEps));          // texel 0
    if (wrap == TextureWrap::ClampToEdge) CHECK(got == Approx(1).margin(kEps));     // texel 3
    if (wrap == TextureWrap::MirroredRepeat) CHECK(got == Approx(1).margin(kEps));  // texel 3 mirrored
    const float neg = sample_texture(t, {-0.1f, 0.5f}, -kInfinity).x;               // texel -1
    if (wrap == TextureWrap::Repeat) CHECK(neg == Approx(1).margin(kEps));
    if (wrap == TextureWrap::ClampToEdge) CHECK(neg == Approx(0).margin(kEps));
    if (wrap == TextureWrap::MirroredRepeat) CHECK(neg == Approx(0).margin(kEps));
    const float far = sample_texture(t, {1.6f, 0.5f}, -kInfinity).x;                      // texel 6
    if (wrap == TextureWrap::MirroredRepeat) CHECK(far == Approx(1.0 / 3).margin(kEps));  // 6 -> 1
    if (wrap == TextureWrap::Repeat) CHECK(far == Approx(2.0 / 3).margin(kEps));          // 6 -> 2
  }
}

TEST_CASE("texture: the pyramid halves down to 1x1 and each level is the box average", "[texture][quick]") {
  const Texture t = ramp(8, 4);
  REQUIRE(t.levels.size() == 4);  // 8x4, 4x2, 2x1, 1x1
  CHECK(t.levels[1].width == 4);
  CHECK(t.levels[1].height == 2);
  CHECK(t.levels[3].width == 1);
  CHECK(t.levels[3].height == 1);
  // The 1x1 level is the mean of the ramp: red 0.5, green 0.5, blue 0.25.
  const auto& top = t.levels[3].texels;
  CHECK(top[0] / 65535.0 == Approx(0.5).margin(1e-4));
  CHECK(top[1] / 65535.0 == Approx(0.5).margin(1e-4));
  CHECK(top[2] / 65535.0 == Approx(0.25).margin(1e-4));
  CHECK(texture_bytes(t) == texture_bytes_for(8, 4));
  // Odd sizes round up; non-mipmapped textures keep one level.
  CHECK(ramp(5, 3).levels.size() == 4);  // 5x3, 3x2, 2x1, 1x1
  TextureSampler no_mip;
  no_mip.mipmaps = false;
  CHECK(ramp(8, 8, no_mip).levels.size() == 1);
}

TEST_CASE("texture: level of detail is log2 of the footprint in texels", "[texture][quick]") {
  const Texture t = ramp(256, 128);
  // A footprint of 4 texels along u: lod 2; the longer axis decides.
  CHECK(texture_lod(t, {4.0f / 256, 0}, {0, 1.0f / 128}) == Approx(2));
  CHECK(texture_lod(t, {0, 0}, {0, 16.0f / 128}) == Approx(4));
  CHECK(texture_lod(t, {3.0f / 256, 4.0f / 128}, {0, 0}) == Approx(std::log2(5.0)));
  CHECK(texture_lod(t, {0, 0}, {0, 0}) == -kInfinity);
}

TEST_CASE("texture: trilinear lookup blends the two levels around lod", "[texture][quick]") {
  // Checkerboard 2x2 of 0/1 texels: level 0 alternates, level 1 is the uniform mean 0.5.
  std::vector<float> px = {0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 1};
  TextureSampler s;
  s.min = TextureFilter::Nearest;
  const Texture t = make_texture("checker", 2, 2, px, s);
  const Vec2f at{0.25f, 0.25f};  // centre of the black texel
  CHECK(sample_texture(t, at, 0.0001f).x == Approx(0).margin(1e-3));
  CHECK(sample_texture(t, at, 1).x == Approx(0.5).margin(kEps));
  CHECK(sample_texture(t, at, 0.5f).x == Approx(0.25).margin(kEps));
  CHECK(sample_texture(t, at, 9).x == Approx(0.5).margin(kEps));  // clamped to the last level
  TextureSampler nearest_level = s;
  nearest_level.mip = TextureFilter::Nearest;
  const Texture tn = make_texture("checker", 2, 2, px, nearest_level);
  CHECK(sample_texture(tn, at, 0.4f).x == Approx(0).margin(kEps));
  CHECK(sample_texture(tn, at, 0.6f).x == Approx(0.5).margin(kEps));
}

TEST_CASE("texture: NaN or huge coordinates stay inside the image", "[texture][quick]") {
  const Texture t = ramp(4, 4);
  const Vec4f a = sample_texture(t, {std::nanf(""), 1e30f}, std::nanf(""));
  CHECK(std::isfinite(a.x));
  CHECK(std::isfinite(sample_texture(t, {-1e30f, 3e9f}, 2).y));
}

TEST_CASE("texture: sRGB decode matches IEC 61966-2-1", "[texture][quick]") {
  CHECK(srgb_to_linear(0) == 0);
  CHECK(srgb_to_linear(1) == Approx(1));
  CHECK(srgb_to_linear(0.04045f) == Approx(0.04045 / 12.92));
  CHECK(srgb_to_linear(0.5f) == Approx(std::pow((0.5 + 0.055) / 1.055, 2.4)));
}
