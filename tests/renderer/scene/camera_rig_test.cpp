// Tests for renderer/scene/camera_rig: the look-at view matrix against one computed by hand,
// orbits and turntables against their closed forms (eye on the sphere about the centre, frame k
// = orbit at azimuth + 2 pi k / N), tight framing checked by projecting the box's corners back
// into the image, lens overrides (field of view, focal length on a sensor, orthographic height,
// clip planes), the Base placement against frame_bounds, and the errors of check_rig.
#include "renderer/scene/camera_rig.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "support/camera_checks.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr double kDeg = M_PI / 180;

/// The non-cubic box most framing tests use, and its centre.
const Bounds3f kBox{{-1, -0.5f, -2}, {3, 1, 0.5f}};
const Vec3f kCentre{1, 0.25f, -0.75f};

/// |a - b| within `rel` of |b| (or of 1 for short vectors).
void check_near(Vec3f a, Vec3f b, double rel) {
  CAPTURE(a.x, a.y, a.z, b.x, b.y, b.z);
  CHECK(double(length(a - b)) <= rel * std::max(1.0, double(length(b))));
}

/// Same eye, frame and lens up to `rel`.
void check_same_camera(const Camera& a, const Camera& b, double rel) {
  check_near(a.eye, b.eye, rel);
  check_near(a.u, b.u, rel);
  check_near(a.v, b.v, rel);
  check_near(a.w, b.w, rel);
  CHECK(a.projection == b.projection);
  CHECK(a.yfov == Approx(b.yfov).epsilon(rel));
  CHECK(a.znear == Approx(b.znear).epsilon(rel).margin(1e-12));
  CHECK(a.zfar == b.zfar);
}

/// The camera's frame is a rotation: orthonormal, right-handed (u x v = w).
void check_rotation_frame(const Camera& c) {
  CHECK(length(c.u) == Approx(1).margin(1e-6));
  CHECK(length(c.v) == Approx(1).margin(1e-6));
  CHECK(length(c.w) == Approx(1).margin(1e-6));
  CHECK(dot(c.u, c.v) == Approx(0).margin(1e-6));
  CHECK(dot(c.u, c.w) == Approx(0).margin(1e-6));
  CHECK(dot(c.v, c.w) == Approx(0).margin(1e-6));
  check_near(cross(c.u, c.v), c.w, 1e-6);
}

bool identical(const Quat& a, const Quat& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w;
}

/// Camera to world: columns u, v, w and the eye.
Transform camera_to_world(const Camera& c) {
  Transform t;
  const Vec3f cols[3] = {c.u, c.v, c.w};
  for (size_t r = 0; r < 3; ++r) t.m[r] = {cols[0][int(r)], cols[1][int(r)], cols[2][int(r)], c.eye[int(r)]};
  return t;
}

void check_identity(const Transform& t, double tol) {
  for (size_t r = 0; r < 4; ++r)
    for (size_t k = 0; k < 4; ++k) CHECK(t.m[r][k] == Approx(r == k ? 1 : 0).margin(tol));
}

CameraRig orbit(double azimuth, double elevation, std::optional<double> distance = std::nullopt) {
  CameraRig r;
  r.placement = CameraPlacement::Orbit;
  r.azimuth = azimuth;
  r.elevation = elevation;
  r.distance = distance;
  return r;
}

CameraRig turntable(double azimuth, double elevation, int frames, long long frame) {
  CameraRig r = orbit(azimuth, elevation);
  r.turntable_frames = frames;
  r.turntable_frame = frame;
  return r;
}

CameraRig euler(EulerAngles e) {
  CameraRig r;
  r.placement = CameraPlacement::Euler;
  r.euler = e;
  return r;
}

CameraRig look(Vec3f eye, Vec3f target, Vec3f up) {
  CameraRig r;
  r.placement = CameraPlacement::LookAt;
  r.eye = eye;
  r.target = target;
  r.up = up;
  return r;
}

/// The image sizes the framing tests use: landscape and portrait.
constexpr std::pair<int, int> kImages[] = {{640, 360}, {300, 500}};

}  // namespace

TEST_CASE("rig: look-at view matrix equals the one computed by hand", "[camera][rig][quick]") {
  struct Case {
    Vec3f eye, target;
    double u[3], v[3], w[3], t[3];  // rows of the view matrix and its translation
  };
  const double r5 = std::sqrt(5.0);
  const Case cases[] = {
      // w = (4, 0, 3) / 5, u = up x w = (0.6, 0, -0.8), v = w x u = (0, 1, 0); the eye is 5 along w.
      {{4, 0, 3}, {0, 0, 0}, {0.6, 0, -0.8}, {0, 1, 0}, {0.8, 0, 0.6}, {0, 0, -5}},
      // w = (1, 2, 2) / 3, u = (2, 0, -1) / sqrt 5, v = (-2, 5, -4) / (3 sqrt 5); eye (5, 2, 4):
      // u.e = 6 / sqrt 5, v.e = -16 / (3 sqrt 5), w.e = 17 / 3.
      {{5, 2, 4},
       {4, 0, 2},
       {2 / r5, 0, -1 / r5},
       {-2 / (3 * r5), 5 / (3 * r5), -4 / (3 * r5)},
       {1.0 / 3, 2.0 / 3, 2.0 / 3},
       {-6 / r5, 16 / (3 * r5), -17.0 / 3}},
  };
  for (const Case& k : cases) {
    CAPTURE(k.eye.x, k.eye.y, k.eye.z);
    const Camera c = look_at(k.eye, k.target, {0, 1, 0}, 0.8f);
    const Transform view = view_matrix(c);
    const double* rows[3] = {k.u, k.v, k.w};
    for (size_t r = 0; r < 3; ++r) {
      for (size_t j = 0; j < 3; ++j) CHECK(view.m[r][j] == Approx(rows[r][j]).margin(1e-6));
      CHECK(view.m[r][3] == Approx(k.t[r]).margin(1e-5));
    }
    for (size_t j = 0; j < 4; ++j) CHECK(view.m[3][j] == (j == 3 ? 1 : 0));
    // The rigid inverse of camera-to-world [R t] (R's columns u, v, w; t the eye): the product
    // both ways is the identity and the 3x3 block is R's transpose.
    const Transform to_world = camera_to_world(c);
    check_identity(view * to_world, 1e-6);
    check_identity(to_world * view, 1e-6);
    for (size_t r = 0; r < 3; ++r)
      for (size_t j = 0; j < 3; ++j) CHECK(view.m[r][j] == to_world.m[j][r]);
    // The LookAt placement gives the same pose; the bounds do not move it.
    const Camera rig = rig_camera(look(k.eye, k.target, {0, 1, 0}), nullptr, kBox, 1.5f);
    check_near(rig.eye, c.eye, 0);
    check_near(rig.u, c.u, 0);
    check_near(rig.v, c.v, 0);
    check_near(rig.w, c.w, 0);
  }
}

TEST_CASE("rig: an orbit places the eye on the sphere about the bounds' centre", "[camera][rig][quick]") {
  const double d = 7.5;
  // Azimuth 0, elevation 0: on +Z of the centre looking down -Z, as look_at gives it.
  const Camera front = rig_camera(orbit(0, 0, d), nullptr, kBox, 1.5f);
  const Camera expected = look_at(kCentre + Vec3f{0, 0, float(d)}, kCentre, {0, 1, 0}, front.yfov);
  check_near(front.eye, expected.eye, 1e-6);
  check_near(front.u, expected.u, 1e-6);
  check_near(front.v, expected.v, 1e-6);
  check_near(front.w, expected.w, 1e-6);
  // Azimuth 90 degrees: on +X of the centre; elevation 30 degrees: above it.
  check_near(rig_camera(orbit(90 * kDeg, 0, d), nullptr, kBox, 1.5f).eye - kCentre, {float(d), 0, 0}, 1e-6);
  const float s = float(d * 0.5), c = float(d * std::sqrt(0.75));
  check_near(rig_camera(orbit(0, 30 * kDeg, d), nullptr, kBox, 1.5f).eye - kCentre, {0, s, c}, 1e-6);
  check_near(rig_camera(orbit(90 * kDeg, 30 * kDeg, d), nullptr, kBox, 1.5f).eye - kCentre, {c, s, 0}, 1e-6);
  // Any (azimuth, elevation): eye - centre = d (sin az cos el, sin el, cos az cos el), looking at
  // the centre with a level horizon (u horizontal, v upwards), the frame a rotation.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> az(-3 * M_PI, 3 * M_PI), el(-0.5 * M_PI, 0.5 * M_PI);
  for (int i = 0; i < 200; ++i) {
    const double a = az(rng), e = el(rng);
    CAPTURE(a, e);
    const Camera cam = rig_camera(orbit(a, e, d), nullptr, kBox, 1.5f);
    const Vec3f offset{float(d * std::sin(a) * std::cos(e)), float(d * std::sin(e)),
                       float(d * std::cos(a) * std::cos(e))};
    check_near(cam.eye - kCentre, offset, 1e-6);
    check_near(cam.w, offset / float(d), 1e-6);
    check_rotation_frame(cam);
    CHECK(cam.u.y == Approx(0).margin(1e-6));
    CHECK(cam.v.y >= -1e-6f);
    CHECK(angle_between(camera_orientation(cam), orbit_orientation(a, e)) < 1e-6);
  }
  // Empty bounds orbit the origin.
  check_near(rig_camera(orbit(0, 0, 2), nullptr, Bounds3f{}, 1).eye, {0, 0, 2}, 1e-6);
}

TEST_CASE("rig: orientations, oriented() and the Euler placement", "[camera][rig][quick]") {
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> angle(-M_PI, M_PI);
  Camera base = look_at({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  base.znear = 0.1f;
  for (int i = 0; i < 200; ++i) {
    const EulerAngles e{angle(rng), 0.5 * angle(rng), angle(rng)};
    CAPTURE(e.yaw, e.pitch, e.roll);
    const Quat q = quat_from_euler(e);
    // oriented: u, v, w are the rotated axes, the rest kept; camera_orientation inverts it.
    const Camera o = oriented(base, q);
    const auto w = rotate_vector(q, {0, 0, 1});
    check_near(o.w, {float(w[0]), float(w[1]), float(w[2])}, 1e-6);
    check_rotation_frame(o);
    CHECK(o.eye == base.eye);
    CHECK(o.yfov == base.yfov);
    CHECK(o.znear == base.znear);
    CHECK(angle_between(camera_orientation(o), q) < 1e-6);
    CHECK(camera_orientation(o).w >= 0);
    // The Euler placement at an eye: that position and orientation.
    CameraRig r = euler(e);
    r.has_eye = true;
    r.eye = {-2, 5, 1};
    const Camera c = rig_camera(r, nullptr, kBox, 1.0f);
    CHECK(c.eye == r.eye);
    check_near(c.w, o.w, 1e-6);
    check_near(c.u, o.u, 1e-6);
    // Framed: the same orientation, looking at the centre.
    const Camera f = rig_camera(euler(e), nullptr, kBox, 1.0f);
    check_near(f.w, o.w, 1e-6);
    check_near(normalize(f.eye - kCentre), f.w, 1e-5);
  }
  // An orbit is the Euler angles (azimuth, -elevation, 0).
  CHECK(angle_between(orbit_orientation(0.4, 0.3), quat_from_euler({0.4, -0.3, 0})) < 1e-12);
  // camera_orientation of look_at's frame.
  const Quat q = camera_orientation(base);
  const auto z = rotate_vector(q, {0, 0, 1});
  check_near({float(z[0]), float(z[1]), float(z[2])}, base.w, 1e-6);
}

TEST_CASE("rig: turntable frames are orbits 2 pi / N apart", "[camera][rig][quick]") {
  for (int n : {1, 2, 3, 4, 7, 8, 10, 36})
    for (double az : {0.0, 0.3, -2.0})
      for (double el : {0.0, 0.4, -0.9, 90 * kDeg, -90 * kDeg}) {
        CAPTURE(n, az, el);
        // Frame N is frame 0 again, and negative and large frame numbers wrap.
        CHECK(identical(turntable_orientation(az, el, n, n), turntable_orientation(az, el, 0, n)));
        CHECK(identical(turntable_orientation(az, el, -1, n), turntable_orientation(az, el, n - 1, n)));
        CHECK(identical(turntable_orientation(az, el, -n - 2, n), turntable_orientation(az, el, n - 2, n)));
        CHECK(identical(turntable_orientation(az, el, 1000000000000LL * n + 3, n),
                        turntable_orientation(az, el, 3 % n, n)));
        for (int k = 0; k < n; ++k) {
          CAPTURE(k);
          const Quat q = turntable_orientation(az, el, k, n);
          CHECK(norm(q) == Approx(1).margin(1e-14));
          CHECK(angle_between(q, orbit_orientation(az + 2 * M_PI * k / n, el)) < 1e-9);
          if (n >= 2)
            CHECK(angle_between(q, turntable_orientation(az, el, k + 1, n)) ==
                  Approx(2 * M_PI / n).margin(1e-9));
          // A valid frame for every elevation; at +-90 degrees straight down / up.
          const Camera c = oriented(Camera{}, q);
          check_rotation_frame(c);
          if (std::fabs(el) == 90 * kDeg) {
            CHECK(-c.w.y == Approx(el > 0 ? -1 : 1).margin(1e-6));
            CHECK(std::hypot(c.w.x, c.w.z) < 1e-6);
          }
        }
      }
  // The rig's turntable with a distance: the orbit at the frame's azimuth.
  for (long long k : {0LL, 1LL, 5LL, 9LL, -4LL}) {
    CAPTURE(k);
    CameraRig r = turntable(0.2, 0.35, 10, k);
    r.distance = 4;
    const Camera t = rig_camera(r, nullptr, kBox, 1.5f);
    const Camera o = rig_camera(orbit(0.2 + 2 * M_PI * double(k) / 10, 0.35, 4.0), nullptr, kBox, 1.5f);
    check_near(t.eye, o.eye, 1e-6);
    check_near(t.u, o.u, 1e-6);
    check_near(t.w, o.w, 1e-6);
  }
}

TEST_CASE("rig: framed orbits and Euler views fit the bounds tightly", "[camera][rig][quick]") {
  const Bounds3f cube{{0, 0, 0}, {1, 1, 1}};
  for (const Bounds3f& b : {kBox, cube})
    for (auto [w, h] : kImages) {
      const float aspect = float(w) / float(h);
      for (auto [az, el] : {std::pair{0.0, 0.0}, std::pair{0.7, 0.3}, std::pair{-2.5, -0.6},
                            std::pair{1.2, 90 * kDeg}, std::pair{3.0, -90 * kDeg}}) {
        CAPTURE(b.lo.x, w, h, az, el);
        const Camera c = rig_camera(orbit(az, el), nullptr, b, aspect);
        CHECK(c.projection == Projection::Perspective);
        CHECK(angle_between(camera_orientation(c), orbit_orientation(az, el)) < 1e-6);
        CHECK(dot(-c.w, normalize(b.center() - c.eye)) == Approx(1));
        check_tight_fit(c, b, w, h);
      }
      for (EulerAngles e : {EulerAngles{0, 0, 0}, EulerAngles{0.5, -0.3, 0.4}, EulerAngles{-2, 0.8, -1.3},
                            EulerAngles{1, 90 * kDeg, 0.5}}) {
        CAPTURE(b.lo.x, w, h, e.yaw, e.pitch, e.roll);
        const Camera c = rig_camera(euler(e), nullptr, b, aspect);
        CHECK(angle_between(camera_orientation(c), quat_from_euler(e)) < 1e-6);
        check_tight_fit(c, b, w, h);
      }
    }
}

TEST_CASE("rig: a framed turntable keeps one distance, every frame inside, the widest tight",
          "[camera][rig][quick]") {
  const int frames = 8;
  for (auto [w, h] : kImages)
    for (auto [az, el] : {std::pair{0.0, 0.0}, std::pair{0.3, 0.5}, std::pair{-1.0, -90 * kDeg}})
      for (bool ortho : {false, true}) {
        CAPTURE(w, h, az, el, ortho);
        const float aspect = float(w) / float(h);
        float dist = -1, ymag = -1, tightest = kInfinity, widest = 0;
        for (long long k = -1; k <= frames; ++k) {
          CAPTURE(k);
          CameraRig r = turntable(az, el, frames, k);
          r.ortho_fit = ortho;
          const Camera c = rig_camera(r, nullptr, kBox, aspect);
          CHECK(c.projection == (ortho ? Projection::Orthographic : Projection::Perspective));
          CHECK(angle_between(camera_orientation(c), turntable_orientation(az, el, k, frames)) < 1e-6);
          check_near(normalize(c.eye - kCentre), c.w, 1e-5);
          // The same distance (and orthographic height) for every frame.
          const float d = length(c.eye - kCentre);
          if (dist < 0) dist = d, ymag = c.ymag;
          CHECK(d == Approx(dist).epsilon(1e-6));
          if (ortho) CHECK(c.ymag == Approx(ymag).epsilon(1e-6));
          // Every frame inside; the tightest is the widest frame, touching the border.
          const ImageFit fit = image_fit(c, kBox, w, h);
          CAPTURE(fit.gap_x, fit.gap_y);
          CHECK(fit.inside);
          CHECK(fit.gap() >= -1e-3f * float(std::max(w, h)));
          tightest = std::min(tightest, fit.gap());
          // The widest frame's own tight fit: the distance (or height) the turntable must keep.
          CameraRig single = orbit(az + 2 * M_PI * double(k) / frames, el);
          single.ortho_fit = ortho;
          const Camera alone = rig_camera(single, nullptr, kBox, aspect);
          widest = std::max(widest, ortho ? alone.ymag : length(alone.eye - kCentre));
        }
        CHECK(tightest <= 1.0f);
        CHECK((ortho ? ymag : dist) == Approx(widest).epsilon(1e-5));
      }
}

TEST_CASE("rig: a turntable's phase turns it between and across frames", "[camera][rig][quick]") {
  for (int n : {1, 3, 8, 36})
    for (double el : {0.0, 0.4, -90 * kDeg}) {
      CAPTURE(n, el);
      const double az = 0.3;
      for (long long k = 0; k < n; ++k) {
        CAPTURE(k);
        // Phase 0 is the frame; phase 1 is the next frame bit for bit; -1 the previous one.
        CHECK(identical(turntable_orientation(az, el, k, n, 0), turntable_orientation(az, el, k, n)));
        CHECK(identical(turntable_orientation(az, el, k, n, 1), turntable_orientation(az, el, k + 1, n)));
        CHECK(angle_between(turntable_orientation(az, el, k, n, -1),
                            turntable_orientation(az, el, k - 1, n)) < 1e-9);
        // A fraction of a frame turns by that fraction of 2 pi / n about +Y.
        for (double f : {0.25, 0.5, -0.375, 2.5}) {
          CAPTURE(f);
          CHECK(angle_between(turntable_orientation(az, el, k, n, f),
                              orbit_orientation(az + 2 * M_PI * (double(k) + f) / n, el)) < 1e-9);
        }
      }
    }
  // A framed turntable keeps the turn's radius between frames; the phase must be finite.
  for (double f : {0.0, 0.5, -0.25, 1.0}) {
    CAPTURE(f);
    CameraRig r = turntable(0.2, 0.35, 8, 2);
    r.turntable_phase = f;
    const Camera c = rig_camera(r, nullptr, kBox, 1.5f);
    const Camera frame = rig_camera(turntable(0.2, 0.35, 8, 2), nullptr, kBox, 1.5f);
    CHECK(length(c.eye - kCentre) == Approx(length(frame.eye - kCentre)).epsilon(1e-6));
    check_near(normalize(c.eye - kCentre), c.w, 1e-5);
  }
  CameraRig bad = turntable(0, 0, 8, 0);
  bad.turntable_phase = std::nan("");
  CHECK_THROWS_WITH(check_rig(bad), Catch::Contains("phase"));
  bad.turntable_phase = 1e7;
  CHECK_THROWS_WITH(check_rig(bad), Catch::Contains("phase"));
}

TEST_CASE("rig: lens overrides", "[camera][rig][quick]") {
  // A 50 mm lens on a 36 mm sensor spanning the larger side: 16:9 has tan_x = 18 / 50, a portrait
  // image has tan_y = 18 / 50, a square image both.
  const float wide = 16.0f / 9.0f, tall = 9.0f / 16.0f;
  CHECK(std::tan(0.5 * focal_length_yfov(50, 36, wide)) * wide == Approx(18.0 / 50).epsilon(1e-6));
  CHECK(focal_length_yfov(50, 36, tall) == Approx(2 * std::atan(18.0 / 50)));
  CHECK(focal_length_yfov(50, 36, 1) == Approx(2 * std::atan(18.0 / 50)));
  CHECK(focal_length_yfov(35, 24, 1.5f) == Approx(2 * std::atan(8.0 / 35)));
  // Longer lenses narrow the view.
  CHECK(focal_length_yfov(85, 36, wide) < focal_length_yfov(50, 36, wide));

  // The rig's field of view and focal length; framed placements fit with them.
  for (auto [w, h] : kImages) {
    CAPTURE(w, h);
    const float aspect = float(w) / float(h);
    CameraRig r = orbit(0.5, 0.2);
    r.yfov = 1.1;
    Camera c = rig_camera(r, nullptr, kBox, aspect);
    CHECK(c.yfov == float(1.1));
    check_tight_fit(c, kBox, w, h);
    r.yfov.reset();
    r.focal_mm = 85;
    r.sensor_mm = 24;
    c = rig_camera(r, nullptr, kBox, aspect);
    CHECK(c.yfov == float(focal_length_yfov(85, 24, aspect)));
    check_tight_fit(c, kBox, w, h);
  }

  // Orthographic height H: ymag H / 2, xmag H / 2 * aspect, kept by every placement.
  const float aspect = 1.6f;
  CameraRig framed_base;
  CameraRig with_distance = orbit(0.1, 0.2, 9.0);
  CameraRig at_eye = euler({0.3, 0.1, 0});
  at_eye.has_eye = true;
  at_eye.eye = {0, 1, 8};
  for (CameraRig r : {framed_base, orbit(0.4, -0.3), turntable(0.4, 0.3, 8, 3), euler({0.3, -0.2, 0.1}),
                      with_distance, at_eye, look({0, 0, 5}, {0, 0, 0}, {0, 1, 0})}) {
    CAPTURE(int(r.placement), r.turntable_frames);
    r.ortho_height = 4;
    const Camera c = rig_camera(r, nullptr, kBox, aspect);
    CHECK(c.projection == Projection::Orthographic);
    CHECK(c.ymag == 2);
    CHECK(c.xmag == Approx(2 * aspect));
    if (rig_frames_bounds(r, false)) {
      // Framed: looking at the centre from in front of every corner.
      check_near(normalize(c.eye - kCentre), c.w, 1e-5);
      for (int k = 0; k < 8; ++k) {
        const Vec3f p{(k & 1) ? kBox.hi.x : kBox.lo.x, (k & 2) ? kBox.hi.y : kBox.lo.y,
                      (k & 4) ? kBox.hi.z : kBox.lo.z};
        CHECK(dot(p - c.eye, c.w) < 0);
      }
    }
  }

  // A fitted orthographic height on an orbit: fit_bounds' ymag for that view, tight.
  for (auto [w, h] : kImages) {
    CameraRig r = orbit(0.7, 0.4);
    r.ortho_fit = true;
    const float a = float(w) / float(h);
    const Camera c = rig_camera(r, nullptr, kBox, a);
    Camera view = oriented(Camera{}, orbit_orientation(0.7, 0.4));
    view.projection = Projection::Orthographic;
    CHECK(c.projection == Projection::Orthographic);
    CHECK(c.ymag == Approx(fit_bounds(view, kBox, a).ymag));
    CHECK(c.xmag == Approx(c.ymag * a));
    check_tight_fit(c, kBox, w, h);
  }

  // Clip planes: the rig's where given, on framed and placed cameras.
  for (CameraRig r : {orbit(0.2, 0.1), orbit(0.2, 0.1, 6.0), look({0, 0, 5}, {0, 0, 0}, {0, 1, 0})}) {
    r.znear = 0.25;
    r.zfar = 100;
    const Camera c = rig_camera(r, nullptr, kBox, 1.5f);
    CHECK(c.znear == 0.25f);
    CHECK(c.zfar == 100.0f);
  }
  CameraRig only_far = orbit(0.2, 0.1);
  only_far.zfar = 1000;
  const Camera far_only = rig_camera(only_far, nullptr, kBox, 1.5f);
  CHECK(far_only.zfar == 1000.0f);
  CHECK(far_only.znear == rig_camera(orbit(0.2, 0.1), nullptr, kBox, 1.5f).znear);

  // A base orthographic camera: a field of view or a focal length makes it perspective; without
  // them the rig keeps the base's lens (and framing fits its height).
  Camera ortho_base = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.5f);
  ortho_base.name = "file camera";
  ortho_base.projection = Projection::Orthographic;
  ortho_base.ymag = 3;
  ortho_base.zfar = 50;
  CameraRig fov = orbit(0.3, 0.2);
  fov.yfov = 0.9;
  Camera c = rig_camera(fov, &ortho_base, kBox, 1.5f);
  CHECK(c.projection == Projection::Perspective);
  CHECK(c.yfov == 0.9f);
  CHECK(c.name == "file camera");
  check_tight_fit(c, kBox, 300, 200);
  CameraRig focal = look({0, 0, 9}, {0, 0, 0}, {0, 1, 0});
  focal.focal_mm = 50;
  c = rig_camera(focal, &ortho_base, kBox, 1.5f);
  CHECK(c.projection == Projection::Perspective);
  CHECK(c.yfov == float(focal_length_yfov(50, 36, 1.5f)));
  CHECK(c.zfar == 50);  // the base's far plane
  c = rig_camera(orbit(0.3, 0.2), &ortho_base, kBox, 1.5f);
  CHECK(c.projection == Projection::Orthographic);
  check_tight_fit(c, kBox, 300, 200);
  c = rig_camera(look({0, 0, 9}, {0, 0, 0}, {0, 1, 0}), &ortho_base, kBox, 1.5f);
  CHECK(c.projection == Projection::Orthographic);
  CHECK(c.ymag == 3);
  // A perspective base keeps its field of view; framing uses it.
  Camera persp_base = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.5f);
  c = rig_camera(orbit(-0.6, 0.25), &persp_base, kBox, 0.6f);
  CHECK(c.yfov == 0.5f);
  check_tight_fit(c, kBox, 300, 500);
}

TEST_CASE("rig: the Base placement", "[camera][rig][quick]") {
  // No base camera and no lens overrides: frame_bounds.
  const Bounds3f cube{{0, 0, 0}, {1, 1, 1}};
  for (const Bounds3f& b : {kBox, cube, Bounds3f{}})
    for (float aspect : {1.0f, 16.0f / 9.0f, 0.6f}) {
      CAPTURE(b.lo.x, aspect);
      const Camera c = rig_camera(CameraRig{}, nullptr, b, aspect);
      const Camera f = frame_bounds(b, aspect);
      check_same_camera(c, f, 1e-6);
      CHECK(c.name == f.name);
    }
  // The default view direction with the rig's lens, still tight.
  CameraRig fov;
  fov.yfov = 1.2;
  const Camera wide = rig_camera(fov, nullptr, kBox, 1.5f);
  CHECK(wide.yfov == 1.2f);
  check_near(wide.w, frame_bounds(kBox, 1.5f).w, 1e-6);
  check_tight_fit(wide, kBox, 300, 200);
  // A base camera keeps its pose whatever the bounds, with the rig's lens overrides.
  Camera base = look_at({2, 3, -4}, {0, 1, 0}, {0, 1, 0}, 0.7f);
  base.name = "file camera";
  base.znear = 0.05f;
  base.zfar = 200;
  for (const Bounds3f& b : {kBox, cube}) {
    const Camera c = rig_camera(CameraRig{}, &base, b, 1.5f);
    check_same_camera(c, base, 0);
    CHECK(c.name == "file camera");
  }
  CameraRig lens;
  lens.yfov = 0.3;
  lens.znear = 1;
  const Camera c = rig_camera(lens, &base, kBox, 1.5f);
  CHECK(c.eye == base.eye);
  CHECK(c.w == base.w);
  CHECK(c.yfov == 0.3f);
  CHECK(c.znear == 1.0f);
  CHECK(c.zfar == 200.0f);
}

TEST_CASE("rig: which placements frame the bounds", "[camera][rig][quick]") {
  CameraRig eye = euler({});
  eye.has_eye = true;
  CHECK(rig_frames_bounds(CameraRig{}, false));
  CHECK_FALSE(rig_frames_bounds(CameraRig{}, true));
  CHECK(rig_frames_bounds(orbit(0, 0), true));
  CHECK_FALSE(rig_frames_bounds(orbit(0, 0, 3.0), false));
  CHECK(rig_frames_bounds(turntable(0, 0, 12, 5), true));
  CHECK(rig_frames_bounds(euler({}), true));
  CHECK_FALSE(rig_frames_bounds(eye, false));
  CHECK_FALSE(rig_frames_bounds(look({0, 0, 1}, {0, 0, 0}, {0, 1, 0}), false));
}

TEST_CASE("rig: values no camera can follow are rejected", "[camera][rig][quick]") {
  // check_rig and rig_camera both throw std::invalid_argument naming what is wrong.
  const auto rejected = [](const CameraRig& r, const std::string& word) {
    CHECK_THROWS_AS(check_rig(r), std::invalid_argument);
    CHECK_THROWS_WITH(check_rig(r), Catch::Contains(word));
    CHECK_THROWS_WITH(rig_camera(r, nullptr, kBox, 1.5f), Catch::Contains(word));
  };
  const auto with = [](CameraRig r, auto&& change) {
    change(r);
    return r;
  };
  // Look-at frames.
  rejected(look({0, 0, 5}, {0, 0, 0}, {0, 0, 0}), "zero");
  rejected(look({1, 2, 3}, {1, 2, 3}, {0, 1, 0}), "same point");
  rejected(look({0, 5, 0}, {0, 0, 0}, {0, 1, 0}), "parallel");
  rejected(look({0, -2, 0}, {0, 3, 0}, {0, 2, 0}), "parallel");
  rejected(look({NAN, 0, 5}, {0, 0, 0}, {0, 1, 0}), "finite");
  // Fields of view, focal lengths and sensors.
  const CameraRig o = orbit(0.3, 0.2);
  for (double bad : {0.0, -0.5, M_PI, 4.0, double(NAN), double(INFINITY)})
    rejected(with(o, [&](CameraRig& r) { r.yfov = bad; }), "field of view");
  rejected(with(o, [](CameraRig& r) { r.yfov = 200 * kDeg; }), "200");
  for (double bad : {0.0, -35.0, double(NAN)})
    rejected(with(o, [&](CameraRig& r) { r.focal_mm = bad; }), "focal length");
  rejected(with(o, [](CameraRig& r) { r.focal_mm = 50, r.sensor_mm = 0; }), "sensor");
  rejected(with(o, [](CameraRig& r) { r.yfov = 0.8, r.focal_mm = 50; }), "not both");
  rejected(with(o, [](CameraRig& r) { r.ortho_height = 2, r.yfov = 0.8; }), "orthographic");
  rejected(with(o, [](CameraRig& r) { r.ortho_fit = true, r.focal_mm = 50; }), "orthographic");
  rejected(with(o, [](CameraRig& r) { r.ortho_height = 0; }), "orthographic height");
  // Orbits and turntables.
  for (double bad : {0.5 * M_PI + 1e-9, 90.001 * kDeg, -91 * kDeg, -100 * kDeg, double(NAN)})
    rejected(orbit(0, bad), "elevation");
  rejected(orbit(0, 100 * kDeg), "100");
  for (double bad : {0.0, -3.0, double(INFINITY)}) rejected(orbit(0, 0, bad), "distance");
  rejected(orbit(double(NAN), 0), "azimuth");
  rejected(turntable(0, 0, -1, 0), "turntable");
  rejected(with(look({0, 0, 5}, {0, 0, 0}, {0, 1, 0}), [](CameraRig& r) { r.turntable_frames = 8; }),
           "turntable");
  rejected(with(euler({}), [](CameraRig& r) { r.turntable_frames = 8; }), "turntable");
  rejected(with(euler({0, NAN, 0}), [](CameraRig&) {}), "finite");
  // Clip planes.
  rejected(with(o, [](CameraRig& r) { r.znear = 2, r.zfar = 2; }), "far clip");
  rejected(with(o, [](CameraRig& r) { r.znear = 3, r.zfar = 1; }), "far clip");
  rejected(with(o, [](CameraRig& r) { r.znear = -1; }), "near clip");
  rejected(with(o, [](CameraRig& r) { r.zfar = 0; }), "far clip");
  // A far plane before the framed near plane (fit_bounds' znear) or the base's: rig_camera only.
  CHECK_THROWS_WITH(rig_camera(with(o, [](CameraRig& r) { r.zfar = 1e-6; }), nullptr, kBox, 1.5f),
                    Catch::Contains("far clip"));
  Camera base;
  base.znear = 10;
  CHECK_THROWS_WITH(rig_camera(with(look({0, 0, 5}, {0, 0, 0}, {0, 1, 0}), [](CameraRig& r) { r.zfar = 5; }),
                               &base, kBox, 1.5f),
                    Catch::Contains("far clip"));
  // A fitted orthographic height on a placement that does not frame the bounds.
  CameraRig eye = euler({});
  eye.has_eye = true;
  for (CameraRig r : {look({0, 0, 5}, {0, 0, 0}, {0, 1, 0}), orbit(0, 0, 4.0), eye}) {
    r.ortho_fit = true;
    CHECK_THROWS_WITH(rig_camera(r, nullptr, kBox, 1.5f), Catch::Contains("orthographic"));
  }
  Camera file;
  CHECK_THROWS_WITH(
      rig_camera(with(CameraRig{}, [](CameraRig& r) { r.ortho_fit = true; }), &file, kBox, 1.5f),
      Catch::Contains("orthographic"));
  // The limits themselves are accepted.
  for (const CameraRig& r : {orbit(0, 90 * kDeg), orbit(0, -90 * kDeg), turntable(0, 90 * kDeg, 1, 0),
                             with(o, [](CameraRig& x) { x.znear = 0, x.zfar = double(INFINITY); }),
                             with(CameraRig{}, [](CameraRig& x) { x.ortho_fit = true; })}) {
    CHECK_NOTHROW(check_rig(r));
    CHECK_NOTHROW(rig_camera(r, nullptr, kBox, 1.5f));
  }
}

// check_rig names the rig's value in its errors, and refuses a fitted orthographic height on a
// placement that never frames the bounds (a look-at, an orbit with a distance, Euler angles at a
// position).
TEST_CASE("rig: check_rig's documented checks on values and fitted orthographic heights",
          "[camera][rig][quick]") {
  CameraRig negative = orbit(0, 0, -3.0);
  CHECK_THROWS_WITH(check_rig(negative), Catch::Contains("-3"));
  CameraRig focal = orbit(0, 0);
  focal.focal_mm = -35;
  CHECK_THROWS_WITH(check_rig(focal), Catch::Contains("-35"));
  CameraRig fit = look({0, 0, 5}, {0, 0, 0}, {0, 1, 0});
  fit.ortho_fit = true;
  CHECK_THROWS_AS(check_rig(fit), std::invalid_argument);
  fit = orbit(0, 0, 4.0);
  fit.ortho_fit = true;
  CHECK_THROWS_AS(check_rig(fit), std::invalid_argument);
}

TEST_CASE("rig: cameras that leave single precision are refused", "[camera][rig][quick]") {
  const Bounds3f box{{-1, -1, -1}, {1, 1, 1}};
  CameraRig tiny_fov = orbit(0, 0);
  tiny_fov.yfov = 1e-30;  // framing puts the eye ~1e30 out
  CHECK_THROWS_WITH(rig_camera(tiny_fov, nullptr, box, 1.5f), Catch::Contains("scene units out"));
  CameraRig rounds_to_pi = orbit(0, 0);
  rounds_to_pi.yfov = M_PI - 1e-9;  // below pi as a double, pi or more as a float
  CHECK_NOTHROW(check_rig(rounds_to_pi));
  CHECK_THROWS_WITH(rig_camera(rounds_to_pi, nullptr, box, 1.5f), Catch::Contains("in single precision"));
  CameraRig huge_height = orbit(0, 0);
  huge_height.ortho_height = 1e39;  // finite as a double, infinite as a float
  CHECK_THROWS_WITH(rig_camera(huge_height, nullptr, box, 1.5f), Catch::Contains("single-precision"));
  CameraRig far_eye = look({1e20f, 0, 0}, {0, 0, 0}, {0, 1, 0});
  CHECK_NOTHROW(check_rig(far_eye));  // the directions are scaled before they are normalised
  CHECK_THROWS_WITH(rig_camera(far_eye, nullptr, box, 1.5f), Catch::Contains("scene units out"));
  // Just inside the reach, the camera is made.
  CameraRig near_limit = look({1e17f, 0, 0}, {0, 0, 0}, {0, 1, 0});
  CHECK(rig_camera(near_limit, nullptr, box, 1.5f).eye.x == 1e17f);
}
