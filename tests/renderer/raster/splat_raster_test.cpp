// Gaussian splats rasterised (EWA): one splat's footprint against the ellipse of its projected
// covariance (orthographic: exactly the traced response; perspective: the Jacobian of the
// projection by finite differences), raster against trace on generated splat spheres within the
// documented tolerance, splats depth-composited with a mesh, and the same image for any thread
// count or tile size.
#include "renderer/raster/splat_raster.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "renderer/integrators/aov.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// One splat (rotation q, scales s, opacity o, linear colour c) placed by `to_world`.
Scene one_splat(Vec3f mu, Vec4f q, Vec3f s, float o, Vec3f c, const Affine3f& to_world = {}) {
  Scene sc;
  SplatCloud cloud;
  cloud.color_space = SplatColorSpace::LinRec709Display;
  cloud.positions = {mu};
  cloud.rotations = {q};
  cloud.scales = {s};
  cloud.opacities = {o};
  cloud.sh = {(c - Vec3f{0.5f, 0.5f, 0.5f}) / 0.2820947917738781f};
  sc.splat_clouds.push_back(cloud);
  sc.splat_instances.push_back({0, to_world, 3});
  return sc;
}

Camera ortho_down(float ymag) {
  Camera c;
  c.projection = Projection::Orthographic;
  c.eye = {0, 0, 5};
  c.ymag = ymag;
  return c;
}

const Vec4f kTurn{0.1f, -0.2f, 0.3f, std::sqrt(1 - 0.14f)};

}  // namespace

TEST_CASE(
    "splat raster: an orthographic footprint is the projected covariance's ellipse and the traced response",
    "[splats][raster][quick]") {
  const Scene s = one_splat({0.2f, -0.1f, 0}, kTurn, {0.5f, 0.2f, 0.3f}, 0.9f, {1, 0.5f, 0.25f});
  const Camera cam = ortho_down(2);
  const int W = 64, H = 64;
  ProjectedSplat p;
  Sym2 cov;
  REQUIRE(project_splat(s, cam, W, H, 0, 0, p, &cov));
  // The world xy block of R S S^T R^T, in pixels: x scaled by W / (2 ymag) = 16, y by -16.
  const Mat3 world = splat_covariance(s.splat_clouds[0], 0);
  CHECK(cov.xx == Approx(256 * world[0][0]).epsilon(1e-5));
  CHECK(cov.xy == Approx(-256 * world[0][1]).epsilon(1e-5));
  CHECK(cov.yy == Approx(256 * world[1][1]).epsilon(1e-5));
  CHECK(p.centre.x == Approx(32 + 16 * 0.2f));
  CHECK(p.centre.y == Approx(32 + 16 * 0.1f));
  CHECK(p.depth == Approx(5));
  // Each pixel centre: the 2D Gaussian equals the 3D one's maximum along the (parallel) ray,
  // and the covered pixels fill the 3-sigma ellipse's area 9 pi sqrt(det).
  const CameraRaster raster = camera_raster(cam, W, H);
  int covered = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const Vec2f at{x + 0.5f, y + 0.5f};
      const float a = splat_alpha_at(p, at);
      covered += a > 0;
      float t = 0, traced = 0;
      REQUIRE(splat_ray_response(s.splat_clouds[0], 0, raster_ray(cam, raster, at.x, at.y), t, traced));
      if (a > 0) CHECK(a == Approx(traced).epsilon(1e-4));
    }
  const double area = 9 * 3.14159265358979 * std::sqrt(cov.xx * cov.yy - cov.xy * cov.xy);
  CHECK(covered == Approx(area).epsilon(0.03));
}

TEST_CASE("splat raster: a perspective footprint takes the projection's Jacobian at the centre",
          "[splats][raster][quick]") {
  const Scene s = one_splat({0.4f, 0.3f, -1}, kTurn, {0.3f, 0.1f, 0.2f}, 1, {1, 1, 1});
  const Camera cam = look_at({0, 0, 3}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  const int W = 80, H = 60;
  ProjectedSplat p;
  Sym2 cov;
  REQUIRE(project_splat(s, cam, W, H, 0, 0, p, &cov));
  // The raster position of a world point, and its Jacobian by central differences.
  const float tan_y = std::tan(0.4f), tan_x = tan_y * float(W) / float(H);
  auto raster_of = [&](Vec3f q) {
    const Vec3f r = q - cam.eye;
    const double z = dot(r, -cam.w);
    return std::array<double, 2>{0.5 * W * (1 + dot(r, cam.u) / (z * tan_x)),
                                 0.5 * H * (1 - dot(r, cam.v) / (z * tan_y))};
  };
  const Vec3f mu = s.splat_clouds[0].positions[0];
  const auto c = raster_of(mu);
  CHECK(p.centre.x == Approx(c[0]).epsilon(1e-5));
  CHECK(p.centre.y == Approx(c[1]).epsilon(1e-5));
  double j[2][3];
  const float h = 1e-3f;
  for (int k = 0; k < 3; ++k) {
    Vec3f e{0, 0, 0};
    e[k] = h;
    const auto a = raster_of(mu + e), b = raster_of(mu - e);
    j[0][k] = (a[0] - b[0]) / (2 * h);
    j[1][k] = (a[1] - b[1]) / (2 * h);
  }
  const Mat3 sigma = splat_covariance(s.splat_clouds[0], 0);
  double want[2][2] = {};
  for (int r = 0; r < 2; ++r)
    for (int q = 0; q < 2; ++q)
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) want[r][q] += j[r][a] * sigma[size_t(a)][size_t(b)] * j[q][b];
  CHECK(cov.xx == Approx(want[0][0]).epsilon(1e-3));
  CHECK(cov.xy == Approx(want[0][1]).epsilon(1e-3));
  CHECK(cov.yy == Approx(want[1][1]).epsilon(1e-3));
  // Behind the camera: not projected.
  const Scene behind = one_splat({0, 0, 5}, kTurn, {0.3f, 0.1f, 0.2f}, 1, {1, 1, 1});
  CHECK_FALSE(project_splat(behind, cam, W, H, 0, 0, p));
}

namespace {

/// A sphere of splats (the generator's, opacity `opacity`) in front of an unlit grey wall.
Scene splat_sphere_scene(float opacity, bool wall) {
  Scene s;
  SplatSphereConfig sc;
  sc.count = 6000;
  sc.opacity = opacity;
  s.splat_clouds.push_back(make_splat_sphere(sc));
  s.splat_instances.push_back({0, Affine3f{}, 2});
  if (wall) add_quad_z(s, -4, 4, -4, 4, -2, add_material(s, {0.3f, 0.3f, 0.3f}, 0, 1, /*unlit=*/true));
  return s;
}

struct Difference {
  double mean = 0, p99 = 0;
};

Difference compare(const Film& a, const Film& b) {
  std::vector<double> d;
  for (size_t i = 0; i < a.rgba.size(); ++i) d.push_back(std::abs(double(a.rgba[i]) - double(b.rgba[i])));
  Difference out;
  for (double v : d) out.mean += v;
  out.mean /= double(d.size());
  std::sort(d.begin(), d.end());
  out.p99 = d[d.size() * 99 / 100];
  return out;
}

}  // namespace

TEST_CASE("splat raster: raster and trace agree on generated splat scenes within the documented tolerance",
          "[splats][raster]") {
  const Camera persp = look_at({0.5f, 0.4f, 4}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  const Camera ortho = ortho_down(1.4f);
  for (bool wall : {false, true})
    for (float opacity : {0.4f, 1.0f})
      for (const Camera* cam : std::vector<const Camera*>{&persp, &ortho}) {
        INFO("wall " << wall << " opacity " << opacity << " ortho " << (cam == &ortho));
        const Scene s = splat_sphere_scene(opacity, wall);
        RenderConfig cfg = small_render_config(64, 64, 4);
        cfg.whitted.ambient = {0, 0, 0};
        const auto accel = make_scene_accelerator("bvh", s);
        const Film traced = render_whitted(s, *accel, *cam, cfg);
        const Film rasterised = render_raster(s, accel.get(), *cam, cfg);
        const Difference d = compare(traced, rasterised);
        INFO("mean " << d.mean << " p99 " << d.p99);
        CHECK(d.mean < 0.003);
        CHECK(d.p99 < 0.02);
        // And the data AOVs' ids where both are sure of a splat layer or the wall.
        const DataAovs ta = render_data_aovs(s, *accel, *cam, cfg, IntegratorType::Whitted);
        const DataAovs ra = render_raster_aovs(s, *cam, cfg);
        size_t same = 0;
        for (size_t i = 0; i < ta.object_id.size(); ++i) same += ta.object_id[i] == ra.object_id[i];
        CHECK(double(same) >= 0.97 * double(ta.object_id.size()));
      }
}

TEST_CASE("splat raster: depth-composited with meshes, the same for any threads and tiles",
          "[splats][raster]") {
  // An opaque red quad cutting the splat sphere at z = 0: its nearer half covers the quad.
  Scene s = splat_sphere_scene(1, false);
  add_quad_z(s, -0.5f, 0.5f, -0.5f, 0.5f, 0, add_material(s, {1, 0, 0}, 0, 1, /*unlit=*/true));
  const Camera cam = look_at({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  RenderConfig cfg = small_render_config(48, 48, 1, 8);
  cfg.threads = 1;
  const auto accel = make_scene_accelerator("bvh", s);  // the shadow rays' structure
  const Film a = render_raster(s, accel.get(), cam, cfg);
  RenderConfig other = cfg;
  other.threads = 2;
  other.tile_size = 5;
  CHECK(render_raster(s, accel.get(), cam, other).rgba == a.rgba);
  // The centre pixel sees the sphere's front (colour 0.5 + 0.5 n, n = +z), not the red quad.
  const float* centre = a.pixel(24, 24);
  CHECK(centre[0] == Approx(0.5f).margin(0.05f));
  CHECK(centre[2] == Approx(1.0f).margin(0.05f));
  // Without the splats' front half, the quad shows: the splats behind it are hidden.
  Scene back = s;
  SplatCloud& cloud = back.splat_clouds[0];
  for (size_t i = 0; i < cloud.positions.size(); ++i)
    if (cloud.positions[i].z > 0) cloud.opacities[i] = 0;
  const Film behind = render_raster(back, make_scene_accelerator("bvh", back).get(), cam, cfg);
  const float* red = behind.pixel(24, 24);
  CHECK(red[0] == Approx(1));
  CHECK(red[1] == Approx(0));
}

TEST_CASE("splat raster: a crop with a wide filter equals the same pixels of the whole frame",
          "[splats][raster][quick]") {
  // Samples of a 4-pixel Gaussian filter lie up to 1.5 pixels outside their pixel: splats just
  // outside the crop still reach its edge pixels.
  const Scene s = splat_sphere_scene(0.7f, false);
  const Camera cam = look_at({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  RenderConfig full = small_render_config(40, 40, 4, 8);
  full.filter.type = FilterType::Gaussian;
  full.filter.width = 4;
  const auto accel = make_scene_accelerator("bvh", s);
  const Film whole = render_raster(s, accel.get(), cam, full);
  RenderConfig crop = full;
  crop.window = {13, 17, 27, 24};
  const Film part = render_raster(s, accel.get(), cam, crop);
  for (int y = 17; y < 24; ++y)
    for (int x = 13; x < 27; ++x)
      for (int c = 0; c < 4; ++c) {
        INFO(x << "," << y << " channel " << c);
        CHECK(part.pixel(x - 13, y - 17)[c] == whole.pixel(x, y)[c]);
      }
}
