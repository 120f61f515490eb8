// Shadow maps: the light's faces as cameras, depth rendered by the rasteriser, PCF lookups.
#include "renderer/raster/shadow_map.h"

#include <algorithm>
#include <cmath>

#include "renderer/raster/rasterize.h"
#include "renderer/scene/camera.h"

namespace penumbra {

namespace {

/// Spots whose cone is at most this wide (half-angle, radians) get one perspective map.
constexpr float kMaxSpotHalfAngle = kPi / 6;

struct FaceContext {
  const ShadowFace& face;
};

Ray face_ray(const void* context, float x, float y) {
  const ShadowFace& f = static_cast<const FaceContext*>(context)->face;
  return generate_camera_ray(f.view, f.size, f.size, x, y);
}

// A perspective face at `eye` looking along `dir` with half-angle tan `tan_half`.
Camera perspective_face(Vec3f eye, Vec3f dir, float tan_half, float znear) {
  const Vec3f up = std::fabs(dir.y) > 0.9f ? Vec3f{0, 0, 1} : Vec3f{0, 1, 0};
  Camera c = look_at(eye, eye + dir, up, 2 * std::atan(tan_half));
  c.znear = znear;
  c.zfar = kInfinity;
  return c;
}

std::vector<Camera> light_faces(const Light& light, const Bounds3f& bounds, int size) {
  const Vec3f centre = bounds.empty() ? Vec3f{} : bounds.center();
  const float radius = bounds.empty() ? 1.0f : std::max(0.5f * length(bounds.extent()), 1e-6f);
  // A few texels beyond each face's frustum, so that filtering at face borders stays inside.
  const float margin = 1.0f + 4.0f / float(size);
  const float znear = 1e-4f * radius;
  std::vector<Camera> faces;
  if (light.type == LightType::Directional) {
    const Vec3f dir = normalize(light.direction);
    const Vec3f up = std::fabs(dir.y) > 0.9f ? Vec3f{0, 0, 1} : Vec3f{0, 1, 0};
    const float dist = radius * 1.01f + 1e-3f;
    Camera c = look_at(centre - dir * dist, centre, up, 1);
    c.projection = Projection::Orthographic;
    c.ymag = c.xmag = radius * margin;
    c.znear = 0;
    c.zfar = 2 * dist;
    faces.push_back(c);
  } else if (light.type == LightType::Spot && light.outer_cone <= kMaxSpotHalfAngle) {
    faces.push_back(perspective_face(light.position, normalize(light.direction),
                                     std::tan(light.outer_cone) * margin, znear));
  } else {
    const Vec3f axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const Vec3f& a : axes) faces.push_back(perspective_face(light.position, a, margin, znear));
  }
  return faces;
}

void render_face(const Scene& scene, ShadowFace& face, int threads) {
  face.depth.assign(size_t(face.size) * size_t(face.size), kInfinity);
  FaceContext ctx{face};
  RasterView view;
  view.view = view_matrix(face.view);
  view.projection = projection_matrix(face.view, 1.0f);
  view.far_plane = std::isfinite(face.view.zfar);
  view.width = view.height = face.size;
  view.ray = &face_ray;
  view.ray_context = &ctx;
  RasterPass pass;
  pass.window = {0, 0, face.size, face.size};
  pass.tile_size = 64;
  pass.threads = threads;
  pass.spp = 1;
  pass.cull_back_faces = false;
  pass.blend = RasterBlend::Threshold;
  pass.depth_only = true;
  rasterize(scene, view, pass, [&](const RasterTile& t) {
    size_t i = 0;
    for (int y = t.pixels.y0; y < t.pixels.y1; ++y)
      for (int x = t.pixels.x0; x < t.pixels.x1; ++x, ++i)
        face.depth[size_t(y) * size_t(face.size) + size_t(x)] = t.opaque[i].depth;
  });
}

// The face of a cube map that sees direction d (from the light).
int cube_face(Vec3f d) {
  const Vec3f a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0 ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0 ? 2 : 3;
  return d.z >= 0 ? 4 : 5;
}

}  // namespace

uint64_t shadow_map_bytes(const Scene& scene, int size) {
  uint64_t faces = 0;
  for (const Light& l : scene.lights)
    faces +=
        l.type == LightType::Directional || (l.type == LightType::Spot && l.outer_cone <= kMaxSpotHalfAngle)
            ? 1
            : 6;
  return faces * uint64_t(size) * uint64_t(size) * sizeof(float);
}

ShadowMaps build_shadow_maps(const Scene& scene, int size, int threads) {
  ShadowMaps maps;
  const Bounds3f bounds = compute_bounds(scene);
  for (const Light& light : scene.lights) {
    ShadowMap m;
    for (const Camera& c : light_faces(light, bounds, size)) {
      ShadowFace f;
      f.view = c;
      f.size = size;
      f.tan_half = c.projection == Projection::Orthographic ? 0.0f : std::tan(0.5f * c.yfov);
      m.faces.push_back(std::move(f));
    }
    m.cube = m.faces.size() == 6;
    for (ShadowFace& f : m.faces) render_face(scene, f, threads);
    maps.lights.push_back(std::move(m));
  }
  return maps;
}

float shadow_map_visibility(const ShadowMaps& maps, int light, Vec3f p, Vec3f ng) {
  if (light < 0 || size_t(light) >= maps.lights.size()) return 1;
  const ShadowMap& m = maps.lights[size_t(light)];
  if (m.faces.empty()) return 1;
  const ShadowFace& f = m.faces[m.cube ? size_t(cube_face(p - m.faces[0].view.eye)) : 0];
  const Camera& c = f.view;
  const bool ortho = c.projection == Projection::Orthographic;
  const float tan_half = f.tan_half;
  // World size of one texel at p's depth, and the cosine between the surface and the light.
  const float depth0 = dot(p - c.eye, -c.w);
  const float texel = 2.0f * (ortho ? c.ymag : tan_half * std::max(depth0, 0.0f)) / float(f.size);
  const Vec3f to_light = ortho ? c.w : normalize(c.eye - p);
  const float cos_t = std::clamp(std::fabs(dot(ng, to_light)), 0.05f, 1.0f);
  // Normal offset towards the lit side, then a slope-scaled bias along the light's view axis.
  const Vec3f q = p + ng * (dot(ng, to_light) >= 0 ? 1.5f * texel : -1.5f * texel);
  const Vec3f d = q - c.eye;
  const float depth = dot(d, -c.w);
  if (!(depth > 0) && !ortho) return 1;
  const float bias = texel * (1.0f + std::sqrt(1 - cos_t * cos_t) / cos_t);
  const float sx = ortho ? dot(d, c.u) / c.xmag : dot(d, c.u) / (depth * tan_half);
  const float sy = ortho ? dot(d, c.v) / c.ymag : dot(d, c.v) / (depth * tan_half);
  const float x = (sx + 1) * 0.5f * float(f.size) - 0.5f, y = (1 - sy) * 0.5f * float(f.size) - 0.5f;
  if (!(std::fabs(x) < 1e9f && std::fabs(y) < 1e9f)) return 1;
  const int cx = int(std::lround(x)), cy = int(std::lround(y));
  int lit = 0, total = 0;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      const int tx = cx + i, ty = cy + j;
      ++total;
      if (tx < 0 || ty < 0 || tx >= f.size || ty >= f.size) {
        ++lit;
        continue;
      }
      lit += f.depth[size_t(ty) * size_t(f.size) + size_t(tx)] >= depth - bias;
    }
  return float(lit) / float(total);
}

}  // namespace penumbra
