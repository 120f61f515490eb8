// Denoising a render in memory: the halves the path tracer and the data AOVs keep (they average
// to the beauty and the AOVs, leave the beauty unchanged, and resume bit for bit), render_scene's
// denoised beauty, and the error of a denoised 16-spp render of a shipped scene against a
// 512-spp render of it.
#include "render/denoise_render.h"

#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>

#include "render/session.h"
#include "renderer/core/math.h"
#include "support/test_util.h"

namespace penumbra {
namespace {

RenderSpec path_spec(int width, int height, int spp) {
  RenderSpec s;
  s.integrator = "path";
  s.width = width;
  s.height = height;
  s.spp = spp;
  s.accel = "bvh";
  return s;
}

// Relative MSE over the RGB of every pixel: (x - ref)^2 / (ref^2 + 0.01), averaged.
double rel_mse(const std::vector<float>& rgba, const std::vector<float>& ref, int channels_x = 4) {
  double sum = 0;
  const size_t n = ref.size() / 4;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = ref[i * 4 + size_t(c)], x = rgba[i * size_t(channels_x) + size_t(c)];
      sum += (x - r) * (x - r) / (r * r + 0.01);
    }
  return sum / double(3 * n);
}

void load_default(Session& s) {
  s.file = (test::source_dir() / "scenes/default.gltf").string();
  s.loaded = load_gltf(s.file);
}

}  // namespace

TEST_CASE("denoise: the halves average to the beauty and the AOVs and change nothing else", "[denoise]") {
  Session session;
  load_default(session);
  RenderSpec spec = path_spec(24, 16, 8);
  spec.aovs = {"albedo", "N", "Z"};
  const RenderResult plain = render_scene(session, spec, uint64_t(1) << 30);
  spec.aovs.insert("halves");
  const RenderResult r = render_scene(session, spec, uint64_t(1) << 30);
  CHECK(r.image.film.rgba == plain.image.film.rgba);
  CHECK(r.layers.data.albedo == plain.layers.data.albedo);
  const size_t n = 24 * 16;
  REQUIRE(r.image.halves.size() == n * kHalfChannels);
  REQUIRE(r.layers.data.halves.size() == n * 2 * kDenoiseFeatures);
  CHECK(r.image.denoised.rgba.empty());
  int differ = 0, followed = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* h = &r.image.halves[i * kHalfChannels];
    const float* f = &r.layers.data.halves[i * 2 * kDenoiseFeatures];
    // 4 even and 4 odd samples: the beauty is the halves' mean.
    for (int c = 0; c < 3; ++c) {
      CHECK(0.5f * (h[c] + h[3 + c]) == Approx(r.image.film.rgba[i * 4 + size_t(c)]).margin(1e-5));
      differ += h[c] != h[3 + c];
    }
    // The features see through the mirror: never nearer than the first hit; where no sample
    // was followed (the depths are the first hit's), the albedo halves average to the AOV.
    const float z = r.layers.data.depth[i];
    CHECK(std::min(f[6], f[kDenoiseFeatures + 6]) >= z);
    if (f[6] == z && f[kDenoiseFeatures + 6] == z) {
      for (int c = 0; c < 3; ++c)
        CHECK(0.5f * (f[c] + f[kDenoiseFeatures + c]) ==
              Approx(r.layers.data.albedo[i * 3 + size_t(c)]).margin(1e-5));
    } else {
      ++followed;
    }
    for (int half = 0; half < 2; ++half) {  // unit normals where a half hit something
      const float* nn = f + half * kDenoiseFeatures + 3;
      const float len = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
      CHECK((len == 0 || std::fabs(len - 1) < 1e-4f));
    }
  }
  CHECK(followed > 0);     // the scene's mirror and gold sphere
  CHECK(differ > int(n));  // two independent estimates, not one copied
}

TEST_CASE("denoise: a render resumed from its accumulators keeps the halves bit for bit", "[denoise]") {
  LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  RenderSpec spec = path_spec(16, 12, 8);
  spec.aovs = {"halves"};
  PrepareOptions o;
  PreparedRender p = prepare_render(loaded, spec, o);
  const Structure s = build_structure(loaded.scene, p.spec, false);
  const RenderImage whole = render_image(loaded.scene, s.accel.get(), p);
  // Stopped after the pass that reaches 4 samples, then resumed.
  PathAccumulators state;
  std::atomic<bool> stop{false};
  RenderHooks hooks;
  hooks.resume = &state;
  hooks.stop = &stop;
  hooks.after_pass = [&](const PathAccumulators& st) { stop = st.reached >= 4; };
  (void)render_image(loaded.scene, s.accel.get(), p, hooks);
  REQUIRE(state.reached == 4);
  REQUIRE(state.odd.size() == 16 * 12 * 4);
  hooks.after_pass = {};
  stop = false;
  const RenderImage resumed = render_image(loaded.scene, s.accel.get(), p, hooks);
  CHECK(resumed.halves == whole.halves);
  CHECK(resumed.film.rgba == whole.film.rgba);
  finish_render(loaded, p);
}

TEST_CASE("denoise: render_scene's denoised beauty is the denoiser's output with the render's alpha",
          "[denoise]") {
  Session session;
  load_default(session);
  RenderSpec spec = path_spec(32, 24, 4);
  spec.denoise = true;
  const RenderResult r = render_scene(session, spec, uint64_t(1) << 30);
  REQUIRE(r.image.denoised.rgba.size() == r.image.film.rgba.size());
  const std::vector<float> rgb =
      denoise_nfor(denoise_input(r.image, r.layers.data), denoise_config(r.prepared.config));
  for (size_t i = 0; i < 32 * 24; ++i) {
    for (int c = 0; c < 3; ++c) CHECK(r.image.denoised.rgba[i * 4 + size_t(c)] == rgb[i * 3 + size_t(c)]);
    CHECK(r.image.denoised.rgba[i * 4 + 3] == r.image.film.rgba[i * 4 + 3]);
  }
  RenderImage without;
  without.film = r.image.film;
  CHECK_THROWS_WITH(denoise_input(without, r.layers.data), Catch::Contains("no colour halves"));
}

// The shipped default scene (diffuse walls, a mirror, glossy plastic and gold, two point
// lights, glints of them on the gold) at 16 spp, denoised, against 512 spp of the same scene:
// the denoised frame's relative MSE must be at least 4x lower than the 16-spp frame's.
TEST_CASE("denoise: a denoised 16-spp render of a shipped scene is 4x closer to 512 spp than the noisy one",
          "[denoise][heavy]") {
  Session session;
  load_default(session);
  RenderSpec spec = path_spec(96, 72, 16);
  spec.accel = "embree";
  spec.denoise = true;
  const RenderResult noisy = render_scene(session, spec, uint64_t(1) << 30);
  RenderSpec ref_spec = path_spec(96, 72, 512);
  ref_spec.accel = "embree";
  ref_spec.seed = 7;  // independent of the 16-spp samples
  const RenderResult ref = render_scene(session, ref_spec, uint64_t(1) << 30);
  const double e_noisy = rel_mse(noisy.image.film.rgba, ref.image.film.rgba);
  const double e_denoised = rel_mse(noisy.image.denoised.rgba, ref.image.film.rgba);
  INFO("relMSE noisy " << e_noisy << ", denoised " << e_denoised);
  CHECK(e_denoised * 4 < e_noisy);
}

}  // namespace penumbra
