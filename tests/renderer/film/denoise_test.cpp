// Tests for renderer/film/denoise: NFOR and the cross-bilateral baseline on synthetic halves
// with known truth: no bias on a noisy constant, the variance reduction each filter implies,
// edges of albedo and normal kept in place, a checkerboard's contrast kept, determinism over
// threads, and input checks.
#include "renderer/film/denoise.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

using namespace penumbra;

namespace {

struct Truth {
  float r, g, b;
  float albedo[3];
  float normal[3];
  float depth;
};

// Two halves of width x height pixels: each the truth plus independent Gaussian noise of
// standard deviation sigma in colour (features exact).
DenoiseInput make_halves(int w, int h, float sigma, uint32_t seed,
                         const std::function<Truth(int, int)>& truth) {
  DenoiseInput in;
  in.width = w;
  in.height = h;
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, sigma);
  for (int s = 0; s < 2; ++s)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Truth t = truth(x, y);
        in.color[s].insert(in.color[s].end(), {t.r + noise(rng), t.g + noise(rng), t.b + noise(rng)});
        in.features[s].insert(in.features[s].end(), {t.albedo[0], t.albedo[1], t.albedo[2], t.normal[0],
                                                     t.normal[1], t.normal[2], t.depth});
      }
  return in;
}

Truth grey(float v, float albedo = 0.5f, float nz = 1.0f, float nx = 0.0f, float depth = 2.0f) {
  return {v, v, v, {albedo, albedo, albedo}, {nx, 0, nz}, depth};
}

double mean_of(const std::vector<float>& v, int channel, int stride = 3) {
  double s = 0;
  for (size_t i = size_t(channel); i < v.size(); i += size_t(stride)) s += v[i];
  return s / double(v.size() / size_t(stride));
}

// Column where row y of channel 0 first rises through `level`, with linear interpolation.
double crossing(const std::vector<float>& img, int w, int y, double level) {
  for (int x = 1; x < w; ++x) {
    const double a = img[(size_t(y) * size_t(w) + size_t(x - 1)) * 3],
                 b = img[(size_t(y) * size_t(w) + size_t(x)) * 3];
    if (a < level && b >= level) return x - 1 + (level - a) / (b - a);
  }
  return -1;
}

DenoiseConfig fast_config() {
  DenoiseConfig c;
  c.window_radius = 6;
  c.threads = 2;
  return c;
}

}  // namespace

TEST_CASE("denoise: a noisy constant keeps its mean and loses most of its variance", "[denoise]") {
  const int w = 128, h = 128;
  const float sigma = 0.2f;
  const DenoiseInput in = make_halves(w, h, sigma, 7, [](int, int) { return grey(0.5f); });
  const double input_mean = 0.5 * (mean_of(in.color[0], 1) + mean_of(in.color[1], 1));
  // Cross-bilateral with constant features is a Gaussian of sigma R/2 in pixels truncated to
  // the (2R+1)^2 window: away from the border, the variance of the halves' mean (sigma^2 / 2)
  // times sum w^2 / (sum w)^2 over the window.
  const int r = 6;
  const std::vector<float> cb = denoise_cross_bilateral(in, r, 2);
  double sw = 0, sw2 = 0;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const double wq = std::exp(-double(dx * dx + dy * dy) / (2 * (r / 2.0) * (r / 2.0)));
      sw += wq;
      sw2 += wq * wq;
    }
  const double predicted = sigma * sigma / 2 * sw2 / (sw * sw);
  double var = 0;
  int n = 0;
  for (int y = r; y < h - r; ++y)
    for (int x = r; x < w - r; ++x, ++n) var += std::pow(cb[(size_t(y) * w + x) * 3 + 1] - 0.5, 2);
  var /= n;
  CHECK(var == Approx(predicted).epsilon(0.3));  // over ~100 independent pixel groups: +-15% (1 sigma)
  CHECK(mean_of(cb, 1) == Approx(input_mean).margin(2e-3));

  const std::vector<float> out = denoise_nfor(in, fast_config());
  REQUIRE(out.size() == size_t(w * h * 3));
  // An affine filter: the mean stays the input's mean (up to noise at the image's border).
  CHECK(mean_of(out, 1) == Approx(input_mean).margin(2e-3));
  double nvar = 0;
  for (size_t i = 1; i < out.size(); i += 3) nvar += std::pow(out[i] - 0.5, 2);
  nvar /= double(w * h);
  // Non-local means with the variance-cancelling distance weighs a constant's neighbours
  // near 1, so the regression averages most of its 13 x 13 window (169 pixels, 8 fitted
  // parameters): at least 20 times less variance than the halves' mean.
  INFO("variance of the halves' mean " << sigma * sigma / 2 << ", denoised " << nvar);
  CHECK(nvar < sigma * sigma / 2 / 20);
}

TEST_CASE("denoise: an albedo edge and a normal crease stay in place", "[denoise]") {
  const int w = 64, h = 48;
  // Albedo 0.2 | 0.8 at x = 32 under unit light; colour = albedo.
  const DenoiseInput albedo_edge = make_halves(w, h, 0.15f, 11, [](int x, int) {
    const float a = x < 32 ? 0.2f : 0.8f;
    return grey(a, a);
  });
  // Two planes meeting at x = 40 with normals 60 degrees apart; colour = cos to the light.
  const DenoiseInput crease = make_halves(w, h, 0.15f, 12, [](int x, int) {
    return x < 40 ? grey(0.25f, 0.5f, 0.5f, -0.866f) : grey(0.85f, 0.5f, 1.0f, 0.0f);
  });
  for (const auto& [in, edge, level] :
       {std::tuple{&albedo_edge, 32.0, 0.5}, std::tuple{&crease, 40.0, 0.55}}) {
    const std::vector<float> out = denoise_nfor(*in, fast_config());
    for (int y = 8; y < h - 8; y += 8) {
      // The true step lies between pixels edge-1 and edge; its 50% crossing at edge - 0.5.
      INFO("row " << y);
      CHECK(std::fabs(crossing(out, w, y, level) - (edge - 0.5)) <= 1.0);
    }
  }
}

TEST_CASE("denoise: a checkerboard texture keeps its contrast", "[denoise]") {
  const int w = 64, h = 64;
  const auto board = [](int x, int y) { return ((x / 4) + (y / 4)) % 2 ? 0.8f : 0.3f; };
  const DenoiseInput in =
      make_halves(w, h, 0.15f, 13, [&](int x, int y) { return grey(board(x, y), board(x, y)); });
  const std::vector<float> out = denoise_nfor(in, fast_config());
  double bright = 0, dark = 0;
  int nb = 0, nd = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      (board(x, y) > 0.5f ? (++nb, bright) : (++nd, dark)) += out[(size_t(y) * w + x) * 3];
  const double contrast = bright / nb - dark / nd;
  CHECK(contrast == Approx(0.5).epsilon(0.05));
}

TEST_CASE("denoise: a one-pixel glint and a one-pixel bright line stay sharp and keep their energy",
          "[denoise]") {
  // A noisy constant 0.5 with a glint of 200 at (20, 20) and a line of 50 along row 40 (the
  // features, as for a point light's highlight on a smooth surface, do not explain them).
  const int w = 64, h = 56;
  const auto truth = [](int x, int y) {
    if (x == 20 && y == 20) return grey(200.0f);
    if (y == 40 && x >= 8 && x < 56) return grey(50.0f);
    return grey(0.5f);
  };
  DenoiseInput in = make_halves(w, h, 0.1f, 17, truth);
  // Each half sees them with sampling noise of its own (250 and 150, 70 and 30), as a few
  // samples of a glint do: the halves' variance there is large.
  const auto set = [&](int x, int y, float v0, float v1) {
    for (int c = 0; c < 3; ++c) {
      in.color[0][(size_t(y) * w + x) * 3 + c] = v0;
      in.color[1][(size_t(y) * w + x) * 3 + c] = v1;
    }
  };
  set(20, 20, 250.0f, 150.0f);
  for (int x = 8; x < 56; ++x) set(x, 40, x % 2 ? 70.0f : 30.0f, x % 2 ? 30.0f : 70.0f);
  const std::vector<float> out = denoise_nfor(in, fast_config());
  const auto at = [&](int x, int y) { return out[(size_t(y) * w + x) * 3 + 1]; };
  CHECK(at(20, 20) == Approx(200.0).epsilon(0.01));
  for (int x = 8; x < 56; x += 6) CHECK(at(x, 40) == Approx(50.0).epsilon(0.01));
  // Neighbours keep the constant: no glow, no streak.
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx != 0 || dy != 0) CHECK(at(20 + dx, 20 + dy) == Approx(0.5).margin(0.1));
  for (int x = 10; x < 54; x += 6) {
    CHECK(at(x, 39) == Approx(0.5).margin(0.1));
    CHECK(at(x, 41) == Approx(0.5).margin(0.1));
  }
}

TEST_CASE("denoise: the output is the same for any thread count", "[denoise]") {
  const DenoiseInput in = make_halves(70, 45, 0.1f, 5, [](int x, int y) {
    return grey(0.3f + 0.01f * float(x % 9), 0.5f + 0.05f * float(y / 15));
  });
  DenoiseConfig one = fast_config(), two = fast_config();
  one.threads = 1;
  one.tile_size = two.tile_size = 16;
  CHECK(denoise_nfor(in, one) == denoise_nfor(in, two));
}

TEST_CASE("denoise: input and config checks", "[denoise][quick]") {
  DenoiseInput in = make_halves(8, 8, 0.1f, 1, [](int, int) { return grey(0.5f); });
  CHECK(std::string(validate(in)).empty());
  in.features[1].pop_back();
  CHECK_THAT(validate(in), Catch::Contains("feature half"));
  in.color[0].clear();
  CHECK_THAT(validate(in), Catch::Contains("colour half"));
  DenoiseConfig c;
  CHECK(std::string(validate(c)).empty());
  c.window_radius = 0;
  CHECK_THAT(validate(c), Catch::Contains("window radius"));
  c = {};
  c.bandwidths[1] = std::nanf("");
  CHECK_THAT(validate(c), Catch::Contains("bandwidths"));
  // Misses (depth +inf) and non-finite colour are read, not propagated.
  DenoiseInput holes = make_halves(
      24, 24, 0.1f, 2, [](int x, int) { return x < 12 ? grey(0.4f) : grey(1.0f, 0, 0, 0, INFINITY); });
  holes.color[0][5] = NAN;
  for (float v : denoise_nfor(holes, fast_config())) REQUIRE(std::isfinite(v));
}
