// Gaussian splats' closed forms: rotations and covariances, spherical-harmonic colours against
// the extension's constants, the sRGB decode, the response at a ray's maximum against a scan of
// the Mahalanobis distance along the ray, and the 3-sigma box.
#include "renderer/scene/splats.h"

#include <catch2/catch.hpp>
#include <cmath>

using namespace penumbra;

namespace {

/// One splat at `mu` with rotation q, scales s, opacity o and degree-0 coefficient dc.
SplatCloud one_splat(Vec3f mu, Vec4f q, Vec3f s, float o, Vec3f dc = {0, 0, 0}) {
  SplatCloud c;
  c.positions = {mu};
  c.rotations = {q};
  c.scales = {s};
  c.opacities = {o};
  c.sh = {dc};
  return c;
}

const float kHalf = std::sqrt(0.5f);

}  // namespace

TEST_CASE("splats: covariance R S S^T R^T", "[splats][quick]") {
  const SplatCloud a = one_splat({}, {0, 0, 0, 1}, {1, 2, 3}, 1);
  const Mat3 c = splat_covariance(a, 0);
  CHECK(c[0][0] == Approx(1));
  CHECK(c[1][1] == Approx(4));
  CHECK(c[2][2] == Approx(9));
  CHECK(c[0][1] == Approx(0).margin(1e-12));
  // A quarter turn about z swaps the x and y spreads.
  const SplatCloud b = one_splat({}, {0, 0, kHalf, kHalf}, {1, 2, 3}, 1);
  const Mat3 d = splat_covariance(b, 0);
  CHECK(d[0][0] == Approx(4).epsilon(1e-6));
  CHECK(d[1][1] == Approx(1).epsilon(1e-6));
  CHECK(d[0][1] == Approx(0).margin(1e-6));
  const Bounds3f box = splat_bounds(b, 0);
  CHECK(box.hi.x == Approx(6).epsilon(1e-4));
  CHECK(box.hi.y == Approx(3).epsilon(1e-4));
  CHECK(box.hi.z == Approx(9).epsilon(1e-4));
}

TEST_CASE("splats: spherical-harmonic colour with the 0.5 bias", "[splats][quick]") {
  SplatCloud c = one_splat({}, {0, 0, 0, 1}, {1, 1, 1}, 1, {1, -1, -3});
  // Degree 0: SH00 x 0.2820948 + 0.5, clamped at 0.
  const Vec3f dc = splat_sh_color(c, 0, {0, 0, 1});
  CHECK(dc.x == Approx(0.7820948f));
  CHECK(dc.y == Approx(0.2179052f));
  CHECK(dc.z == 0);
  // Degree 1: (m = -1, 0, 1) times (-0.4886 y, 0.4886 z, -0.4886 x).
  c.sh_degree = 1;
  c.sh = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Vec3f up = splat_sh_color(c, 0, {0, 1, 0}), fwd = splat_sh_color(c, 0, {0, 0, 1}),
              right = splat_sh_color(c, 0, {1, 0, 0});
  CHECK(up.x == Approx(0.5f - 0.4886025f));
  CHECK(fwd.y == Approx(0.5f + 0.4886025f));
  CHECK(right.z == Approx(0.5f - 0.4886025f));
  CHECK(right.x == Approx(0.5f));
  // Degree 2's m = 0 term along z: 0.3153916 x 2.
  c.sh_degree = 2;
  c.sh.resize(9);
  c.sh[6] = {1, 0, 0};
  CHECK(splat_sh_color(c, 0, {0, 0, 1}).x == Approx(0.5f + 0.6307831f));
  // The sRGB decode; linear colours pass through.
  const Vec3f lin = splat_linear_color(SplatColorSpace::SrgbRec709Display, {0.5f, 0.04f, 1});
  CHECK(lin.x == Approx(0.2140411f));
  CHECK(lin.y == Approx(0.04f / 12.92f));
  CHECK(lin.z == Approx(1));
  CHECK(splat_linear_color(SplatColorSpace::LinRec709Display, {0.5f, 0, 0}).x == 0.5f);
}

TEST_CASE("splats: the response at a ray's maximum is the closed form", "[splats][quick]") {
  // Isotropic, unit spread: a ray passing 0.5 from the centre peaks at exp(-0.125).
  const SplatCloud iso = one_splat({1, 2, 3}, {0, 0, 0, 1}, {1, 1, 1}, 0.8f);
  float t = 0, alpha = 0;
  REQUIRE(splat_ray_response(iso, 0, Ray{{1, 2.5f, -2}, 0, {0, 0, 2}, kInfinity}, t, alpha));
  CHECK(t == Approx(2.5f));  // the direction's length counts: the point is o + t d
  CHECK(alpha == Approx(0.8f * std::exp(-0.125f)));
  // Anisotropic and turned: against the smallest Mahalanobis distance found along the ray.
  const SplatCloud an = one_splat({0, 0, 0}, {0.2f, -0.3f, 0.4f, std::sqrt(1 - 0.29f)}, {2, 0.5f, 1}, 1);
  const Mat3 cov = splat_covariance(an, 0);
  // Inverse of the symmetric covariance by cofactors.
  const double det = cov[0][0] * (cov[1][1] * cov[2][2] - cov[1][2] * cov[2][1]) -
                     cov[0][1] * (cov[1][0] * cov[2][2] - cov[1][2] * cov[2][0]) +
                     cov[0][2] * (cov[1][0] * cov[2][1] - cov[1][1] * cov[2][0]);
  Mat3 inv{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
      inv[size_t(r)][size_t(c)] = (cov[size_t(r1)][size_t(c1)] * cov[size_t(r2)][size_t(c2)] -
                                   cov[size_t(r1)][size_t(c2)] * cov[size_t(r2)][size_t(c1)]) /
                                  det;
    }
  const Ray ray{{0.7f, -0.4f, -4}, 0, normalize(Vec3f{0.1f, 0.2f, 1}), kInfinity};
  double best = 1e30, best_t = 0;
  for (int k = 0; k <= 80000; ++k) {
    const double s = 8.0 * k / 80000;
    const double p[3] = {ray.org.x + s * ray.dir.x, ray.org.y + s * ray.dir.y, ray.org.z + s * ray.dir.z};
    double m = 0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m += p[r] * inv[size_t(r)][size_t(c)] * p[c];
    if (m < best) best = m, best_t = s;
  }
  REQUIRE(splat_ray_response(an, 0, ray, t, alpha));
  CHECK(t == Approx(best_t).margin(2e-3));
  CHECK(alpha == Approx(std::exp(-0.5 * best)).epsilon(1e-4));
  // A flat splat (a zero scale, raised to 1e-3 of the largest) peaks where the ray crosses its
  // plane y = 0, with the 2D Gaussian's value there; without any scale it is never hit.
  const SplatCloud flat = one_splat({}, {0, 0, 0, 1}, {1, 0, 1}, 1);
  REQUIRE(splat_ray_response(flat, 0, ray, t, alpha));
  const float tc = -ray.org.y / ray.dir.y;
  CHECK(t == Approx(tc).epsilon(1e-3));
  const Vec3f pc = ray.org + ray.dir * tc;
  CHECK(alpha == Approx(std::exp(-0.5f * (pc.x * pc.x + pc.z * pc.z))).epsilon(1e-3));
  CHECK_FALSE(splat_ray_response(one_splat({}, {0, 0, 0, 1}, {0, 0, 0}, 1), 0, ray, t, alpha));
}
