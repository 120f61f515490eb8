// Motion blur of a loaded scene: the shutter and the moving instances' keys.
#include "render/motion.h"

#include <cstdio>
#include <cstring>
#include <vector>

#include "io/files/error.h"
#include "renderer/integrators/motion_vectors.h"
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

namespace {

/// The scene at every step of the shutter: each instance's map, each camera's frame, each light,
/// and (from loaded frames) each mesh's positions and normals, step after step.
struct ShutterSteps {
  std::vector<std::vector<Affine3f>> maps, frames;
  std::vector<std::vector<Vec3f>> positions, normals;
  std::vector<std::vector<Light>> lights;
  bool cameras = true;  ///< every step has the scene's cameras
  bool lit = true;      ///< every step has the scene's lights
};

void record_step(const Scene& at, bool vertices, ShutterSteps& out) {
  for (size_t i = 0; i < at.instances.size(); ++i) out.maps[i].push_back(at.instances[i].to_world);
  out.cameras = out.cameras && at.cameras.size() == out.frames.size();
  for (size_t i = 0; out.cameras && i < at.cameras.size(); ++i)
    out.frames[i].push_back(camera_frame(at.cameras[i]));
  out.lit = out.lit && at.lights.size() == out.lights.size();
  for (size_t i = 0; out.lit && i < at.lights.size(); ++i) out.lights[i].push_back(at.lights[i]);
  if (!vertices) return;
  for (size_t m = 0; m < at.meshes.size(); ++m) {
    const Mesh& mesh = at.meshes[m];
    out.positions[m].insert(out.positions[m].end(), mesh.positions.begin(), mesh.positions.end());
    out.normals[m].insert(out.normals[m].end(), mesh.normals.begin(), mesh.normals.end());
  }
}

/// The steps by posing the kept animation; false (the scene posed back at `frame_time`) when it
/// cannot pose every step.
bool pose_steps(LoadedScene& loaded, const Shutter& s, int steps, double frame_time, const std::string& file,
                ShutterSteps& out) {
  if (!loaded.animation) return false;
  bool posed = true;
  for (int k = 0; k < steps && posed; ++k) {
    const double t = s.open + (s.close - s.open) * double(k) / double(steps - 1);
    posed = pose_gltf_scene(*loaded.animation, t, loaded.scene);
    if (posed) record_step(loaded.scene, false, out);
  }
  if (!pose_gltf_scene(*loaded.animation, frame_time, loaded.scene))
    throw InputError(file, "motion blur", "the scene cannot be posed back at the frame's time");
  return posed;
}

/// The steps from the file loaded at each step's time, each checked against the scene.
void load_steps(const Scene& scene, const Shutter& s, int steps, const std::string& file,
                const LoadAtTime& load_at, ShutterSteps& out) {
  if (!load_at)
    throw InputError(file, "motion blur",
                     "the scene's animation deforms meshes (skins or morph targets) or was not kept with the "
                     "scene, and the scene was not loaded at a time, so the file cannot be loaded at the "
                     "shutter's times to match it (load the scene at a time)");
  for (int k = 0; k < steps; ++k) {
    const double t = s.open + (s.close - s.open) * double(k) / double(steps - 1);
    const LoadedScene frame = load_at(t);
    const std::string why = check_motion_frame(scene, frame.scene);
    if (!why.empty()) {
      char at[64];
      std::snprintf(at, sizeof at, "the scene at %.9g s", t);
      throw InputError(file, at, "motion blur cannot follow the scene to this time (" + why + ")");
    }
    record_step(frame.scene, true, out);
  }
}

/// Whether a light's steps differ in what light_at interpolates.
bool light_moves(const std::vector<Light>& steps) {
  const Light& a = steps.front();
  for (const Light& l : steps) {
    if (std::memcmp(&l.position, &a.position, sizeof(Vec3f)) != 0 ||
        std::memcmp(&l.direction, &a.direction, sizeof(Vec3f)) != 0 ||
        std::memcmp(&l.color, &a.color, sizeof(Vec3f)) != 0 || l.intensity != a.intensity)
      return true;
  }
  return false;
}

template <class T>
bool differ(const std::vector<T>& keys, size_t count) {
  for (size_t i = count; i < keys.size(); ++i)
    if (std::memcmp(&keys[i], &keys[i % count], sizeof(T)) != 0) return true;
  return false;
}

}  // namespace

std::string set_scene_motion(LoadedScene& loaded, const RenderSpec& spec, double frame_time,
                             const std::string& file, const LoadAtTime& load_at) {
  Scene& scene = loaded.scene;
  scene.instance_motion.clear();
  scene.light_motion.clear();
  for (Camera& c : scene.cameras) c.motion.clear();
  for (Mesh& m : scene.meshes) {
    m.motion_positions = {};
    m.motion_normals = {};
    m.motion_steps = 0;
  }
  if (!spec.motion_blur) return "";
  const Shutter s = shutter_interval(spec, frame_time);
  char text[64];
  std::snprintf(text, sizeof text, "%.17g..%.17g", s.open, s.close);
  if (loaded.info.animation_count == 0) return text;  // nothing moves
  const int steps = spec.motion_steps;
  const auto fresh = [&] {
    ShutterSteps st;
    st.maps.resize(scene.instances.size());
    st.frames.resize(scene.cameras.size());
    st.lights.resize(scene.lights.size());
    st.positions.resize(scene.meshes.size());
    st.normals.resize(scene.meshes.size());
    return st;
  };
  ShutterSteps st = fresh();
  if (!pose_steps(loaded, s, steps, frame_time, file, st)) {
    st = fresh();
    load_steps(scene, s, steps, file, load_at, st);
  }
  scene.instance_motion.resize(scene.instances.size());
  bool any = false;
  for (size_t i = 0; i < st.maps.size(); ++i) {
    if (!moves(st.maps[i])) continue;
    scene.instance_motion[i] = make_motion_keys(st.maps[i]);
    any = true;
  }
  if (!any) scene.instance_motion.clear();
  for (size_t i = 0; st.cameras && i < st.frames.size(); ++i)
    if (moves(st.frames[i])) scene.cameras[i].motion = make_motion_keys(st.frames[i]);
  for (size_t i = 0; st.lit && i < st.lights.size(); ++i)
    if (light_moves(st.lights[i])) {
      scene.light_motion.resize(scene.lights.size());
      scene.light_motion[i] = std::move(st.lights[i]);
    }
  for (size_t m = 0; m < st.positions.size(); ++m) {
    Mesh& mesh = scene.meshes[m];
    const size_t n = mesh.positions.size();
    if (n == 0 || st.positions[m].size() != n * size_t(steps) || !differ(st.positions[m], n)) continue;
    mesh.motion_positions = std::move(st.positions[m]);
    if (st.normals[m].size() == mesh.normals.size() * size_t(steps))
      mesh.motion_normals = std::move(st.normals[m]);
    mesh.motion_steps = uint32_t(steps);
  }
  return text;
}

}  // namespace penumbra
