// Motion blur of a loaded scene: the shutter and the moving instances' keys.
#include "render/motion.h"

#include <cstdio>
#include <cstring>
#include <vector>

#include "io/files/error.h"

namespace penumbra {

Shutter shutter_interval(const RenderSpec& spec, double frame_time) {
  const double centre = frame_time + double(spec.shutter_offset) / spec.fps;
  const double half = 0.5 * double(spec.shutter) / spec.fps;
  return {centre - half, centre + half};
}

std::string set_scene_motion(LoadedScene& loaded, const RenderSpec& spec, double frame_time,
                             const std::string& file) {
  Scene& scene = loaded.scene;
  scene.instance_motion.clear();
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
  std::vector<std::vector<Affine3f>> maps(scene.instances.size());
  for (int k = 0; k < steps; ++k) {
    const double t = s.open + (s.close - s.open) * double(k) / double(steps - 1);
    if (!pose_gltf_scene(*loaded.animation, t, scene))
      throw InputError(file, "motion blur",
                       "the animation deforms meshes (skins or morph targets): only moving nodes, instances "
                       "and their transforms are blurred");
    for (size_t i = 0; i < scene.instances.size(); ++i) maps[i].push_back(scene.instances[i].to_world);
  }
  if (!pose_gltf_scene(*loaded.animation, frame_time, scene))
    throw InputError(file, "motion blur", "the scene cannot be posed back at the frame's time");
  scene.instance_motion.resize(scene.instances.size());
  bool any = false;
  for (size_t i = 0; i < maps.size(); ++i) {
    const auto& m = maps[i];
    bool moves = false;
    for (size_t k = 1; k < m.size() && !moves; ++k) moves = std::memcmp(&m[k], &m[0], sizeof(Affine3f)) != 0;
    if (!moves) continue;
    Affine3f inverse_map;
    bool invertible = true;
    for (const Affine3f& a : m) invertible = invertible && inverse(a, inverse_map);
    if (!invertible) continue;  // a key that collapses the instance: it stays at its frame pose
    scene.instance_motion[i] = make_motion_keys(m);
    any = true;
  }
  if (!any) scene.instance_motion.clear();
  return text;
}

}  // namespace penumbra
