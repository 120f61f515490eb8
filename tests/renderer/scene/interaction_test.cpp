// Tests for renderer/interaction: attribute interpolation and ray-differential footprints
// against analytic values.
#include "renderer/scene/interaction.h"

#include <catch2/catch.hpp>

#include "renderer/scene/camera.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
// A 2 x 2 quad in the plane z = 0 (facing +z) with uv = ((x+1)/2, (1-y)/2) as TEXCOORD_0 and
// uv1 = 4 x uv as TEXCOORD_1.
Scene uv_quad() {
  Scene s;
  add_quad_z(s, -1, 1, -1, 1, 0, -1);
  Mesh& m = s.meshes[0];
  for (Vec3f p : m.positions) {
    m.uvs.push_back({(p.x + 1) / 2, (1 - p.y) / 2});
    m.uvs1.push_back({2 * (p.x + 1), 2 * (1 - p.y)});
    m.colors.push_back({(p.x + 1) / 2, 0.5f, 1, 1});
  }
  return s;
}

Hit hit_quad(const Scene& s, const Ray& r) {
  // Plane z = 0: solve directly (the quad is two triangles 0-1-2 and 0-2-3).
  const float t = -r.org.z / r.dir.z;
  const Vec3f p = r.org + r.dir * t;
  Hit h;
  h.t = t;
  h.geom_id = 0;
  const Vec3f a = s.meshes[0].positions[0];
  const float x = (p.x - a.x) / 2, y = (p.y - a.y) / 2;  // in [0,1]^2 across the quad
  if (x >= y) {  // triangle 0: (0,0) (1,0) (1,1): p = a + u (b-a) + v (c-a)
    h.prim_id = 0;
    h.u = x - y;
    h.v = y;
  } else {  // triangle 1: (0,0) (1,1) (0,1)
    h.prim_id = 1;
    h.u = x;
    h.v = y - x;
  }
  return h;
}
}  // namespace

TEST_CASE("interaction: UV sets and vertex colours interpolate linearly", "[interaction][quick]") {
  const Scene s = uv_quad();
  Ray r;
  r.org = {0.5f, -0.25f, 3};
  r.dir = {0, 0, -1};
  const SurfaceInteraction si = make_interaction(s, r, hit_quad(s, r));
  CHECK(si.p.x == Approx(0.5));
  CHECK(si.uv[0].x == Approx(0.75));
  CHECK(si.uv[0].y == Approx(0.625));
  CHECK(si.uv[1].x == Approx(3.0));
  CHECK(si.uv[1].y == Approx(2.5));
  CHECK(si.color.x == Approx(0.75));
  CHECK(si.color.z == Approx(1));
  CHECK_FALSE(si.back_face);
}

TEST_CASE("interaction: a camera's pixel footprint on a facing plane is 2 d tan(fov/2) / height",
          "[interaction][quick]") {
  const Scene s = uv_quad();
  const float d = 4, fov = 0.5f;
  const Camera cam = look_at({0, 0, d}, {0, 0, 0}, {0, 1, 0}, fov);
  const int w = 200, h = 200;
  const float px = 100, py = 100;  // image centre
  const Ray r = generate_camera_ray(cam, w, h, px, py);
  const Ray rx = generate_camera_ray(cam, w, h, px + 1, py), ry = generate_camera_ray(cam, w, h, px, py + 1);
  SurfaceInteraction si = make_interaction(s, r, hit_quad(s, r));
  compute_differentials(s, si, RayDifferential{true, rx.org, rx.dir, ry.org, ry.dir});
  const double pixel = 2 * d * std::tan(fov / 2) / h;
  CHECK(si.dpdx.x == Approx(pixel).epsilon(1e-3));
  CHECK(si.dpdx.y == Approx(0).margin(1e-6));
  CHECK(si.dpdy.y == Approx(-pixel).epsilon(1e-3));  // image y runs down
  // uv = ((x+1)/2, (1-y)/2): du/dx = pixel/2, dv/dy = +pixel/2; TEXCOORD_1 is 4x that.
  CHECK(si.duvdx[0].x == Approx(pixel / 2).epsilon(1e-3));
  CHECK(si.duvdx[0].y == Approx(0).margin(1e-6));
  CHECK(si.duvdy[0].y == Approx(pixel / 2).epsilon(1e-3));
  CHECK(si.duvdx[1].x == Approx(2 * pixel).epsilon(1e-3));
  // Without differentials, no footprint.
  SurfaceInteraction plain = make_interaction(s, r, hit_quad(s, r));
  compute_differentials(s, plain, RayDifferential{});
  CHECK(plain.duvdx[0].x == 0);
}

TEST_CASE("interaction: a flat mirror reflects the differential rays exactly", "[interaction][quick]") {
  const Scene s = uv_quad();
  const Camera cam = look_at({0.3f, 0.2f, 2}, {0, 0, 0}, {0, 1, 0}, 0.6f);
  const Ray r = generate_camera_ray(cam, 64, 64, 32.5f, 30.5f);
  const Ray rx = generate_camera_ray(cam, 64, 64, 33.5f, 30.5f),
            ry = generate_camera_ray(cam, 64, 64, 32.5f, 31.5f);
  const RayDifferential rd{true, rx.org, rx.dir, ry.org, ry.dir};
  SurfaceInteraction si = make_interaction(s, r, hit_quad(s, r));
  compute_differentials(s, si, rd);
  const Vec3f wo = normalize(-r.dir), n = si.ns;
  const Vec3f wi = reflect(normalize(r.dir), n);
  const RayDifferential out = reflect_differential(si, rd, wo, n, wi);
  REQUIRE(out.valid);
  // On a plane (dn = 0) the auxiliary rays are the mirror images of the incoming ones.
  const Vec3f ex = reflect(normalize(rx.dir), n);
  CHECK(out.rx_dir.x == Approx(ex.x).margin(1e-5));
  CHECK(out.rx_dir.y == Approx(ex.y).margin(1e-5));
  CHECK(out.rx_dir.z == Approx(ex.z).margin(1e-5));
  // Their origins are where the incoming auxiliary rays meet the plane.
  const float tx = -rx.org.z / rx.dir.z;
  CHECK(out.rx_org.x == Approx(rx.org.x + rx.dir.x * tx).margin(1e-5));
  CHECK(out.rx_org.y == Approx(rx.org.y + rx.dir.y * tx).margin(1e-5));
  CHECK_FALSE(reflect_differential(si, RayDifferential{}, wo, n, wi).valid);
}
