// Tests for renderer/camera: pixel centres, aspect, orthographic and perspective rays, framing
// (the corners of the bounds projected back into the image: inside, the extreme one at the border).
#include "renderer/scene/camera.h"

#include <array>
#include <catch2/catch.hpp>
#include <limits>
#include <stdexcept>

#include "support/camera_checks.h"

using namespace penumbra;
using namespace penumbra::test;

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

TEST_CASE("frame_bounds fits the corners of the bounds tightly, keeping the view direction",
          "[camera][quick]") {
  Scene sphere;  // a sphere of radius 2 at (1, -3, 0.5): its bounds are the box around it
  Shape ball;
  ball.radius = 2;
  sphere.shapes.push_back({"ball", ball, -1, -1});
  sphere.instances.push_back(make_shape_instance(0, to_affine(translate(1, -3, 0.5))));
  const Bounds3f sphere_bounds = compute_bounds(sphere);
  REQUIRE(sphere_bounds.lo.x == Approx(-1));
  REQUIRE(sphere_bounds.hi.y == Approx(-1));
  const Bounds3f cube{{0, 0, 0}, {1, 1, 1}};
  const Bounds3f slab{{-1, -2, -3}, {5, 2, 1}};
  for (const Bounds3f& b : {cube, sphere_bounds, slab})
    for (auto [w, h] :
         {std::pair{960, 540}, std::pair{400, 400}, std::pair{300, 600}, std::pair{2000, 100}}) {
      CAPTURE(b.lo.x, b.hi.x, w, h);
      const Camera c = frame_bounds(b, float(w) / float(h));
      CHECK(c.name == "auto-framed");
      CHECK(c.projection == Projection::Perspective);
      // The view of frame_bounds: the centre from the front-right-above direction (0.5, 0.4, 1).
      CHECK(dot(c.w, normalize(Vec3f{0.5f, 0.4f, 1.0f})) == Approx(1));
      CHECK(dot(-c.w, normalize(b.center() - c.eye)) == Approx(1));
      check_tight_fit(c, b, w, h);
    }
}

TEST_CASE("fit_bounds: orthographic views get ymag from the extents", "[camera][quick]") {
  Camera view = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 1);
  view.projection = Projection::Orthographic;
  const Bounds3f cube{{0, 0, 0}, {1, 1, 1}};
  // Looking down -z at the unit cube: half-extents 0.5 x 0.5; the wide image is limited by height.
  Camera c = fit_bounds(view, cube, 2.0f);
  CHECK(c.ymag == Approx(0.5f));
  CHECK(c.xmag == Approx(1.0f));
  check_tight_fit(c, cube, 200, 100);
  // A tall image is limited by width: ymag = 0.5 / aspect.
  c = fit_bounds(view, cube, 0.5f);
  CHECK(c.ymag == Approx(1.0f));
  check_tight_fit(c, cube, 100, 200);
  // Every corner in front of the eye, the view direction kept.
  CHECK(c.eye.z > 1);
  CHECK(c.w.z == Approx(1));
  // Seen along a diagonal, the extents are the corners' projections onto u and v.
  const Camera diagonal = fit_bounds(look_at({1, 1, 1}, {0, 0, 0}, {0, 1, 0}, 1), cube, 1.0f);
  check_tight_fit(diagonal, cube, 256, 256);
}

TEST_CASE("fit_bounds: perspective distance solved per corner", "[camera][quick]") {
  // Looking down -z at a cube of side 2 centred at the origin with tan(yfov/2) = 0.5 and a square
  // image: the front corners (z = 1, |x| = |y| = 1) need distance 1 + 1 / 0.5 = 3.
  Camera view = look_at({0, 0, 1}, {0, 0, 0}, {0, 1, 0}, 2 * std::atan(0.5f));
  const Bounds3f box{{-1, -1, -1}, {1, 1, 1}};
  Camera c = fit_bounds(view, box, 1.0f);
  CHECK(c.eye.x == Approx(0).margin(1e-6));
  CHECK(c.eye.z == Approx(3));
  // A 2:1 image: the horizontal half-extent is tan_x = 1, the vertical limits: still 3.
  c = fit_bounds(view, box, 2.0f);
  CHECK(c.eye.z == Approx(3));
  // A 1:2 image: tan_x = 0.25, so 1 + 1 / 0.25 = 5.
  c = fit_bounds(view, box, 0.5f);
  CHECK(c.eye.z == Approx(5));
  // Empty bounds frame the unit sphere's box at the origin; a point stays at a positive distance.
  c = fit_bounds(view, Bounds3f{}, 1.0f);
  CHECK(c.eye.z == Approx(3));
  c = fit_bounds(view, Bounds3f{{2, 2, 2}, {2, 2, 2}}, 1.0f);
  CHECK(c.eye.z > 2);
  CHECK(std::isfinite(c.eye.z));
}

namespace {
// Clip-space (x, y, z, w) of world point p: projection x view.
std::array<double, 4> clip_of(const Camera& c, float aspect, Vec3f p) {
  const Transform m = projection_matrix(c, aspect) * view_matrix(c);
  std::array<double, 4> out{};
  for (size_t r = 0; r < 4; ++r) out[r] = m.m[r][0] * p.x + m.m[r][1] * p.y + m.m[r][2] * p.z + m.m[r][3];
  return out;
}
}  // namespace

TEST_CASE("view matrix: the rigid inverse of the camera frame", "[camera][quick]") {
  const Camera c = look_at({1, 2, 3}, {-2, 0.5f, -1}, {0, 1, 0}, 0.8f);
  // Camera to world: columns u, v, w and the eye; its inverse is [R^T  -R^T eye].
  Transform to_world;
  const Vec3f cols[3] = {c.u, c.v, c.w};
  for (size_t r = 0; r < 3; ++r)
    to_world.m[r] = {cols[0][int(r)], cols[1][int(r)], cols[2][int(r)], c.eye[int(r)]};
  Transform inv;
  REQUIRE(inverse(to_world, inv));
  const Transform v = view_matrix(c);
  for (size_t r = 0; r < 4; ++r)
    for (size_t k = 0; k < 4; ++k) CHECK(v.m[r][k] == Approx(inv.m[r][k]).margin(1e-6));
  // The eye maps to the origin and the view direction to -Z.
  const Vec3f e = transform_point(v, c.eye), f = transform_point(v, c.eye - c.w * 2);
  CHECK(length(e) < 1e-5f);
  CHECK(length(f - Vec3f{0, 0, -2}) < 1e-5f);
}

TEST_CASE("projection matrix: glTF's depth mapping and the ray generator's image plane", "[camera][quick]") {
  Camera c = look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 0.9f);
  c.znear = 0.5f;
  c.zfar = 20;
  const float aspect = 1.5f;
  // Finite far plane: depth znear -> z/w = -1, zfar -> +1.
  auto n = clip_of(c, aspect, {0, 0, -0.5f}), f = clip_of(c, aspect, {0, 0, -20});
  CHECK(n[2] / n[3] == Approx(-1));
  CHECK(f[2] / f[3] == Approx(1));
  CHECK(n[3] == Approx(0.5));  // w = depth
  // Infinite far plane: z + w = 2 (depth - znear), z/w -> 1 far away.
  c.zfar = kInfinity;
  const auto i = clip_of(c, aspect, {0, 0, -3});
  CHECK(i[2] + i[3] == Approx(2 * (3 - 0.5)));
  const auto far_away = clip_of(c, aspect, {0, 0, -1e6f});
  CHECK(far_away[2] / far_away[3] == Approx(1).margin(1e-5));
  // A point on the ray through raster (x, y) projects back to that raster position.
  for (Vec2f r : {Vec2f{10, 20}, Vec2f{299.5f, 0.25f}, Vec2f{150, 100}}) {
    const Ray ray = generate_camera_ray(c, 300, 200, r.x, r.y);
    const auto q = clip_of(c, aspect, ray.org + ray.dir * 7);
    CHECK((q[0] / q[3] + 1) * 150 == Approx(r.x).margin(1e-3));
    CHECK((1 - q[1] / q[3]) * 100 == Approx(r.y).margin(1e-3));
  }
  // Orthographic: x/w in [-1, 1] over xmag = ymag * aspect, depth znear..zfar -> -1..1.
  c.projection = Projection::Orthographic;
  c.ymag = 2;
  c.zfar = 10;
  const auto o = clip_of(c, aspect, {3, -2, -10});
  CHECK(o[0] == Approx(1));
  CHECK(o[1] == Approx(-1));
  CHECK(o[2] == Approx(1));
  CHECK(clip_of(c, aspect, {0, 0, -0.5f})[2] == Approx(-1));
}

TEST_CASE("validate_camera refuses cameras whose rays leave single precision", "[camera][quick]") {
  Camera c;  // perspective at the origin
  CHECK_NOTHROW(validate_camera(c, 64, 32));
  Camera far = c;
  far.eye = {0, 0, 2e18f};
  CHECK_THROWS_WITH(validate_camera(far, 64, 32), Catch::Matchers::Contains("the eye lies"));
  Camera ortho = c;
  ortho.projection = Projection::Orthographic;
  ortho.ymag = 4e17f;  // 4e17 high, 8e17 wide for a 2:1 image: inside 1e18 ...
  CHECK_NOTHROW(validate_camera(ortho, 64, 64));
  // ... but the image plane of a 4:1 image reaches 1.6e18.
  CHECK_THROWS_WITH(validate_camera(ortho, 128, 32), Catch::Matchers::Contains("image plane reaches"));
  ortho.ymag = 1e19f;
  CHECK_THROWS_AS(validate_camera(ortho, 16, 16), std::invalid_argument);
  Camera narrow = c;
  narrow.yfov = 1e-38f;  // tan(fov/2) subnormal
  CHECK_THROWS_WITH(validate_camera(narrow, 16, 16), Catch::Matchers::Contains("field of view"));
  Camera clip = c;
  clip.znear = -1;
  CHECK_THROWS_WITH(validate_camera(clip, 16, 16), Catch::Matchers::Contains("near clip"));
  clip.znear = 2, clip.zfar = 1;
  CHECK_THROWS_WITH(validate_camera(clip, 16, 16), Catch::Matchers::Contains("far clip"));
  Camera nan = c;
  nan.u.x = std::numeric_limits<float>::quiet_NaN();
  CHECK_THROWS_WITH(validate_camera(nan, 16, 16), Catch::Matchers::Contains("not finite"));
}

namespace {

/// A u in [0, 1)^2 on a regular n x n lattice (cell centres).
Vec2f lattice(int i, int n) {
  return {(float(i % n) + 0.5f) / float(n), (float(i / n) + 0.5f) / float(n)};
}

}  // namespace

TEST_CASE("sample_aperture: uniform over the unit disc, the polygon and the squeezed disc",
          "[camera][quick]") {
  const int n = 64;
  ThinLens round;
  double r2 = 0;
  float far = 0;
  for (int i = 0; i < n * n; ++i) {
    const Vec2f p = sample_aperture(round, lattice(i, n));
    far = std::max(far, std::hypot(p.x, p.y));
    r2 += double(p.x) * p.x + double(p.y) * p.y;
  }
  CHECK(far <= 1.0f + 1e-6f);
  CHECK(far > 0.98f);
  CHECK(r2 / (n * n) == Approx(0.5).margin(0.01));  // E[r^2] = 1/2 for a uniform unit disc
  // A hexagon, corners at 30 + 60 k degrees (half a blade from the rotation, 0): every point
  // inside its six edges (outward normals at 60 k degrees).
  ThinLens hex;
  hex.blades = 6;
  const float apothem = std::cos(kPi / 6);
  double area_r2 = 0;
  float reach_corner = 0, reach_edge = 0;
  for (int i = 0; i < n * n; ++i) {
    const Vec2f p = sample_aperture(hex, lattice(i, n));
    for (int k = 0; k < 6; ++k) {
      const float a = float(k) * kPi / 3;  // edge k's outward normal
      CHECK(p.x * std::cos(a) + p.y * std::sin(a) <= apothem + 1e-5f);
    }
    const float angle = std::atan2(p.y, p.x), r = std::hypot(p.x, p.y);
    if (std::fabs(angle - kPi / 6) < 0.05f) reach_corner = std::max(reach_corner, r);
    if (std::fabs(angle - kPi / 3) < 0.05f) reach_edge = std::max(reach_edge, r);
    area_r2 += double(p.x) * p.x + double(p.y) * p.y;
  }
  CHECK(reach_corner > 0.95f);
  CHECK(reach_edge <= apothem + 1e-3f);
  // E[r^2] over a regular hexagon of circumradius 1: 5/12.
  CHECK(area_r2 / (n * n) == Approx(5.0 / 12).margin(0.01));
  ThinLens squeezed;
  squeezed.ratio = 2;
  float max_x = 0, max_y = 0;
  for (int i = 0; i < n * n; ++i) {
    const Vec2f p = sample_aperture(squeezed, lattice(i, n));
    max_x = std::max(max_x, std::fabs(p.x));
    max_y = std::max(max_y, std::fabs(p.y));
  }
  CHECK(max_x == Approx(0.5).margin(0.01));  // lattice cell centres reach 63/64 of the rim
  CHECK(max_y == Approx(1.0).margin(0.02));
}

TEST_CASE("thin_lens_ray: every aperture point meets the pinhole ray on the plane in focus",
          "[camera][quick]") {
  for (Projection projection : {Projection::Perspective, Projection::Orthographic}) {
    Camera cam = look_at({1, 2, 3}, {0, 0, -4}, {0, 1, 0}, 0.8f);
    cam.projection = projection;
    cam.ymag = 2;
    cam.znear = 0.5f;
    cam.zfar = 40;
    cam.lens.radius = 0.25f;
    cam.lens.focus_distance = 6;
    const Ray pinhole = generate_camera_ray(cam, 64, 48, 40.3f, 11.7f);
    // With no radius the ray is the pinhole's, bit for bit.
    Camera pin = cam;
    pin.lens.radius = 0;
    const Ray same = thin_lens_ray(pin, pinhole, {0.7f, -0.2f});
    CHECK(same.org == pinhole.org);
    CHECK(same.dir == pinhole.dir);
    const float t_focus = cam.lens.focus_distance / dot(pinhole.dir, -cam.w);
    const Vec3f focus = pinhole.org + pinhole.dir * t_focus;
    for (Vec2f a : {Vec2f{1, 0}, Vec2f{0, -1}, Vec2f{0.6f, 0.8f}, Vec2f{-0.3f, 0.1f}}) {
      const Ray r = thin_lens_ray(cam, pinhole, a);
      CHECK(length(r.dir) == Approx(1).margin(1e-6));
      // The origin lies on the lens plane (depth 0 from the pinhole ray's origin), a * radius away.
      const Vec3f off = r.org - pinhole.org;
      CHECK(dot(off, cam.w) == Approx(0).margin(1e-5));
      CHECK(dot(off, cam.u) == Approx(a.x * 0.25f).margin(1e-5));
      CHECK(dot(off, cam.v) == Approx(a.y * 0.25f).margin(1e-5));
      // It passes through the pinhole ray's point in focus.
      const float t = dot(focus - r.org, r.dir);
      CHECK(length(r.org + r.dir * t - focus) < 1e-4f);
      // The clip planes stay at depths znear and zfar.
      CHECK(dot(r.dir * r.tnear, -cam.w) == Approx(0.5).margin(1e-5));
      CHECK(dot(r.dir * r.tfar, -cam.w) == Approx(40).margin(1e-3));
    }
  }
}

TEST_CASE("fstop_lens_radius: focal length / (2 N), from the rig's focal length or the field of view",
          "[camera][quick]") {
  Camera cam;
  // A 50 mm lens on a 36 mm sensor spanning the width of a 3:2 image: f/2 gives a 12.5 mm radius.
  const float tan_x = 18.0f / 50.0f;
  cam.yfov = 2 * std::atan(tan_x * 2 / 3);
  CHECK(fstop_lens_radius(cam, 2, 300, 200) == Approx(0.0125).epsilon(1e-4));
  // Portrait: the sensor spans the height.
  cam.yfov = 2 * std::atan(tan_x);
  CHECK(fstop_lens_radius(cam, 2, 200, 300) == Approx(0.0125).epsilon(1e-4));
  // A focal length known from the rig wins over the field of view.
  cam.focal_mm = 85;
  CHECK(fstop_lens_radius(cam, 1.4f, 200, 300) == Approx(0.085 / 2.8).epsilon(1e-5));
}

TEST_CASE("validate_camera: the lens' ranges", "[camera][quick]") {
  Camera cam;
  cam.lens.radius = 0.1f;
  CHECK_NOTHROW(validate_camera(cam, 10, 10));
  const auto refused = [&](auto change, const char* message) {
    Camera bad = cam;
    change(bad.lens);
    CHECK_THROWS_WITH(validate_camera(bad, 10, 10), Catch::Contains(message));
  };
  refused([](ThinLens& l) { l.radius = std::numeric_limits<float>::quiet_NaN(); }, "aperture radius");
  refused([](ThinLens& l) { l.focus_distance = 0; }, "focus distance");
  refused([](ThinLens& l) { l.blades = 2; }, "2 blades");
  refused([](ThinLens& l) { l.ratio = 0; }, "ratio");
  refused([](ThinLens& l) { l.rotation = std::numeric_limits<float>::infinity(); }, "rotation");
  refused([](ThinLens& l) { l.radius = 2e18f; }, "beyond");
}
