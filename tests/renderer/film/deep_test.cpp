// Tests for renderer/film/deep (a pixel's camera-sample records merged into deep samples):
// analytic alphas and colours for side-by-side surfaces, Blend layers and the background,
// flattening back to the mean, the merge tolerance, and independence of the sample order; and the
// compositing operations: flatten, merge, holdout against "over" written out here.
#include "renderer/film/deep.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <random>

using namespace penumbra;

namespace {

DeepHit hit(uint32_t key, float depth, float weight, Vec3f radiance) {
  return {key, key * 10, depth, weight, radiance, {0, 0, 1}, {0.5f, 0.5f, 0.5f}};
}

DeepTrace one(const DeepHit& h) {
  DeepTrace t;
  t.add(h);
  return t;
}

/// "Over" front to back, as OpenImageIO's flatten and Nuke's DeepToImage composite.
std::array<double, 4> flatten(const std::vector<DeepSample>& s) {
  std::array<double, 4> out{0, 0, 0, 0};
  for (const DeepSample& d : s) {
    const double t = 1 - out[3];
    out[0] += t * d.r;
    out[1] += t * d.g;
    out[2] += t * d.b;
    out[3] += t * d.a;
  }
  return out;
}

}  // namespace

TEST_CASE("deep: one surface seen by every sample is one sample of the mean colour", "[deep]") {
  DeepPixel px;
  double sum = 0;
  for (int s = 0; s < 64; ++s) {
    const float v = 0.01f * float(s);
    sum += v;
    px.add(one(hit(3, 5.0f + 0.001f * float(s % 7), 1, {v, 2 * v, 0})));
  }
  std::vector<DeepSample> out;
  REQUIRE(px.resolve(64, 0.01f, out) == 1);
  CHECK(out[0].a == 1.0f);
  CHECK(out[0].r == Approx(sum / 64).epsilon(1e-6));
  CHECK(out[0].g == Approx(2 * sum / 64).epsilon(1e-6));
  CHECK(out[0].z == 5.0f);  // the nearest depth; a hard surface
  CHECK(out[0].zback == out[0].z);
  CHECK(out[0].id == 30);
  CHECK(out[0].nz == 1.0f);
  CHECK(out[0].albedo_r == 0.5f);
}

TEST_CASE("deep: surfaces side by side take the coverage the ones in front leave", "[deep]") {
  // 1 of 4 samples on a near surface, 3 on a far one: A = 1/4, then 3/4 / (1 - 1/4) = 1.
  DeepPixel px;
  px.add(one(hit(1, 2, 1, {1, 0, 0})));
  for (int s = 0; s < 3; ++s) px.add(one(hit(2, 8, 1, {0, 1, 0})));
  std::vector<DeepSample> out;
  REQUIRE(px.resolve(4, 0.01f, out) == 2);
  CHECK(out[0].a == Approx(0.25));
  CHECK(out[0].r == Approx(0.25));
  CHECK(out[1].a == Approx(1.0));
  CHECK(out[1].g == Approx(1.0));  // 3/4 of the pixel's green over the 3/4 left uncovered
  const auto f = flatten(out);
  CHECK(f[0] == Approx(0.25));
  CHECK(f[1] == Approx(0.75));
  CHECK(f[3] == Approx(1.0));
  // With half of the samples missing everything, the far surface covers 1/4 / 3/4 = 1/3 of the rest.
  DeepPixel half;
  half.add(one(hit(1, 2, 1, {1, 0, 0})));
  half.add(one(hit(2, 8, 1, {0, 1, 0})));
  out.clear();
  REQUIRE(half.resolve(4, 0.01f, out) == 2);
  CHECK(out[1].a == Approx(1.0 / 3));
  CHECK(flatten(out)[3] == Approx(0.5));
  CHECK(flatten(out)[1] == Approx(0.25));
}

TEST_CASE("deep: Blend layers are samples of their own in depth order, flattening to the composite",
          "[deep]") {
  // A Blend layer of alpha 0.4 (radiance 1) in front of an opaque surface (radiance 0.5), as the
  // Whitted integrator records them: coverage a T, radiance L a T.
  DeepTrace t;
  t.add(hit(2, 9, 0.6f, Vec3f{0.5f, 0.5f, 0.5f} * 0.6f));  // recorded far first, as the recursion does
  t.add(hit(1, 3, 0.4f, Vec3f{1, 1, 1} * 0.4f));
  DeepPixel px;
  px.add(t);
  std::vector<DeepSample> out;
  REQUIRE(px.resolve(1, 0.01f, out) == 2);
  CHECK(out[0].z == 3);
  CHECK(out[0].a == Approx(0.4));
  CHECK(out[1].z == 9);
  CHECK(out[1].a == Approx(1.0));
  const auto f = flatten(out);
  CHECK(f[0] == Approx(0.4 * 1 + 0.6 * 0.5));
  CHECK(f[3] == Approx(1.0));
}

TEST_CASE("deep: light from no surface is a sample of alpha 0 behind everything", "[deep]") {
  DeepPixel px;
  px.add(one(hit(1, 4, 1, {0.2f, 0.2f, 0.2f})));
  px.add(one(DeepHit{0, 0, 0, 0, {1, 2, 3}, {}, {}}));
  std::vector<DeepSample> out;
  REQUIRE(px.resolve(2, 0.01f, out) == 2);
  CHECK(out[1].a == 0);
  CHECK(std::isinf(out[1].z));
  CHECK(out[1].id == 0);
  const auto f = flatten(out);
  CHECK(f[0] == Approx(0.1 + 0.5));
  CHECK(f[2] == Approx(0.1 + 1.5));
  CHECK(f[3] == Approx(0.5));
  // A black background adds nothing: no sample.
  DeepPixel dark;
  dark.add(one(DeepHit{0, 0, 0, 0, {0, 0, 0}, {}, {}}));
  out.clear();
  CHECK(dark.resolve(1, 0.01f, out) == 0);
}

TEST_CASE("deep: the merge tolerance is relative to depth and chains along a surface", "[deep]") {
  const auto count = [](std::vector<float> depths, float tol, uint32_t key2 = 1) {
    DeepPixel px;
    for (size_t i = 0; i < depths.size(); ++i) px.add(one(hit(i == 0 ? 1 : key2, depths[i], 1, {1, 1, 1})));
    std::vector<DeepSample> out;
    return px.resolve(uint32_t(depths.size()), tol, out);
  };
  CHECK(count({100, 100.5f}, 0.01f) == 1);
  CHECK(count({100, 102}, 0.01f) == 2);
  CHECK(count({100, 102}, 0.05f) == 1);
  CHECK(count({100, 100}, 0) == 1);
  CHECK(count({100, 100.001f}, 0) == 2);
  // Steps of 0.8% each merge into one sample although the ends lie 4% apart (a grazing surface).
  CHECK(count({100, 100.8f, 101.6f, 102.4f, 103.2f, 104}, 0.01f) == 1);
  // Different surfaces never merge, however close.
  CHECK(count({100, 100}, 0.5f, 2) == 2);
}

TEST_CASE("deep: the samples do not depend on the order the records arrive in", "[deep]") {
  std::vector<DeepTrace> traces;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  for (int s = 0; s < 50; ++s) {
    DeepTrace t;
    const uint32_t key = 1 + uint32_t(s % 3);
    t.add(hit(key, 2.0f * float(key) + 0.001f * u(rng), 0.5f, {u(rng), u(rng), u(rng)}));
    t.add(hit(5, 20 + u(rng), 0.5f, {u(rng), 0, 0}));
    traces.push_back(t);
  }
  const auto resolve = [&](std::vector<DeepTrace> ts) {
    DeepPixel px;
    for (const auto& t : ts) px.add(t);
    std::vector<DeepSample> out;
    px.resolve(uint32_t(ts.size()), 0.01f, out);
    return out;
  };
  const std::vector<DeepSample> a = resolve(traces);
  std::shuffle(traces.begin(), traces.end(), rng);
  const std::vector<DeepSample> b = resolve(traces);
  REQUIRE(a.size() == 4);
  REQUIRE(b.size() == a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].z == b[i].z);
    CHECK(a[i].a == Approx(b[i].a).epsilon(1e-6));
    CHECK(a[i].r == Approx(b[i].r).epsilon(1e-6));
  }
  for (size_t i = 1; i < a.size(); ++i) CHECK(a[i - 1].z <= a[i].z);
}

TEST_CASE("deep: records beyond a trace's capacity add to its last one", "[deep]") {
  DeepTrace t;
  for (int i = 0; i < kMaxDeepHits + 3; ++i) t.add(hit(uint32_t(i + 1), float(i + 1), 0.01f, {0.01f, 0, 0}));
  CHECK(t.count == kMaxDeepHits);
  CHECK(t.hits[kMaxDeepHits - 1].weight == Approx(0.04f));
}

namespace {

/// A 2 x 1 image: pixel 0 with `a`'s samples, pixel 1 with none.
DeepImage image_of(std::vector<DeepSample> a) {
  DeepImage img;
  img.width = img.full_width = 2;
  img.height = img.full_height = 1;
  img.counts = {uint32_t(a.size()), 0};
  img.samples = std::move(a);
  return img;
}

DeepSample sample(float z, float a, float r) {
  DeepSample s;
  s.z = s.zback = z;
  s.a = a;
  s.r = r;
  s.g = 2 * r;
  return s;
}

}  // namespace

TEST_CASE("deep: flatten, merge and holdout composite as over does", "[deep]") {
  const DeepImage a = image_of({sample(1, 0.5f, 0.4f), sample(5, 1, 0.3f)});
  const DeepImage b = image_of({sample(3, 0.25f, 0.2f), sample(7, 1, 0.9f)});
  const Film fa = flatten_deep(a);
  CHECK(fa.rgba[0] == Approx(0.4 + 0.5 * 0.3));
  CHECK(fa.rgba[1] == Approx(0.8 + 0.5 * 0.6));
  CHECK(fa.rgba[3] == Approx(1.0));
  CHECK(fa.rgba[4] == 0);  // the empty pixel
  CHECK(fa.rgba[7] == 0);

  REQUIRE(same_window(a, b));
  const DeepImage m = merge_deep({&a, &b});
  REQUIRE(m.counts == std::vector<uint32_t>{4, 0});
  for (size_t k = 1; k < 4; ++k) CHECK(m.samples[k - 1].z <= m.samples[k].z);
  CHECK(m.samples[1].z == 3);  // b's first sample between a's two
  const std::vector<DeepSample> in_order = {sample(1, 0.5f, 0.4f), sample(3, 0.25f, 0.2f), sample(5, 1, 0.3f),
                                            sample(7, 1, 0.9f)};
  const auto over = flatten(in_order);
  const Film fm = flatten_deep(m);
  for (int c = 0; c < 4; ++c) CHECK(fm.rgba[size_t(c)] == Approx(over[size_t(c)]));
  // r = 0.4 + 0.5 (0.2 + 0.75 x 0.3): b's far sample lies behind a's opaque one.
  CHECK(fm.rgba[0] == Approx(0.4 + 0.5 * (0.2 + 0.75 * 0.3)));

  // A held out by B: a's samples only, each behind everything in front of it.
  const Film ha = holdout_deep(a, b), hb = holdout_deep(b, a);
  CHECK(ha.rgba[0] == Approx(0.4 + 0.5 * 0.75 * 0.3));
  CHECK(ha.rgba[3] == Approx(0.5 + 0.5 * 0.75 * 1));
  CHECK(hb.rgba[0] == Approx(0.5 * 0.2));
  for (int c = 0; c < 4; ++c) CHECK(ha.rgba[size_t(c)] + hb.rgba[size_t(c)] == Approx(fm.rgba[size_t(c)]));

  DeepImage other = b;
  other.origin_x = 1;
  CHECK_FALSE(same_window(a, other));
}

TEST_CASE("deep: a merge keeps one background, holdouts none, and equal depths split the same way",
          "[deep]") {
  const DeepSample bg = sample(kInfinity, 0, 0.5f);
  const DeepImage a = image_of({sample(2, 0.5f, 0.4f), bg});
  const DeepImage b = image_of({sample(2, 0.5f, 0.2f), bg});  // the same depth as a's surface
  const DeepImage m = merge_deep({&a, &b});
  REQUIRE(m.counts[0] == 3);
  CHECK(std::isinf(m.samples[2].z));
  CHECK(std::isfinite(m.samples[1].z));
  const Film fm = flatten_deep(m);
  // The environment once, through what both surfaces leave: 0.25 of the pixel.
  CHECK(fm.rgba[0] == Approx(0.2 + 0.5 * 0.4 + 0.25 * 0.5));
  const Film ha = holdout_deep(a, b), hb = holdout_deep(b, a);
  // b's sample (less red) comes first at the shared depth, in the merge and in both holdouts.
  CHECK(hb.rgba[0] == Approx(0.2));
  CHECK(ha.rgba[0] == Approx(0.5 * 0.4));
  // The two holdouts and the background through both surfaces make the merge.
  const double background[4] = {0.25 * bg.r, 0.25 * bg.g, 0.25 * bg.b, 0};
  for (int c = 0; c < 4; ++c)
    CHECK(ha.rgba[size_t(c)] + hb.rgba[size_t(c)] + background[c] == Approx(fm.rgba[size_t(c)]));
}
