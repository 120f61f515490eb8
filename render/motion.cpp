// Motion blur of a loaded scene: the shutter and the moving instances' keys.
#include "render/motion.h"

#include <cstdio>
#include <cstring>
#include <vector>

#include "io/files/error.h"
#include "renderer/scene/camera.h"

namespace penumbra {

Shutter shutter_interval(const RenderSpec& spec, double frame_time) {
  const double centre = frame_time + double(spec.shutter_offset) / spec.fps;
  const double half = 0.5 * double(spec.shutter) / spec.fps;
  return {centre - half, centre + half};
}

namespace {

/// Whether the maps of one thing over the shutter differ (bit for bit) and are all invertible.
bool moves(const std::vector<Affine3f>& maps) {
  bool differ = false;
  for (size_t k = 1; k < maps.size() && !differ; ++k)
    differ = std::memcmp(&maps[k], &maps[0], sizeof(Affine3f)) != 0;
  Affine3f inverse_map;
  for (const Affine3f& a : maps)
    if (!inverse(a, inverse_map)) return false;  // a key that collapses it: it stays at its frame pose
  return differ;
}

}  // namespace

std::string set_scene_motion(LoadedScene& loaded, const RenderSpec& spec, double frame_time,
                             const std::string& file) {
  Scene& scene = loaded.scene;
  scene.instance_motion.clear();
  for (Camera& c : scene.cameras) c.motion.clear();
  if (!spec.motion_blur) return "";
  const Shutter s = shutter_interval(spec, frame_time);
  char text[64];
  std::snprintf(text, sizeof text, "%.17g..%.17g", s.open, s.close);
  if (loaded.info.animation_count == 0) return text;  // nothing moves
  if (!loaded.animation)
    throw InputError(
        file, "motion blur",
        "the scene's animation cannot be posed over the shutter: it deforms meshes (skins or morph "
        "targets), which motion blur does not cover, or the scene was loaded without a time and "
        "its animation kept");
  const int steps = spec.motion_steps;
  std::vector<std::vector<Affine3f>> maps(scene.instances.size()), frames(scene.cameras.size());
  for (int k = 0; k < steps; ++k) {
    const double t = s.open + (s.close - s.open) * double(k) / double(steps - 1);
    if (!pose_gltf_scene(*loaded.animation, t, scene))
      throw InputError(file, "motion blur",
                       "the animation deforms meshes (skins or morph targets): only moving nodes, instances, "
                       "cameras and their transforms are blurred");
    for (size_t i = 0; i < scene.instances.size(); ++i) maps[i].push_back(scene.instances[i].to_world);
    for (size_t i = 0; i < scene.cameras.size(); ++i) frames[i].push_back(camera_frame(scene.cameras[i]));
  }
  if (!pose_gltf_scene(*loaded.animation, frame_time, scene))
    throw InputError(file, "motion blur", "the scene cannot be posed back at the frame's time");
  scene.instance_motion.resize(scene.instances.size());
  bool any = false;
  for (size_t i = 0; i < maps.size(); ++i) {
    if (!moves(maps[i])) continue;
    scene.instance_motion[i] = make_motion_keys(maps[i]);
    any = true;
  }
  if (!any) scene.instance_motion.clear();
  for (size_t i = 0; i < frames.size(); ++i)
    if (moves(frames[i])) scene.cameras[i].motion = make_motion_keys(frames[i]);
  return text;
}

}  // namespace penumbra
