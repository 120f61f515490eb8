// Motion blur of a loaded scene: the shutter of a frame and the keys of every moving instance
// over it, posed from the file's animation. What the command and the Python module both call
// before a render with RenderSpec::motion_blur.
#pragma once

#include <string>

#include "io/gltf/loader.h"
#include "render/spec.h"

namespace penumbra {

/// When a frame's shutter is open, in seconds.
struct Shutter {
  double open = 0, close = 0;
};

/// The shutter of the frame at `frame_time` seconds: spec.shutter frame intervals (1 / spec.fps)
/// long, centred spec.shutter_offset frames after the frame's time (centred on it by default).
Shutter shutter_interval(const RenderSpec& spec, double frame_time);

/// With spec.motion_blur, fills loaded.scene.instance_motion: the scene posed at
/// spec.motion_steps times spread evenly over the shutter (key k at open + k (close - open) /
/// (steps - 1), which Ray::time k / (steps - 1) meets), each instance whose map changes given its
/// maps as keys (make_motion_keys), and the scene posed back at `frame_time`; without it, or
/// when the file has no animation, clears it. Returns the shutter as the render identity records
/// it ("open..close" seconds; empty without motion blur). Throws InputError(file, "motion blur")
/// when the file's animation cannot be posed that way: it deforms meshes (skins, morph targets),
/// which this motion blur does not cover, or the scene was loaded without a time and
/// GltfLoadOptions::keep_animation (LoadedScene::animation is null for both).
std::string set_scene_motion(LoadedScene& loaded, const RenderSpec& spec, double frame_time,
                             const std::string& file);

}  // namespace penumbra
