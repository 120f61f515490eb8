// Tests for renderer/lights/light_tree: the cone union holds both cones, importance is zero
// only where no light can reach, the probabilities of all lights sum to one at any shading
// point and sampling follows them (chi-square), and light sampling through the tree, the power
// table and uniformly estimates the same irradiance, the tree with less variance among many
// lights.
#include "renderer/lights/light_tree.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "renderer/core/rng.h"
#include "renderer/lights/area.h"
#include "renderer/lights/punctual.h"
#include "renderer/materials/material.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

float angle(Vec3f a, Vec3f b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0f, 1.0f));
}

// A room's worth of emissive quads (two triangles each) of varied power, size and facing, in a
// 20 x 20 x 4 box, and one emissive sphere.
Scene many_lights(int quads, uint64_t seed) {
  Scene s;
  Rng rng = make_pixel_rng(0, 0, 0, seed);
  for (int i = 0; i < quads; ++i) {
    const float x = rng.next_float() * 20 - 10, y = rng.next_float() * 20 - 10, z = rng.next_float() * 4;
    const float size = 0.05f + 0.2f * rng.next_float();
    const float le = std::pow(10.0f, 2 * rng.next_float());  // 1 to 100
    const int m = add_lambert(s, {0, 0, 0}, {le, le, le}, /*double_sided=*/rng.next_float() < 0.3f);
    add_quad_z(s, x, x + size, y, y + size, z, m, /*flip=*/rng.next_float() < 0.5f);
  }
  add_shape(s, sphere_shape(0.3f), translation({2, 3, 1}), add_lambert(s, {0, 0, 0}, {50, 50, 50}));
  return s;
}

Vec3f random_unit(Rng& rng) {
  return sample_uniform_sphere({rng.next_float(), rng.next_float()});
}

}  // namespace

TEST_CASE("light tree: the union of two cones holds both", "[lights][tree][quick]") {
  Rng rng = make_pixel_rng(0, 0, 0, 3);
  for (int i = 0; i < 2000; ++i) {
    LightBounds a, b;
    a.bounds = b.bounds = {{0, 0, 0}, {1, 1, 1}};
    a.phi = b.phi = 1;
    a.w = random_unit(rng);
    b.w = random_unit(rng);
    a.cos_o = std::cos(rng.next_float() * kPi);
    b.cos_o = std::cos(rng.next_float() * kPi);
    const LightBounds m = merge(a, b);
    const float theta_m = std::acos(std::clamp(m.cos_o, -1.0f, 1.0f));
    INFO("a " << a.cos_o << " b " << b.cos_o << " m " << m.cos_o);
    // Every direction of a and of b is within theta_m of m.w (the whole sphere: theta_m = pi).
    CHECK(std::min(angle(m.w, a.w) + std::acos(std::clamp(a.cos_o, -1.0f, 1.0f)), kPi) <= theta_m + 1e-3f);
    CHECK(std::min(angle(m.w, b.w) + std::acos(std::clamp(b.cos_o, -1.0f, 1.0f)), kPi) <= theta_m + 1e-3f);
    CHECK(m.phi == 2);
  }
}

TEST_CASE("light tree: importance is zero only behind a one-sided light", "[lights][tree][quick]") {
  // A one-sided unit quad at z = 0 facing +z: points above get importance, points below none
  // (no point of the quad faces them); a two-sided one lights both sides.
  LightBounds b;
  b.bounds = {{0, 0, 0}, {1, 1, 0}};
  b.w = {0, 0, 1};
  b.phi = 1;
  CHECK(light_importance(b, {0.5f, 0.5f, 2}, {}) > 0);
  CHECK(light_importance(b, {5, 5, 0.01f}, {}) > 0);
  CHECK(light_importance(b, {0.5f, 0.5f, -2}, {}) == 0);
  b.two_sided = true;
  CHECK(light_importance(b, {0.5f, 0.5f, -2}, {}) > 0);
  // A receiver whose surface holds the direction to the light still counts it (|cos|), and one
  // facing it gets more than one turned away.
  CHECK(light_importance(b, {0.5f, 0.5f, 2}, {0, 0, -1}) > light_importance(b, {0.5f, 0.5f, 2}, {1, 0, 0}));
  // Closer and more powerful lights matter more.
  CHECK(light_importance(b, {0.5f, 0.5f, 1}, {}) > light_importance(b, {0.5f, 0.5f, 4}, {}));
}

TEST_CASE("light tree: probabilities sum to one everywhere and sampling follows them", "[lights][tree]") {
  const Scene s = many_lights(500, 7);
  const AreaLights al = build_area_lights(s);
  REQUIRE(al.pmf.size() == 1001);
  REQUIRE(al.tree.nodes.size() == 2 * 1001 - 1);
  Rng rng = make_pixel_rng(0, 0, 0, 5);
  for (int trial = 0; trial < 40; ++trial) {
    const Vec3f p{rng.next_float() * 24 - 12, rng.next_float() * 24 - 12, rng.next_float() * 6 - 1};
    const Vec3f n = trial % 4 == 0 ? Vec3f{} : random_unit(rng);
    const LightChoice c{p, n, LightSampler::Tree};
    double sum = 0;
    std::vector<double> pmf(al.pmf.size());
    for (size_t k = 0; k < pmf.size(); ++k) sum += pmf[k] = light_pmf(al, c, k);
    INFO("p " << p.x << " " << p.y << " " << p.z);
    // Sampling: each returned pmf is the light's, and the counts follow the pmf (chi-square over
    // bins of expected count >= 5, the rest pooled; 99.9% quantile by Wilson-Hilferty). A
    // descent ends without a light where both children's bounds say that nothing in them
    // reaches p (one-sided lights facing away): the probabilities then sum to one less the
    // chance of that, which sampling measures.
    const int n_samples = 20000;
    std::vector<int> counts(pmf.size(), 0);
    int failed = 0;
    for (int i = 0; i < n_samples; ++i) {
      uint32_t light = 0;
      float q = 0;
      if (!sample_light_tree(al.tree, p, n, rng.next_float(), light, q)) {
        ++failed;
        continue;
      }
      REQUIRE(q == Approx(pmf[light]).epsilon(1e-5));
      ++counts[light];
    }
    const double lost = 1 - sum;
    CHECK(sum <= 1 + 1e-4);
    CHECK(std::fabs(double(failed) / n_samples - lost) <=
          4 * std::sqrt(std::max(lost, 1e-6) / n_samples) + 1e-4);
    double chi2 = 0, pooled_e = 0, pooled_o = 0;
    int bins = 0;
    for (size_t k = 0; k < pmf.size(); ++k) {
      const double e = pmf[k] * n_samples;
      if (e >= 5) {
        chi2 += (counts[k] - e) * (counts[k] - e) / e;
        ++bins;
      } else {
        pooled_e += e;
        pooled_o += counts[k];
        if (pmf[k] == 0) REQUIRE(counts[k] == 0);
      }
    }
    if (pooled_e > 0) chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e, ++bins;
    const double dof = std::max(1, bins - 1), z = 3.09;
    const double limit = dof * std::pow(1 - 2 / (9 * dof) + z * std::sqrt(2 / (9 * dof)), 3);
    CHECK(chi2 < limit);
  }
}

TEST_CASE("light tree: tree, power and uniform sampling estimate the same irradiance", "[lights][tree]") {
  // Irradiance at points of a floor below the lights, by light sampling alone (no visibility:
  // the lights float in empty space). The tree spends its samples on nearby lights: lower
  // variance than the power table among many scattered lights.
  const Scene s = many_lights(2000, 11);
  const AreaLights al = build_area_lights(s);
  Rng rng = make_pixel_rng(0, 0, 0, 9);
  for (int point = 0; point < 4; ++point) {
    const Vec3f p{rng.next_float() * 16 - 8, rng.next_float() * 16 - 8, -0.5f}, n{0, 0, 1};
    double mean[3], var[3];
    for (LightSampler sampler : {LightSampler::Tree, LightSampler::Power, LightSampler::Uniform}) {
      const int k = int(sampler);
      const int count = 200000;
      double sum = 0, sum2 = 0;
      for (int i = 0; i < count; ++i) {
        AreaLightSample ls;
        double e = 0;
        if (sample_area_light(al, s, {p, n, sampler}, 0, rng.next_float(),
                              {rng.next_float(), rng.next_float()}, ls)) {
          const Vec3f d = ls.p - p;
          const float dist2 = dot(d, d);
          const Vec3f wi = d / std::sqrt(dist2);
          const float cos_l = dot(ls.ng, wi);  // < 0: the light's front faces p
          const Material& m = material_of(s, instance_material(s, s.instances[ls.instance]));
          if ((cos_l < 0 || m.double_sided) && dot(n, wi) > 0)
            e = double(m.emissive.x) * dot(n, wi) * std::fabs(cos_l) / (double(ls.pdf_area) * dist2);
        }
        sum += e;
        sum2 += e * e;
      }
      mean[k] = sum / count;
      var[k] = (sum2 / count - mean[k] * mean[k]) / count;
    }
    INFO("tree " << mean[0] << " +- " << std::sqrt(var[0]) << ", power " << mean[1] << " +- "
                 << std::sqrt(var[1]) << ", uniform " << mean[2] << " +- " << std::sqrt(var[2]));
    CHECK(mean[0] > 0);
    for (int k : {1, 2}) CHECK(std::fabs(mean[k] - mean[0]) < 5 * std::sqrt(var[0] + var[k]));
    CHECK(var[0] < var[1]);
  }
}

TEST_CASE("light tree: point and spot lights among the entries estimate their exact sum", "[lights][tree]") {
  // 40 point and 20 spot lights of varied power scattered over emissive quads, and a
  // directional light (never an entry). Choosing one entry per sample and dividing a punctual
  // light's irradiance by its probability estimates the sum over every punctual light.
  Scene s = many_lights(50, 5);
  Rng rng = make_pixel_rng(0, 0, 0, 21);
  for (int i = 0; i < 60; ++i) {
    Light l = point_light({rng.next_float() * 20 - 10, rng.next_float() * 20 - 10, rng.next_float() * 4},
                          std::pow(10.0f, 2 * rng.next_float()));
    if (i >= 40) {
      l.type = LightType::Spot;
      l.direction = normalize(Vec3f{rng.next_float() - 0.5f, rng.next_float() - 0.5f, -1});
      l.outer_cone = 0.2f + 0.8f * rng.next_float();
      l.inner_cone = l.outer_cone * rng.next_float();
    }
    if (i % 7 == 0) l.range = 6;
    s.lights.push_back(l);
  }
  Light sun;
  sun.type = LightType::Directional;
  s.lights.push_back(sun);
  s.lights.push_back(point_light({0, 0, 2}, 0.0f));  // no power: evaluated, never an entry
  // At most the limit of them (61 with the dark one): every one evaluated, none an entry.
  const AreaLights few = build_area_lights(s, 61);
  CHECK(few.punctual.empty());
  CHECK(few.sampled.empty());
  const AreaLights al = build_area_lights(s);
  REQUIRE(al.punctual.size() == 60);
  REQUIRE(al.sampled.size() == 62);
  CHECK(al.sampled[60] == 0);
  CHECK(al.sampled[61] == 0);
  CHECK(al.pmf.size() == al.triangles.size() + al.shapes.size() + 60);
  for (int point = 0; point < 4; ++point) {
    const Vec3f p{rng.next_float() * 16 - 8, rng.next_float() * 16 - 8, -0.5f}, n{0, 0, 1};
    double exact = 0;
    for (size_t i = 0; i < 60; ++i) {
      LightSample ls;
      if (sample_light(s.lights[i], p, ls)) exact += double(ls.irradiance.x) * std::max(0.0f, dot(n, ls.wi));
    }
    for (LightSampler sampler : {LightSampler::Tree, LightSampler::Power, LightSampler::Uniform}) {
      const int count = 200000;
      double sum = 0, sum2 = 0;
      for (int i = 0; i < count; ++i) {
        AreaLightSample as;
        double e = 0;
        LightSample ls;
        if (sample_area_light(al, s, {p, n, sampler}, 0, rng.next_float(),
                              {rng.next_float(), rng.next_float()}, as) &&
            as.light >= 0 && sample_light(s.lights[size_t(as.light)], p, ls)) {
          if (i < 100)
            CHECK(as.pdf_area ==
                  Approx(light_pmf(al, {p, n, sampler}, al.pmf.size() - 60 + size_t(as.light))));
          e = double(ls.irradiance.x) * std::max(0.0f, dot(n, ls.wi)) / double(as.pdf_area);
        }
        sum += e;
        sum2 += e * e;
      }
      const double mean = sum / count, err = std::sqrt((sum2 / count - mean * mean) / count);
      INFO("point " << point << " sampler " << int(sampler) << ": " << mean << " +- " << err << ", exact "
                    << exact);
      CHECK(exact > 0);
      CHECK(std::fabs(mean - exact) < 5 * err + 1e-9 * exact);
      CHECK(err < 0.05 * exact);
    }
  }
}
