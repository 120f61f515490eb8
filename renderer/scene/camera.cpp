// Camera ray generation and framing (the fit solved per corner of the bounds).
#include "renderer/scene/camera.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace penumbra {

CameraRaster camera_raster(const Camera& cam, int width, int height) {
  CameraRaster m{float(width), float(height), float(width) / float(height)};
  if (cam.projection != Projection::Orthographic) {
    m.tan_y = std::tan(0.5f * cam.yfov);
    m.tan_x = m.tan_y * m.aspect;
  }
  return m;
}

Ray raster_ray(const Camera& cam, const CameraRaster& m, float x, float y) {
  const float sx = 2.0f * x / m.width - 1.0f;   // -1 left .. +1 right
  const float sy = 1.0f - 2.0f * y / m.height;  // +1 top .. -1 bottom
  Ray ray;
  if (cam.projection == Projection::Orthographic) {
    const float half_h = cam.ymag, half_w = cam.ymag * m.aspect;
    ray.org = cam.eye + cam.u * (sx * half_w) + cam.v * (sy * half_h);
    ray.dir = -cam.w;
    ray.tnear = cam.znear;
    ray.tfar = cam.zfar;
    return ray;
  }
  const Vec3f d = -cam.w + cam.u * (sx * m.tan_x) + cam.v * (sy * m.tan_y);
  const float len = length(d);
  ray.org = cam.eye;
  ray.dir = d / len;
  // Distance along the unit ray to the plane at depth z is z * len (depth component is 1).
  ray.tnear = cam.znear * len;
  ray.tfar = cam.zfar * len;
  return ray;
}

Vec2f sample_aperture(const ThinLens& lens, Vec2f u) {
  Vec2f p{0, 0};
  if (lens.blades >= 3) {
    // A uniform point in one of the polygon's triangles (centre, corner k, corner k + 1), the
    // triangle picked by u.x and the rest of u.x reused within it.
    const float n = float(lens.blades), f = u.x * n;
    const int k = std::min(int(f), lens.blades - 1);
    // Corners at rotation + (k + 1/2) 360/N degrees, as Cycles places its blades.
    const float a0 = lens.rotation + kPi / n + 2 * kPi * float(k) / n, a1 = a0 + 2 * kPi / n;
    const float s = std::sqrt(std::clamp(f - float(k), 0.0f, 1.0f));
    const float b1 = s * (1 - u.y), b2 = s * u.y;
    p = {b1 * std::cos(a0) + b2 * std::cos(a1), b1 * std::sin(a0) + b2 * std::sin(a1)};
  } else {
    const float ox = 2 * u.x - 1, oy = 2 * u.y - 1;
    if (ox != 0 || oy != 0) {
      float r, theta;
      if (std::fabs(ox) > std::fabs(oy)) {
        r = ox;
        theta = 0.25f * kPi * (oy / ox);
      } else {
        r = oy;
        theta = 0.5f * kPi - 0.25f * kPi * (ox / oy);
      }
      p = {r * std::cos(theta), r * std::sin(theta)};
    }
  }
  p.x /= lens.ratio;
  return p;
}

Ray thin_lens_ray(const Camera& cam, const Ray& pinhole, Vec2f aperture) {
  if (!(cam.lens.radius > 0)) return pinhole;
  // The pinhole ray meets the plane in focus at depth focus_distance (depth grows along -w).
  const Vec3f forward = -cam.w;
  const Vec3f focus = pinhole.org + pinhole.dir * (cam.lens.focus_distance / dot(pinhole.dir, forward));
  Ray r = pinhole;
  r.org = pinhole.org + cam.u * (aperture.x * cam.lens.radius) + cam.v * (aperture.y * cam.lens.radius);
  r.dir = normalize(focus - r.org);
  // The lens lies on the plane of depth 0, so the clip planes stay at depths znear and zfar.
  const float c = dot(r.dir, forward);
  r.tnear = cam.znear / c;
  r.tfar = cam.zfar / c;
  return r;
}

float fstop_lens_radius(const Camera& cam, float fstop, int width, int height) {
  float focal_mm = cam.focal_mm;
  if (!(focal_mm > 0)) {
    const float tan_larger = std::tan(0.5f * cam.yfov) * std::max(1.0f, float(width) / float(height));
    focal_mm = 18.0f / tan_larger;  // half the 36 mm sensor over the half-angle's tangent
  }
  return focal_mm * 1e-3f / (2 * fstop);
}

void validate_camera(const Camera& cam, int width, int height) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("camera: " + what + " (rays beyond single-precision range)");
  };
  const auto shown = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return std::string(text);
  };
  if (width < 1 || height < 1) fail("an image of " + std::to_string(width) + " x " + std::to_string(height));
  if (!is_finite(cam.eye) || !is_finite(cam.u) || !is_finite(cam.v) || !is_finite(cam.w))
    fail("the eye or the axes are not finite");
  if (!(std::isfinite(cam.znear) && cam.znear >= 0 && cam.znear < kMaxCameraReach))
    fail("near clip distance " + shown(cam.znear) + " is not within [0, " + shown(kMaxCameraReach) + ")");
  if (!(cam.zfar > cam.znear)) fail("far clip distance " + shown(cam.zfar) + " is not beyond the near one");
  // The largest origin coordinate of any ray: the eye, plus the image plane's half-extents
  // along u and v for an orthographic camera (computed in double: the sum must not round).
  double half_w = 0, half_h = 0;
  if (cam.projection == Projection::Orthographic) {
    half_h = cam.ymag;
    half_w = double(cam.ymag) * double(width) / double(height);
    if (!(std::isfinite(half_h) && half_h > 0 && double(float(half_w)) > 0 && std::isfinite(float(half_w))))
      fail("orthographic height " + shown(2.0 * half_h) + " for a " + std::to_string(width) + " x " +
           std::to_string(height) + " image");
  } else {
    const float t = std::tan(0.5f * cam.yfov);
    const float tx = t * float(width) / float(height);
    if (!(cam.yfov > 0 && cam.yfov < float(M_PI) && std::isfinite(t) && std::isnormal(t) && t > 0 &&
          std::isfinite(tx) && std::isnormal(tx)))
      fail("field of view " + shown(double(cam.yfov) * 180 / M_PI) + " degrees for a " +
           std::to_string(width) + " x " + std::to_string(height) + " image");
  }
  const ThinLens& lens = cam.lens;
  if (!(std::isfinite(lens.radius) && lens.radius >= 0))
    fail("aperture radius " + shown(lens.radius) + " is not a finite number >= 0");
  if (!(std::isfinite(lens.focus_distance) && lens.focus_distance > 0))
    fail("focus distance " + shown(lens.focus_distance) + " is not a finite number > 0");
  if (lens.blades != 0 && !(lens.blades >= 3 && lens.blades <= kMaxApertureBlades))
    fail("an aperture of " + std::to_string(lens.blades) + " blades (0 for round, or 3 to " +
         std::to_string(kMaxApertureBlades) + ")");
  if (!std::isfinite(lens.rotation)) fail("the aperture rotation is not finite");
  if (!(lens.ratio >= 0.01f && lens.ratio <= 100))
    fail("aperture ratio " + shown(lens.ratio) + " is outside [0.01, 100]");
  double reach = 0;
  for (int k = 0; k < 3; ++k)
    reach =
        std::max(reach, std::fabs(double(cam.eye[k])) + std::fabs(double(cam.u[k])) * half_w +
                            std::fabs(double(cam.v[k])) * half_h +
                            (std::fabs(double(cam.u[k])) / double(lens.ratio) + std::fabs(double(cam.v[k]))) *
                                double(lens.radius));
  if (!(reach < double(kMaxCameraReach)))
    fail(std::string(cam.projection == Projection::Orthographic ? "the image plane reaches "
                                                                : "the eye lies ") +
         shown(reach) + " scene units out, beyond " + shown(kMaxCameraReach));
}

Affine3f camera_frame(const Camera& cam) {
  Affine3f m;
  const Vec3f cols[4] = {cam.u, cam.v, cam.w, cam.eye};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r) m.m[r][c] = cols[c][r];
  return m;
}

Ray move_camera_ray(const Camera& cam, const Ray& ray, float time) {
  if (cam.motion.empty()) return ray;
  const Affine3f at = interpolate_motion(cam.motion, time);
  const Vec3f o = ray.org - cam.eye;
  const Vec3f local_org{dot(o, cam.u), dot(o, cam.v), dot(o, cam.w)};
  const Vec3f local_dir{dot(ray.dir, cam.u), dot(ray.dir, cam.v), dot(ray.dir, cam.w)};
  Ray r = ray;
  r.org = apply_point(at, local_org);
  r.dir = normalize(apply_vector(at, local_dir));
  return r;
}

Ray generate_camera_ray(const Camera& cam, int width, int height, float x, float y) {
  return raster_ray(cam, camera_raster(cam, width, height), x, y);
}

void generate_camera_rays(const Camera& cam, int width, int height, float x, float y, float step, Ray out[3],
                          Vec2f aperture) {
  const CameraRaster m = camera_raster(cam, width, height);
  out[0] = thin_lens_ray(cam, raster_ray(cam, m, x, y), aperture);
  out[1] = thin_lens_ray(cam, raster_ray(cam, m, x + step, y), aperture);
  out[2] = thin_lens_ray(cam, raster_ray(cam, m, x, y + step), aperture);
}

Transform view_matrix(const Camera& cam) {
  Transform t;
  const Vec3f rows[3] = {cam.u, cam.v, cam.w};
  for (int r = 0; r < 3; ++r) {
    t.m[size_t(r)] = {rows[r].x, rows[r].y, rows[r].z, -double(dot(rows[r], cam.eye))};
  }
  return t;
}

Transform projection_matrix(const Camera& cam, float aspect) {
  Transform p;
  const double n = cam.znear, f = cam.zfar;
  if (cam.projection == Projection::Orthographic) {
    const double ymag = cam.ymag, xmag = cam.ymag * double(aspect);
    p.m[0] = {1 / xmag, 0, 0, 0};
    p.m[1] = {0, 1 / ymag, 0, 0};
    p.m[2] = std::isfinite(f) ? std::array<double, 4>{0, 0, 2 / (n - f), (f + n) / (n - f)}
                              : std::array<double, 4>{0, 0, -1, -(n + 1)};
    p.m[3] = {0, 0, 0, 1};
    return p;
  }
  const double near = n > 0 ? n : double(kMinZnear);
  const double t = std::tan(0.5 * double(cam.yfov));
  p.m[0] = {1 / (double(aspect) * t), 0, 0, 0};
  p.m[1] = {0, 1 / t, 0, 0};
  p.m[2] = std::isfinite(f) ? std::array<double, 4>{0, 0, (f + near) / (near - f), 2 * f * near / (near - f)}
                            : std::array<double, 4>{0, 0, -1, -2 * near};
  p.m[3] = {0, 0, -1, 0};
  return p;
}

Camera look_at(Vec3f eye, Vec3f target, Vec3f up, float yfov) {
  Camera c;
  c.eye = eye;
  c.w = normalize(eye - target);
  c.u = normalize(cross(up, c.w));
  if (!(dot(c.u, c.u) > 0)) c.u = normalize(cross(Vec3f{0, 0, 1}, c.w));
  c.v = cross(c.w, c.u);
  c.yfov = yfov;
  return c;
}

Camera fit_bounds(const Camera& view, const Bounds3f& bounds, float aspect) {
  Camera c = view;
  Vec3f lo{-1, -1, -1}, hi{1, 1, 1};  // empty bounds: the unit sphere's box at the origin
  if (!bounds.empty()) lo = bounds.lo, hi = bounds.hi;
  const Vec3f centre = 0.5f * (lo + hi);
  // The box's size, with a floor for a point: the least gap left between the eye and the
  // nearest corner is a share of it.
  const float size = std::max(length(hi - lo), 1e-3f * std::max(1.0f, length(centre)));
  float max_x = 0, max_y = 0, max_z = -kInfinity, dist = 0;
  const float tan_y = std::tan(0.5f * view.yfov), tan_x = tan_y * aspect;
  for (int k = 0; k < 8; ++k) {
    const Vec3f p{(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z};
    const Vec3f d = p - centre;
    const float x = std::fabs(dot(d, view.u)), y = std::fabs(dot(d, view.v)), z = dot(d, view.w);
    max_x = std::max(max_x, x);
    max_y = std::max(max_y, y);
    max_z = std::max(max_z, z);
    // Perspective: the corner at depth (dist - z) projects to x / (dist - z) <= tan_x.
    dist = std::max(dist, z + std::max(x / tan_x, y / tan_y));
  }
  if (view.projection == Projection::Orthographic) {
    c.ymag = std::max({max_y, max_x / aspect, 1e-6f * size});
    c.xmag = c.ymag * aspect;
    dist = max_z + size;  // in front of every corner; orthographic rays start on the image plane
    c.znear = 0;
  } else {
    dist = std::max(dist, max_z + 1e-3f * size);
    c.znear = dist * 1e-4f;
  }
  c.eye = centre + view.w * dist;
  return c;
}

Camera frame_bounds(const Bounds3f& bounds, float aspect) {
  constexpr float kYfov = 0.6911f;  // 39.6 degrees, Blender's default 50 mm lens
  // The frame only: fit_bounds places the eye (far from the origin too, without rounding).
  const Vec3f dir = normalize(Vec3f{0.5f, 0.4f, 1.0f});
  Camera c = fit_bounds(look_at(dir, {0, 0, 0}, {0, 1, 0}, kYfov), bounds, aspect);
  c.name = "auto-framed";
  return c;
}

Light default_key_light(const Camera& cam) {
  Light l;
  l.name = "default key light";
  l.type = LightType::Directional;
  l.intensity = kPi;
  l.direction = normalize(0.5f * cam.u - 0.8f * cam.v - 1.0f * cam.w);
  return l;
}

}  // namespace penumbra
