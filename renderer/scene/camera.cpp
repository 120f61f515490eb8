// Camera ray generation and framing.
#include "renderer/scene/camera.h"

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

Ray generate_camera_ray(const Camera& cam, int width, int height, float x, float y) {
  return raster_ray(cam, camera_raster(cam, width, height), x, y);
}

void generate_camera_rays(const Camera& cam, int width, int height, float x, float y, float step,
                          Ray out[3]) {
  const CameraRaster m = camera_raster(cam, width, height);
  out[0] = raster_ray(cam, m, x, y);
  out[1] = raster_ray(cam, m, x + step, y);
  out[2] = raster_ray(cam, m, x, y + step);
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

Camera frame_bounds(const Bounds3f& bounds, float aspect) {
  constexpr float kYfov = 0.6911f;  // 39.6 degrees, Blender's default 50 mm lens
  Vec3f center{0, 0, 0};
  float radius = 1;
  if (!bounds.empty()) {
    center = bounds.center();
    radius = std::max(0.5f * length(bounds.extent()), 1e-6f);
  }
  const float half_fov = 0.5f * std::min(kYfov, 2.0f * std::atan(std::tan(0.5f * kYfov) * aspect));
  const float dist = radius / std::sin(half_fov) * 1.05f;
  const Vec3f dir = normalize(Vec3f{0.5f, 0.4f, 1.0f});
  Camera c = look_at(center + dir * dist, center, {0, 1, 0}, kYfov);
  c.name = "auto-framed";
  c.znear = dist * 1e-4f;
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
