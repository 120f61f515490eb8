// Motion blur of a loaded scene: the shutter of a frame and the keys of every moving instance
// over it, posed from the file's animation. What the command and the Python module both call
// before a render with RenderSpec::motion_blur.
#pragma once

#include <functional>
#include <string>

#include "io/gltf/loader.h"
#include "render/spec.h"

namespace penumbra {

/// Loads the render's scene file posed at `time` seconds, with the options the render's own
/// scene was loaded with (the vector layer's neighbouring frames, the steps of deformation
/// motion blur). Throws as load_gltf does.
using LoadAtTime = std::function<LoadedScene(double time)>;

/// When a frame's shutter is open, in seconds.
struct Shutter {
  double open = 0, close = 0;
};

/// The shutter of the frame at `frame_time` seconds: spec.shutter frame intervals (1 / spec.fps)
/// long, centred spec.shutter_offset frames after the frame's time (centred on it by default).
Shutter shutter_interval(const RenderSpec& spec, double frame_time);

/// With spec.motion_blur, fills the scene's motion over the shutter from the scene posed at
/// spec.motion_steps times spread evenly over it (key k at open + k (close - open) / (steps - 1),
/// which Ray::time k / (steps - 1) meets): each instance whose map changes gets its maps as keys
/// (Scene::instance_motion, make_motion_keys), each file camera that moves its frames
/// (Camera::motion), each punctual light that moves or changes the light at every step
/// (Scene::light_motion), and each mesh whose vertices move (skins, morph targets) its positions
/// and normals at every step (Mesh::motion_positions, motion_normals). A file whose animation moves
/// only placements is posed by pose_gltf_scene and posed back at `frame_time`; one that deforms
/// meshes, or whose animation was not kept, is loaded at each step's time through `load_at`,
/// each load checked against the scene (check_motion_frame). Without motion blur, or when the
/// file has no animation, clears all of it. Returns the shutter as the render identity records
/// it ("open..close" seconds; empty without motion blur). Throws InputError(file, "motion blur")
/// when the animation cannot be followed: no kept animation and no `load_at`, or a step's load
/// with other meshes or instances than the scene; and whatever `load_at` throws. Give `load_at`
/// only for a scene loaded at `frame_time` (GltfLoadOptions::time): a scene loaded at its rest
/// pose would not match loads at the shutter's times.
std::string set_scene_motion(LoadedScene& loaded, const RenderSpec& spec, double frame_time,
                             const std::string& file, const LoadAtTime& load_at = {});

}  // namespace penumbra
