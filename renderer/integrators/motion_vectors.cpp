// The motion-vector layer.
#include "renderer/integrators/motion_vectors.h"

#include <cmath>

#include "renderer/core/parallel.h"
#include "renderer/integrators/visibility.h"

namespace penumbra {

namespace {

/// Where hit `hit` of `ray` in `scene` lies, as object space of its instance: the triangle's
/// primitive and barycentrics (kept to be re-evaluated elsewhere), or a shape's point.
struct SurfacePoint {
  uint32_t instance = Hit::kInvalidId;
  uint32_t prim = 0;
  float u = 0, v = 0;
  Vec3f object;  ///< shapes: the hit point in the instance's object space
};

/// The world position of `sp` in `scene` (the render's or a neighbouring frame's).
Vec3f world_point(const Scene& scene, const SurfacePoint& sp) {
  const Instance& inst = scene.instances[sp.instance];
  if (inst.shape >= 0) return apply_point(inst.to_world, sp.object);
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const size_t k = size_t(sp.prim) * 3;
  const Vec3f a = mesh.positions[mesh.indices[k]], b = mesh.positions[mesh.indices[k + 1]],
              c = mesh.positions[mesh.indices[k + 2]];
  return apply_point(inst.to_world, a * (1 - sp.u - sp.v) + b * sp.u + c * sp.v);
}

std::string count_text(const char* what, size_t a, size_t b) {
  return std::string(what) + ": " + std::to_string(b) + " instead of " + std::to_string(a);
}

}  // namespace

std::string check_motion_frame(const Scene& scene, const Scene& other) {
  if (scene.instances.size() != other.instances.size())
    return count_text("instances", scene.instances.size(), other.instances.size());
  if (scene.meshes.size() != other.meshes.size())
    return count_text("meshes", scene.meshes.size(), other.meshes.size());
  if (scene.shapes.size() != other.shapes.size())
    return count_text("shapes", scene.shapes.size(), other.shapes.size());
  for (size_t i = 0; i < scene.instances.size(); ++i)
    if (scene.instances[i].mesh != other.instances[i].mesh ||
        scene.instances[i].shape != other.instances[i].shape)
      return "instances[" + std::to_string(i) + "] places another mesh or shape";
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh &a = scene.meshes[m], &b = other.meshes[m];
    if (a.indices != b.indices || a.positions.size() != b.positions.size())
      return "meshes[" + std::to_string(m) + "] ('" + a.name + "') has other triangles or vertices";
  }
  return "";
}

bool project_to_raster(const Camera& cam, int width, int height, Vec3f p, Vec2f& raster) {
  const Vec3f d = p - cam.eye;
  const float x = dot(d, cam.u), y = dot(d, cam.v), depth = dot(d, -cam.w);
  const float aspect = float(width) / float(height);
  float sx, sy;  // -1 .. +1 across the image, +1 at the right and the top
  if (cam.projection == Projection::Orthographic) {
    sx = x / (cam.ymag * aspect);
    sy = y / cam.ymag;
  } else {
    if (!(depth > 0)) return false;
    const float tan_y = std::tan(0.5f * cam.yfov);
    sx = x / (depth * tan_y * aspect);
    sy = y / (depth * tan_y);
  }
  raster = {(sx + 1) * 0.5f * float(width), (1 - sy) * 0.5f * float(height)};
  return std::isfinite(raster.x) && std::isfinite(raster.y);
}

Vec3f to_camera_space(const Camera& cam, Vec3f p) {
  const Vec3f d = p - cam.eye;
  return {dot(d, cam.u), dot(d, cam.v), dot(d, cam.w)};
}

std::vector<float> render_motion_vectors(const Scene& scene, const Accelerator& accel, const Camera& camera,
                                         const RenderConfig& config, const MotionFrame& previous,
                                         const MotionFrame& next, std::vector<float>* velocity,
                                         double interval) {
  const PixelWindow win = render_window(config);
  const size_t w = size_t(win.width());
  std::vector<float> out(w * size_t(win.height()) * kMotionVectorChannels, 0.0f);
  if (velocity) velocity->assign(w * size_t(win.height()) * kVelocityChannels, 0.0f);
  const float per_second = interval > 0 ? float(0.5 / interval) : 0.0f;
  const bool filter = scene_needs_hit_filter(scene);
  TileScheduler scheduler(win, config.tile_size, config.threads);
  scheduler.for_each_tile([&](const PixelWindow& tile) {
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) {
        const Vec2f centre{float(x) + 0.5f, float(y) + 0.5f};
        const Ray ray = generate_camera_ray(camera, config.width, config.height, centre.x, centre.y);
        Hit hit;
        if (!intersect_visible(scene, accel, ray, hit, filter)) continue;
        // The surface point, kept in the terms each frame's scene re-evaluates.
        SurfacePoint sp{hit.geom_id, hit.prim_id, hit.u, hit.v, {}};
        // A shape's point through its instance as the ray met it (under motion blur, at the ray's
        // time); its motion is measured from its frame pose, which is where the centre ray's
        // time, the shutter's middle, places it unless the shutter is offset.
        Instance moving;
        const Instance& inst = instance_at(scene, hit.geom_id, ray.time, moving);
        if (inst.shape >= 0) sp.object = apply_point(inst.to_object, ray.org + ray.dir * hit.t);
        if (inst.shape < 0 && renders_as_curves(scene.meshes[size_t(inst.mesh)])) {
          // A point or segment: the axis point nearest the hit, as the parameter along its
          // (a, b, b) triangle's first edge.
          const Mesh& m = scene.meshes[size_t(inst.mesh)];
          const Vec3f a = m.positions[m.indices[3 * size_t(hit.prim_id)]],
                      b = m.positions[m.indices[3 * size_t(hit.prim_id) + 1]];
          const Vec3f p = inst.identity ? ray.org + ray.dir * hit.t
                                        : apply_point(inst.to_object, ray.org + ray.dir * hit.t);
          const float dd = dot(b - a, b - a);
          sp.u = dd > 0 ? std::clamp(dot(p - a, b - a) / dd, 0.0f, 1.0f) : 0.0f;
          sp.v = 0;
        }
        const size_t pixel = size_t(y - win.y0) * w + size_t(x - win.x0);
        const Vec3f was = world_point(*previous.scene, sp), will = world_point(*next.scene, sp);
        if (velocity) {
          const Vec3f v =
              (to_camera_space(next.camera, will) - to_camera_space(previous.camera, was)) * per_second;
          for (int c = 0; c < kVelocityChannels; ++c)
            (*velocity)[pixel * kVelocityChannels + size_t(c)] = v[c];
        }
        // Where it is now (the projection of the point itself, not the pixel centre, so that
        // a still surface under a still camera moves by exactly 0) and in each frame.
        Vec2f now, before, after;
        if (!project_to_raster(camera, config.width, config.height, world_point(scene, sp), now)) continue;
        const size_t i = pixel * kMotionVectorChannels;
        if (project_to_raster(previous.camera, config.width, config.height, was, before)) {
          out[i] = before.x - now.x;
          out[i + 1] = now.y - before.y;  // +Y up
        }
        if (project_to_raster(next.camera, config.width, config.height, will, after)) {
          out[i + 2] = now.x - after.x;
          out[i + 3] = after.y - now.y;  // +Y up
        }
      }
  });
  return out;
}

}  // namespace penumbra
