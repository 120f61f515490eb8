// Tests for renderer/camera: pixel centres, aspect, orthographic and perspective rays, framing.
#include "renderer/scene/camera.h"

#include <catch2/catch.hpp>

using namespace penumbra;

TEST_CASE("perspective: centre ray looks down -w, edges span the field of view", "[camera][quick]") {
  Camera cam;                      // at the origin looking down -z
  cam.yfov = 2 * std::atan(0.5f);  // tan(yfov/2) = 0.5
  const int w = 200, h = 100;      // aspect 2
  const Ray centre = generate_camera_ray(cam, w, h, 100, 50);
  CHECK(centre.dir.x == Approx(0).margin(1e-6));
  CHECK(centre.dir.y == Approx(0).margin(1e-6));
  CHECK(centre.dir.z == Approx(-1));
  // Top edge of the image: direction (0, tan(yfov/2), -1) normalised.
  const Ray top = generate_camera_ray(cam, w, h, 100, 0);
  CHECK(top.dir.y / -top.dir.z == Approx(0.5));
  // Right edge: horizontal extent = tan(yfov/2) * aspect = 1 (no distortion).
  const Ray right = generate_camera_ray(cam, w, h, 200, 50);
  CHECK(right.dir.x / -right.dir.z == Approx(1.0));
  // Pixel (0, 0)'s centre is (0.5, 0.5): up and to the left.
  const Ray px = generate_camera_ray(cam, w, h, 0.5f, 0.5f);
  CHECK(px.dir.x / -px.dir.z == Approx(-0.995));  // (2 * 0.5 / 200 - 1) * tan_x, tan_x = 1
  CHECK(px.dir.y / -px.dir.z == Approx(0.495));   // (1 - 2 * 0.5 / 100) * tan_y, tan_y = 0.5
  CHECK(length(px.dir) == Approx(1));
}

TEST_CASE("perspective: square pixels for any image aspect", "[camera][quick]") {
  Camera cam;
  cam.yfov = 0.8f;
  for (auto [w, h] : {std::pair{640, 480}, std::pair{300, 600}, std::pair{1000, 100}}) {
    // One pixel step right and one step down subtend the same image-plane distance.
    const Ray a = generate_camera_ray(cam, w, h, w / 2.0f, h / 2.0f);
    const Ray b = generate_camera_ray(cam, w, h, w / 2.0f + 1, h / 2.0f);
    const Ray c = generate_camera_ray(cam, w, h, w / 2.0f, h / 2.0f + 1);
    const float dx = b.dir.x / -b.dir.z - a.dir.x / -a.dir.z;
    const float dy = a.dir.y / -a.dir.z - c.dir.y / -c.dir.z;
    CHECK(dx == Approx(dy).epsilon(1e-3));  // float raster arithmetic
  }
}

TEST_CASE("perspective: near and far clip at planes", "[camera][quick]") {
  Camera cam;
  cam.yfov = 1.0f;
  cam.znear = 0.5f;
  cam.zfar = 10;
  const Ray corner = generate_camera_ray(cam, 100, 100, 0, 0);
  // The point at t = tnear lies on the plane z = -znear.
  CHECK((corner.org + corner.dir * corner.tnear).z == Approx(-0.5));
  CHECK((corner.org + corner.dir * corner.tfar).z == Approx(-10));
}

TEST_CASE("orthographic: parallel rays from the image plane with ymag half-height", "[camera][quick]") {
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 2;
  const int w = 400, h = 200;
  const Ray tl = generate_camera_ray(cam, w, h, 0, 0);
  CHECK(tl.org.x == Approx(-4));  // xmag' = ymag * aspect = 4
  CHECK(tl.org.y == Approx(2));
  CHECK(tl.org.z == Approx(5));
  const Ray br = generate_camera_ray(cam, w, h, 400, 200);
  CHECK(br.org.x == Approx(4));
  CHECK(br.org.y == Approx(-2));
  CHECK(tl.dir == br.dir);
  CHECK(tl.dir.z == Approx(-1));
}

TEST_CASE("look_at builds a right-handed orthonormal frame", "[camera][quick]") {
  const Camera c = look_at({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 1);
  CHECK(dot(c.u, c.v) == Approx(0).margin(1e-6));
  CHECK(dot(c.u, c.w) == Approx(0).margin(1e-6));
  const Vec3f uxv = cross(c.u, c.v);
  CHECK(uxv.x == Approx(c.w.x));
  CHECK(uxv.y == Approx(c.w.y));
  CHECK(uxv.z == Approx(c.w.z));
  CHECK(dot(-c.w, normalize(Vec3f{-1, -2, -3})) == Approx(1));
}

TEST_CASE("frame_bounds keeps the whole bounding sphere in view", "[camera][quick]") {
  const Bounds3f b{{-1, -2, -3}, {5, 2, 1}};
  for (float aspect : {0.5f, 1.0f, 16.0f / 9.0f}) {
    const Camera c = frame_bounds(b, aspect);
    const Vec3f centre = b.center();
    const float r = 0.5f * length(b.extent());
    const float d = length(c.eye - centre);
    const float half_v = 0.5f * c.yfov, half_h = std::atan(std::tan(half_v) * aspect);
    CHECK(std::asin(r / d) <= std::min(half_v, half_h) + 1e-5f);
    CHECK(dot(-c.w, normalize(centre - c.eye)) == Approx(1));
  }
}
