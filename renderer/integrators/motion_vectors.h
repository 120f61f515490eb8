// The motion-vector layer ("vector"): for each pixel, where the surface its centre ray sees was
// on the screen one frame before and will be one frame after, in Blender Cycles' Vector pass
// layout; and beside it the same surface's camera-space velocity ("velocity"). The scenes and
// cameras at the neighbouring times are given: this module poses and loads nothing.
#pragma once

// Per pixel (4 floats, pixels of render_window(config), rows from the top):
//   X, Y  the surface's raster position in the previous frame minus its position now;
//   Z, W  its position now minus its position in the next frame;
// in pixels, +X to the right and +Y UP the image (Cycles' raster axes, whose rows run from the
// bottom). 0 where the centre ray misses, and for a frame whose camera cannot see the point
// (behind a perspective camera's eye).

#include <string>
#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/integrators/render_config.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// The channels per pixel of the vector layer.
inline constexpr int kMotionVectorChannels = 4;

/// The channels per pixel of the velocity layer (camera-space velocity: X, Y, Z).
inline constexpr int kVelocityChannels = 3;

/// A neighbouring frame: the render's scene posed at another time (the same instances, meshes
/// and shapes in the same order: check_motion_frame) and the camera as placed at that time.
struct MotionFrame {
  const Scene* scene = nullptr;  ///< not owned; must outlive the call
  Camera camera;
};

/// Why `other` cannot stand for `scene` at another time (another count of instances, meshes,
/// shapes, a mesh's triangles or vertices, or an instance placing another mesh or shape);
/// empty when it can.
std::string check_motion_frame(const Scene& scene, const Scene& other);

/// Raster position of world point `p` through `camera` for a width x height image, x to the
/// right and y down as generate_camera_ray takes it (the inverse of its pinhole ray). False
/// when p is not in front of a perspective camera's eye.
bool project_to_raster(const Camera& camera, int width, int height, Vec3f p, Vec2f& raster);

/// The vector layer of `scene` through `camera` under `config` (size, window, tiles, threads):
/// per pixel the centre ray's first visible hit (the pinhole ray, with no lens or pixel filter,
/// as one sample of every integrator), that hit re-evaluated in each frame's scene (a triangle's
/// instance, primitive and barycentrics on the posed, skinned or morphed vertices; a shape's
/// object-space point through the posed instance transform) and projected through each frame's
/// camera. The frames' scenes must pass check_motion_frame. Deterministic for any thread count.
/// With `velocity`, also fills it (kVelocityChannels per pixel of the window) with the same
/// surface point's camera-space velocity in scene units per second: its position in the next
/// frame's camera space minus that in the previous frame's, over the 2 `interval` seconds
/// between them (central difference). Camera space is glTF's: +X right, +Y up, +Z towards the
/// viewer (the camera looks down -Z), so a surface approaching the camera has Z > 0. 0 where the
/// centre ray misses.
std::vector<float> render_motion_vectors(const Scene& scene, const Accelerator& accel, const Camera& camera,
                                         const RenderConfig& config, const MotionFrame& previous,
                                         const MotionFrame& next, std::vector<float>* velocity = nullptr,
                                         double interval = 0);

/// World point `p` in `camera`'s space: +X right, +Y up, +Z behind the camera (it looks down -Z).
Vec3f to_camera_space(const Camera& camera, Vec3f p);

}  // namespace penumbra
