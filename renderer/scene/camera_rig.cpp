// Cameras from parameters: validation, orientations (orbits, turntables, Euler angles), lens
// overrides and tight framing.
#include "renderer/scene/camera_rig.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace penumbra {

namespace {

constexpr double kHalfPi = 0.5 * M_PI;
constexpr const char* kOrthoFitNeedsFraming =
    "a fitted orthographic height needs a framed camera (an orbit without a distance, Euler angles without a "
    "position, or no camera at all)";

[[noreturn]] void fail(const std::string& message) {
  throw std::invalid_argument(message);
}

bool finite3(Vec3f v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

std::string degrees(double radians) {
  return number(radians * 180 / M_PI);
}

/// d / |d|, scaled by its largest component first so that no square overflows; zero for a zero
/// or non-finite d.
Vec3f unit_direction(Vec3f d) {
  const float m = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
  return m > 0 && std::isfinite(m) ? normalize(d / m) : Vec3f{};
}

void check_look_at(const CameraRig& r) {
  if (!finite3(r.eye) || !finite3(r.target) || !finite3(r.up))
    fail("look-at: eye, target and up must be finite");
  const Vec3f view = unit_direction(r.target - r.eye), up = unit_direction(r.up);
  if (!(length(view) > 0)) fail("look-at: the eye and the target are the same point (no view direction)");
  if (!(length(up) > 0)) fail("look-at: the up vector is zero");
  // |sin| of the angle between up and the view direction.
  if (!(length(cross(view, up)) > 1e-6f))
    fail("look-at: the up vector is parallel to the view direction (no image orientation)");
}

void check_lens(const CameraRig& r) {
  if (r.yfov && !(std::isfinite(*r.yfov) && *r.yfov > 0 && *r.yfov < M_PI))
    fail("field of view " + degrees(*r.yfov) + " degrees is outside (0, 180)");
  if (r.focal_mm && !(std::isfinite(*r.focal_mm) && *r.focal_mm > 0))
    fail("focal length " + number(*r.focal_mm) + " mm: must be a finite number > 0");
  if (!(std::isfinite(r.sensor_mm) && r.sensor_mm > 0))
    fail("sensor size " + number(r.sensor_mm) + " mm: must be a finite number > 0");
  if (r.yfov && r.focal_mm) fail("give a field of view or a focal length, not both");
  if (r.ortho_height && !(std::isfinite(*r.ortho_height) && *r.ortho_height > 0))
    fail("orthographic height " + number(*r.ortho_height) + ": must be a finite number > 0");
  const bool ortho = r.ortho_height || r.ortho_fit;
  if (ortho && (r.yfov || r.focal_mm)) fail("an orthographic camera has no field of view or focal length");
  if (r.znear && !(std::isfinite(*r.znear) && *r.znear >= 0))
    fail("near clip distance " + number(*r.znear) + ": must be finite and >= 0");
  if (r.zfar && !(*r.zfar > 0)) fail("far clip distance " + number(*r.zfar) + ": must be > 0 (or infinite)");
  if (r.znear && r.zfar && !(*r.zfar > *r.znear))
    fail("far clip distance " + number(*r.zfar) + " is not beyond the near one " + number(*r.znear));
}

/// The finished camera in single precision: finite, a field of view whose tangent is finite
/// and positive, a positive orthographic height.
void check_result(const Camera& c) {
  const float reach = std::max({std::fabs(c.eye.x), std::fabs(c.eye.y), std::fabs(c.eye.z), c.znear});
  if (!(reach < kMaxCameraReach))
    fail("the camera lies " + number(reach) + " scene units out, beyond " + number(kMaxCameraReach) +
         " (a distance too large, or a field of view too small for the framing)");
  if (!finite3(c.u) || !finite3(c.v) || !finite3(c.w))
    fail("the camera's axes are out of single-precision range (values too large or too small)");
  if (c.projection == Projection::Orthographic) {
    if (!(std::isfinite(c.ymag) && c.ymag > 0 && std::isfinite(c.xmag) && c.xmag > 0))
      fail("orthographic height " + number(2.0 * c.ymag) + " is out of single-precision range");
  } else {
    const float t = std::tan(0.5f * c.yfov);
    if (!(c.yfov > 0 && c.yfov < float(M_PI) && std::isfinite(t) && t > 0 && std::isnormal(t)))
      fail("field of view " + degrees(c.yfov) + " degrees is outside (0, 180) in single precision");
  }
}

/// The bounds fit_bounds frames (its unit box for empty bounds) and their centre.
Vec3f framed_centre(const Bounds3f& b) {
  return b.empty() ? Vec3f{0, 0, 0} : b.center();
}

/// fit_bounds, keeping a given orthographic height.
Camera fit_keeping_height(const Camera& cam, const CameraRig& r, const Bounds3f& bounds, float aspect) {
  Camera c = fit_bounds(cam, bounds, aspect);
  if (r.ortho_height) c.ymag = cam.ymag, c.xmag = cam.xmag;
  return c;
}

/// The framed turntable: fitted at its own frame, then moved out to the distance (and given the
/// orthographic height) the tightest fit of its widest frame needs.
Camera fit_turntable(const Camera& cam, const CameraRig& r, const Bounds3f& bounds, float aspect) {
  Camera c = fit_keeping_height(cam, r, bounds, aspect);
  const Vec3f centre = framed_centre(bounds);
  // The distance of the whole frames only: a time between frames keeps the turn's radius.
  float dist = -std::numeric_limits<float>::infinity(), ymag = 0;
  for (int k = 0; k < r.turntable_frames; ++k) {
    const Quat q = turntable_orientation(r.azimuth, r.elevation, k, r.turntable_frames);
    const Camera f = fit_keeping_height(oriented(cam, q), r, bounds, aspect);
    dist = std::max(dist, dot(f.eye - centre, f.w));
    ymag = std::max(ymag, f.ymag);
  }
  c.eye = centre + c.w * dist;
  if (c.projection == Projection::Orthographic) {
    c.ymag = ymag;
    c.xmag = ymag * aspect;
  } else {
    c.znear = dist * 1e-4f;
  }
  return c;
}

/// The lens: the base's, with the rig's overrides.
Camera lens(const CameraRig& r, const Camera* base, float aspect) {
  Camera c = base ? *base : Camera{};
  if (!base) c.name = "auto-framed";
  if (r.yfov || r.focal_mm) {
    c.projection = Projection::Perspective;
    c.yfov = float(r.yfov ? *r.yfov : focal_length_yfov(*r.focal_mm, r.sensor_mm, aspect));
    c.focal_mm = r.focal_mm ? float(*r.focal_mm) : 0.0f;
  }
  if (r.ortho_height || r.ortho_fit) c.projection = Projection::Orthographic, c.focal_mm = 0;
  if (r.ortho_height) {
    c.ymag = float(0.5 * *r.ortho_height);
    c.xmag = c.ymag * aspect;
  }
  return c;
}

}  // namespace

void check_rig(const CameraRig& r) {
  switch (r.placement) {
    case CameraPlacement::LookAt:
      check_look_at(r);
      break;
    case CameraPlacement::Orbit:
      if (!std::isfinite(r.azimuth)) fail("orbit: the azimuth must be finite");
      if (!(std::fabs(r.elevation) <= kHalfPi + 1e-12))
        fail("orbit: elevation " + degrees(r.elevation) + " degrees is outside [-90, 90]");
      if (r.distance && !(std::isfinite(*r.distance) && *r.distance > 0))
        fail("orbit: distance " + number(*r.distance) + ": must be a finite number > 0");
      break;
    case CameraPlacement::Euler:
      if (!std::isfinite(r.euler.yaw) || !std::isfinite(r.euler.pitch) || !std::isfinite(r.euler.roll))
        fail("euler: yaw, pitch and roll must be finite");
      if (r.has_eye && !finite3(r.eye)) fail("euler: the position must be finite");
      break;
    case CameraPlacement::Base:
      break;
  }
  if (r.turntable_frames < 0)
    fail("turntable: " + std::to_string(r.turntable_frames) + " frames (>= 1 frames per turn; 0 for none)");
  if (!(std::fabs(r.turntable_phase) <= 1048576.0))
    fail("turntable: phase " + std::to_string(r.turntable_phase) +
         " frames (finite, at most 2^20 either way)");
  if (r.turntable_frames > 0 && r.placement != CameraPlacement::Orbit)
    fail("turntable: the camera orbits; it cannot also be placed by look-at or Euler angles");
  check_lens(r);
  const bool never_framed = r.placement == CameraPlacement::LookAt ||
                            (r.placement == CameraPlacement::Orbit && r.distance) ||
                            (r.placement == CameraPlacement::Euler && r.has_eye);
  if (r.ortho_fit && never_framed) fail(kOrthoFitNeedsFraming);
}

bool rig_frames_bounds(const CameraRig& r, bool has_base_camera) {
  switch (r.placement) {
    case CameraPlacement::Base:
      return !has_base_camera;
    case CameraPlacement::Orbit:
      return !r.distance;
    case CameraPlacement::Euler:
      return !r.has_eye;
    case CameraPlacement::LookAt:
      return false;
  }
  return false;
}

Camera rig_camera(const CameraRig& r, const Camera* base, const Bounds3f& bounds, float aspect) {
  check_rig(r);
  const bool framed = rig_frames_bounds(r, base != nullptr);
  if (r.ortho_fit && !framed) fail(kOrthoFitNeedsFraming);
  Camera c = lens(r, base, aspect);
  switch (r.placement) {
    case CameraPlacement::Base:
      if (!base) {
        // frame_bounds' view direction (its frame does not depend on the bounds), fitted with the
        // rig's lens.
        const Camera f = frame_bounds(Bounds3f{}, aspect);
        c.u = f.u, c.v = f.v, c.w = f.w;
        c = fit_keeping_height(c, r, bounds, aspect);
      }
      break;
    case CameraPlacement::LookAt: {
      const Camera frame = look_at(r.eye, r.target, r.up, c.yfov);
      c.eye = frame.eye, c.u = frame.u, c.v = frame.v, c.w = frame.w;
      break;
    }
    case CameraPlacement::Orbit: {
      const Quat q = r.turntable_frames > 0 ? turntable_orientation(r.azimuth, r.elevation, r.turntable_frame,
                                                                    r.turntable_frames, r.turntable_phase)
                                            : orbit_orientation(r.azimuth, r.elevation);
      c = oriented(c, q);
      if (r.distance) {
        c.eye = framed_centre(bounds) + c.w * float(*r.distance);
      } else {
        c = r.turntable_frames > 0 ? fit_turntable(c, r, bounds, aspect)
                                   : fit_keeping_height(c, r, bounds, aspect);
      }
      break;
    }
    case CameraPlacement::Euler:
      c = oriented(c, quat_from_euler(r.euler));
      if (r.has_eye)
        c.eye = r.eye;
      else
        c = fit_keeping_height(c, r, bounds, aspect);
      break;
  }
  if (r.placement != CameraPlacement::Base) c.motion.clear();  // placed by flags: it stays put
  if (r.znear) c.znear = float(*r.znear);
  if (r.zfar) c.zfar = float(*r.zfar);
  check_result(c);
  if (!(c.zfar > c.znear))
    fail("the far clip distance " + number(c.zfar) + " is not beyond the near one " + number(c.znear));
  return c;
}

Camera oriented(const Camera& cam, const Quat& q) {
  const auto axis = [&](double x, double y, double z) {
    const auto a = rotate_vector(normalize(q), {x, y, z});
    return Vec3f{float(a[0]), float(a[1]), float(a[2])};
  };
  Camera c = cam;
  c.u = axis(1, 0, 0);
  c.v = axis(0, 1, 0);
  c.w = axis(0, 0, 1);
  return c;
}

Quat camera_orientation(const Camera& cam) {
  Transform r;
  const Vec3f cols[3] = {cam.u, cam.v, cam.w};
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) r.m[size_t(k)][size_t(c)] = cols[c][k];
  return quat_from_matrix(r);
}

Quat orbit_orientation(double azimuth, double elevation) {
  return quat_from_euler({azimuth, -elevation, 0});
}

Quat turntable_orientation(double azimuth, double elevation, long long frame, int frames, double phase) {
  const long long n = std::max(frames, 1);
  const long long k = ((frame % n) + n) % n;
  double quarters = 4.0 * (double(k) + phase) / double(n);  // [0, 4) for phase 0
  quarters -= 4.0 * std::floor(quarters / 4.0);
  const double key = std::floor(quarters);
  return slerp(orbit_orientation(azimuth + key * kHalfPi, elevation),
               orbit_orientation(azimuth + (key + 1) * kHalfPi, elevation), quarters - key);
}

double focal_length_yfov(double focal_mm, double sensor_mm, float aspect) {
  // The sensor spans the larger side; the vertical extent is sensor / aspect in landscape.
  const double height_mm = aspect >= 1 ? sensor_mm / double(aspect) : sensor_mm;
  return 2 * std::atan(0.5 * height_mm / focal_mm);
}

}  // namespace penumbra
