// The camera flags `render` and `info` share: --look-at, --orbit, --euler (with --position),
// --turntable (with --turntable-elevation), and the lens flags --fov, --focal-length, --sensor,
// --ortho, --near and --far. check_camera_args turns them into a checked CameraRig before the
// scene loads; choose_camera applies it to the loaded scene.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "renderer/scene/camera_rig.h"

namespace penumbra::cli {

/// The camera flags as typed; empty strings are flags not given.
struct CameraArgs {
  std::vector<std::string> look_at;  ///< EYE TARGET [UP], each "x,y,z"
  std::string orbit;                 ///< "AZ,EL[,DIST]", degrees and scene units
  std::string euler;                 ///< "YAW,PITCH,ROLL", degrees
  std::string position;              ///< "x,y,z": the eye for --euler
  std::string turntable;             ///< N frames per turn
  std::string turntable_elevation;   ///< degrees
  std::string fov, focal_length, sensor, ortho, near, far;
};

/// Declares the camera flags on `app`, bound to `args`.
void add_camera_options(CLI::App& app, CameraArgs& args);

/// True when a flag places the camera (--look-at, --orbit, --euler, --turntable): the file's
/// camera is then replaced, and only a --camera given explicitly lends its lens.
bool places_camera(const CameraArgs& args);

/// The turntable's frames per turn (0 without --turntable). Throws UsageError as below.
int turntable_frames(const CameraArgs& args);

/// The rig the flags describe, for turntable frame `frame` (any integer; 0 when none). Throws
/// UsageError naming the flag for values that cannot be parsed or that no camera can follow
/// (zero up vector, eye == target, fov <= 0 or >= 180, --turntable N < 1, ...) and for flags
/// that contradict each other.
CameraRig check_camera_args(const CameraArgs& args, long long frame = 0);

/// The scene camera the flags start from: the one `camera` (--camera) names, else the first
/// unless the flags place the camera; -1 for none. Throws InputError as find_camera.
int base_camera_index(const Scene& scene, const std::string& camera, const CameraArgs& args,
                      const std::string& file);

/// The image size from --width and --height (0 = not given): 960 wide by default, the other side
/// following the aspect `hint` (width / height) of the camera. Throws UsageError past 16384.
std::pair<int, int> image_size(int width, int height, float hint);

/// The aspect hint of scene camera `index` (16:9 for none or one without a hint).
float aspect_hint(const Scene& scene, int index);

/// The camera a render of `scene` uses for an image of `width` x `height`: the rig applied to
/// camera `index` of the scene (-1: none) as CameraRig documents. Throws UsageError with the
/// rig's message when the result is not a camera (a far plane before the near one). `bounds`:
/// compute_bounds(scene) when the caller has it (a turntable placed many times), else null.
Camera choose_camera(const CameraRig& rig, const Scene& scene, int index, int width, int height,
                     const Bounds3f* bounds = nullptr);

/// The camera a render with these flags uses, with what chose it.
struct ChosenView {
  Camera camera;
  CameraRig rig;
  int index = -1;  ///< the scene camera it starts from (base_camera_index), -1: none
  int width = 0, height = 0;
};

/// check_camera_args(args, frame), base_camera_index, image_size(width, height) for that
/// camera's aspect hint and choose_camera, then validate_camera (failures: InputError naming
/// `file` and the camera): the camera `render` places for the same flags.
ChosenView choose_view(const Scene& scene, const std::string& file, const std::string& camera,
                       const CameraArgs& args, int width, int height, long long frame = 0);

}  // namespace penumbra::cli
