// Tests for renderer/film/cryptomatte: MurmurHash3_x86_32 against its published test vectors
// and the specification's manifest examples, the float conversion's exponent clamp, the
// ranking filter, and coverage on a known scene (edges, Blend layers, thread determinism).
#include "renderer/film/cryptomatte.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>

#include "renderer/integrators/aov.h"
#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

}  // namespace

TEST_CASE("cryptomatte: MurmurHash3_x86_32 matches its reference vectors", "[cryptomatte][quick]") {
  // SMHasher's reference implementation's outputs.
  CHECK(murmur3_32("", 0) == 0u);
  CHECK(murmur3_32("", 1) == 0x514e28b7u);
  CHECK(murmur3_32("", 0xffffffffu) == 0x81f16f39u);
  CHECK(murmur3_32(std::string_view("\0\0\0\0", 4), 0) == 0x2362f9deu);
  CHECK(murmur3_32("aaaa", 0x9747b28cu) == 0x5a97808au);
  CHECK(murmur3_32("aaa", 0x9747b28cu) == 0x283e0130u);
  CHECK(murmur3_32("aa", 0x9747b28cu) == 0x5d211726u);
  CHECK(murmur3_32("a", 0x9747b28cu) == 0x7fa09ea6u);
  CHECK(murmur3_32("Hello, world!", 0x9747b28cu) == 0x24884cbau);
  CHECK(murmur3_32("The quick brown fox jumps over the lazy dog", 0x9747b28cu) == 0x2fa826cdu);
}

TEST_CASE("cryptomatte: ids and manifest hex follow the specification's examples", "[cryptomatte][quick]") {
  // Cryptomatte specification, "Metadata": {"bunny":"13851a76", "default":"42c9679f"},
  // {"bunny_porcelain_mat":"b24b26d4"}.
  CHECK(crypto_hex(crypto_id("bunny")) == "13851a76");
  CHECK(crypto_hex(crypto_id("default")) == "42c9679f");
  CHECK(crypto_hex(crypto_id("bunny_porcelain_mat")) == "b24b26d4");
  // The key is the first 7 hex digits of the layer name's hash.
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08x", murmur3_32("CryptoObject"));
  CHECK(crypto_key("CryptoObject") == std::string(hex, 7));
  CHECK(crypto_key("CryptoObject").size() == 7);
}

TEST_CASE("cryptomatte: the float conversion clamps the exponent and keeps every other bit",
          "[cryptomatte][quick]") {
  for (uint32_t h : {0u, 0x00000001u, 0x007fffffu, 0x80000000u, 0x7f800000u, 0xff800001u, 0x3f800000u,
                     0x12345678u, 0xdeadbeefu}) {
    const float f = crypto_hash_to_float(h);
    CHECK(std::isfinite(f));
    const uint32_t e = (h >> 23) & 0xffu;
    const uint32_t expect = (h & 0x807fffffu) | (e == 0 ? 1u : e == 255 ? 254u : e) << 23;
    CHECK(bits(f) == expect);
    CHECK(f != 0.0f);
  }
}

TEST_CASE("cryptomatte: ranking by coverage, ties by the smaller id, zero padding", "[cryptomatte][quick]") {
  const float a = crypto_id("a"), b = crypto_id("b"), c = crypto_id("c");
  std::vector<float> ids = {b, a, 0, a, c, a, b, 0};  // a 3/8, b 2/8, c 1/8, background 2/8
  float out[8];
  rank_crypto_ids(ids, 3, 8, out);
  CHECK(bits(out[0]) == bits(a));
  CHECK(out[1] == 0.375f);
  CHECK(bits(out[2]) == bits(b));
  CHECK(out[3] == 0.25f);
  CHECK(bits(out[4]) == bits(c));
  CHECK(out[5] == 0.125f);
  CHECK(out[6] == 0);  // depth 3: the fourth rank is padding
  CHECK(out[7] == 0);
  // Depth 1 keeps the largest; equal coverage ranks the smaller id's bits first.
  std::vector<float> tie = {a, b};
  float one[4];
  rank_crypto_ids(tie, 2, 4, one);
  CHECK(bits(one[0]) == std::min(bits(a), bits(b)));
  CHECK(one[1] == 0.5f);
  CHECK(one[3] == 0.5f);
  std::vector<float> none = {0, 0};
  rank_crypto_ids(none, 2, 4, one);
  for (float v : one) CHECK(v == 0);
}

TEST_CASE("cryptomatte: coverage on a known scene: full, an edge fraction, Blend layers, any thread count",
          "[cryptomatte]") {
  // Orthographic view down -z over x in [-2, 2], 16 x 8 pixels of 0.25 units: quad A (node 0)
  // covers x < 0.1 at z = 0 (40% of column 8), quad B (node 1) the rest at z = -1; a Blend quad C
  // of alpha 0.5 (node 2) lies over column 0..3 of rows 0..3 at z = 1.
  Scene s;
  const int opaque = add_material(s, {0.5f, 0.5f, 0.5f}, 0, 1);
  const int glass = add_material(s, {0.5f, 0.5f, 0.5f}, 0, 1);
  s.materials[size_t(glass)].alpha_mode = AlphaMode::Blend;
  s.materials[size_t(glass)].alpha = 0.5f;
  s.instances[size_t(add_quad_z(s, -3, 0.1f, -3, 3, 0, opaque))].node = 0;
  s.instances[size_t(add_quad_z(s, 0.1f, 3, -3, 3, -1, opaque))].node = 1;
  s.instances[size_t(add_quad_z(s, -2, -1, 0, 1, 1, glass))].node = 2;
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 2);
  cam.projection = Projection::Orthographic;
  cam.ymag = 1;
  const auto accel = make_scene_accelerator("embree", s);
  const float ida = crypto_id("A"), idb = crypto_id("B"), idc = crypto_id("C");
  const std::vector<CryptoLayerIds> layers = {{"CryptoObject", {ida, idb, idc}}};
  RenderConfig cfg = small_render_config(16, 8, 64, 4);
  const CryptoImage img = render_cryptomatte(s, *accel, cam, cfg, IntegratorType::Whitted, layers, 6);
  REQUIRE(img.channels == 12);
  REQUIRE(img.layers.size() == 1);
  auto px = [&](int x, int y) { return &img.layers[0][size_t(y * 16 + x) * 12]; };
  // Inside A and inside B: one name with coverage 1.
  CHECK(bits(px(5, 6)[0]) == bits(ida));
  CHECK(px(5, 6)[1] == 1.0f);
  CHECK(px(5, 6)[2] == 0);
  CHECK(bits(px(12, 2)[0]) == bits(idb));
  CHECK(px(12, 2)[1] == 1.0f);
  // Column 8, x in [0, 0.25): A covers 40%, B 60% (stratified 8 x 8: within one stratum).
  for (int y = 4; y < 8; ++y) {
    const float* p = px(8, y);
    CHECK(bits(p[0]) == bits(idb));
    CHECK(p[1] == Approx(0.6).margin(0.126));
    CHECK(bits(p[2]) == bits(ida));
    CHECK(p[3] == Approx(0.4).margin(0.126));
    CHECK(p[1] + p[3] == 1.0f);
  }
  // Under the Blend quad (columns 0..3, rows 0..3: y in (0, 1)): half C, half A.
  const float* blend = px(2, 1);
  CHECK(blend[1] == 0.5f);
  CHECK(blend[3] == 0.5f);
  CHECK(std::min(bits(blend[0]), bits(blend[2])) == std::min(bits(ida), bits(idc)));
  CHECK(std::max(bits(blend[0]), bits(blend[2])) == std::max(bits(ida), bits(idc)));
  // The same ranks for any thread count and tile size.
  cfg.threads = 1;
  cfg.tile_size = 3;
  const CryptoImage one = render_cryptomatte(s, *accel, cam, cfg, IntegratorType::Whitted, layers, 6);
  CHECK(std::memcmp(one.layers[0].data(), img.layers[0].data(), img.layers[0].size() * sizeof(float)) == 0);
  // Odd depth: two groups of four channels, the last rank's pair zero-padded.
  const CryptoImage odd = render_cryptomatte(s, *accel, cam, cfg, IntegratorType::Path, layers, 3);
  CHECK(odd.channels == 8);
  for (size_t i = 0; i < size_t(16 * 8); ++i) {
    CHECK(odd.layers[0][i * 8 + 6] == 0);
    CHECK(odd.layers[0][i * 8 + 7] == 0);
  }
}
