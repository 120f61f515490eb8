// Test helpers for cameras: the raster position of a world point (perspective or orthographic,
// the image aspect giving the horizontal extent as in generate_camera_ray) and the tight-fit
// check of a framed box (all 8 corners inside the image, the extreme one at the border), and the
// angle between two orientations.
#pragma once

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "renderer/core/math.h"
#include "renderer/core/quaternion.h"
#include "renderer/scene/camera.h"

namespace penumbra::test {

inline double norm(const Quat& q) {
  return std::sqrt(dot(q, q));
}

/// The rotation angle (radians, in [0, pi]) between unit orientations a and b: 2 acos|a.b|,
/// evaluated as 4 atan2(|a - b|, |a + b|) with b's sign chosen so that a.b >= 0 (accurate for
/// small angles, where acos is not).
inline double angle_between(const Quat& a, Quat b) {
  if (dot(a, b) < 0) b = {-b.x, -b.y, -b.z, -b.w};
  const Quat d{a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w}, s{a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w};
  return 4 * std::atan2(norm(d), norm(s));
}

/// Raster position (x right, y down, in pixels) of world point `p` under `cam` in a w x h image.
/// Requires (REQUIRE) a perspective camera's point to lie in front of the eye.
inline Vec2f project(const Camera& cam, Vec3f p, int w, int h) {
  const float aspect = float(w) / float(h);
  const Vec3f q = p - cam.eye;
  float sx = 0, sy = 0;
  if (cam.projection == Projection::Orthographic) {
    sx = dot(q, cam.u) / (cam.ymag * aspect);
    sy = dot(q, cam.v) / cam.ymag;
  } else {
    const float depth = -dot(q, cam.w);
    REQUIRE(depth > 0);  // in front of the camera
    const float tan_y = std::tan(0.5f * cam.yfov);
    sx = dot(q, cam.u) / depth / (tan_y * aspect);
    sy = dot(q, cam.v) / depth / tan_y;
  }
  return {0.5f * (sx + 1) * float(w), 0.5f * (1 - sy) * float(h)};
}

/// How the 8 corners of a box sit in a w x h image.
struct ImageFit {
  bool inside = true;  ///< every corner within the image, up to 1e-3 of its size
  float gap_x = 0;     ///< pixels between the outermost corner and the left/right border
  float gap_y = 0;     ///< the same vertically
  float gap() const { return std::min(gap_x, gap_y); }  ///< the limiting axis' gap
};

/// The corners of `b` projected by `cam` into a w x h image (see ImageFit).
inline ImageFit image_fit(const Camera& cam, const Bounds3f& b, int w, int h) {
  ImageFit fit;
  float reach_x = 0, reach_y = 0;  // the largest distance from the centre line, pixels
  for (int k = 0; k < 8; ++k) {
    const Vec3f p{(k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z};
    const Vec2f r = project(cam, p, w, h);
    fit.inside = fit.inside && r.x >= -1e-3f * float(w) && r.x <= float(w) * (1 + 1e-3f) &&
                 r.y >= -1e-3f * float(h) && r.y <= float(h) * (1 + 1e-3f);
    reach_x = std::max(reach_x, std::fabs(r.x - 0.5f * float(w)));
    reach_y = std::max(reach_y, std::fabs(r.y - 0.5f * float(h)));
  }
  fit.gap_x = 0.5f * float(w) - reach_x;
  fit.gap_y = 0.5f * float(h) - reach_y;
  return fit;
}

/// Every corner of `b` projects inside the w x h image, and the outermost one lies within one
/// pixel of the border on the axis that limits the fit.
inline void check_tight_fit(const Camera& cam, const Bounds3f& b, int w, int h) {
  const ImageFit fit = image_fit(cam, b, w, h);
  CAPTURE(fit.gap_x, fit.gap_y);
  CHECK(fit.inside);
  CHECK(fit.gap() <= 1.0f);  // the limiting axis touches the border
  CHECK(fit.gap() >= -1e-3f * float(std::max(w, h)));
}

}  // namespace penumbra::test
