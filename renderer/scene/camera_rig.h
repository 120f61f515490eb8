// Cameras placed by parameters instead of a file: a look-at, an orbit about the bounds' centre,
// Euler angles, and turntables whose orientations are slerped between quaternion keys, with lens
// overrides (vertical field of view, focal length on a sensor, orthographic height, clip planes).
// Wherever the distance is not given the camera is framed tightly on the bounds (fit_bounds), as
// Blender's "frame selected" does.
//
// Orbits and turntables turn about the world's +Y axis (glTF's up): azimuth 0 and elevation 0
// put the camera on the +Z side of the centre looking down -Z; positive azimuth moves it
// counter-clockwise seen from above (towards +X), positive elevation above the centre. An
// orbit at (azimuth, elevation) has the orientation of the Euler angles (azimuth, -elevation, 0)
// (core/quaternion.h), so elevations of +-90 degrees look straight down or up without a
// degenerate frame.
#pragma once

#include <optional>
#include <stdexcept>

#include "renderer/core/quaternion.h"
#include "renderer/scene/camera.h"

namespace penumbra {

/// How the rig places the camera.
enum class CameraPlacement {
  Base,    ///< the base camera's pose (a file camera), or the default framing without one
  LookAt,  ///< eye, target and up
  Orbit,   ///< azimuth, elevation and distance about the bounds' centre
  Euler,   ///< yaw, pitch and roll, at `eye` or framed on the bounds
};

/// A camera described by parameters. Angles are in radians, lengths in scene units, the
/// sensor and focal length in millimetres. Unset lens values keep the base camera's.
struct CameraRig {
  CameraPlacement placement = CameraPlacement::Base;
  Vec3f eye, target, up{0, 1, 0};     ///< LookAt; `eye` is also Euler's position when has_eye
  bool has_eye = false;               ///< Euler: at `eye`; false: framed on the bounds
  double azimuth = 0, elevation = 0;  ///< Orbit; elevation in [-pi/2, pi/2]
  std::optional<double> distance;     ///< Orbit: eye to centre; none = tight fit
  EulerAngles euler;                  ///< Euler
  int turntable_frames = 0;           ///< > 0: an Orbit turned by 2 pi * turntable_frame / turntable_frames
  long long turntable_frame = 0;      ///< any integer; frame N is frame 0 again
  double turntable_phase = 0;         ///< frames added to turntable_frame (finite, |phase| <= 2^20):
                                      ///< shutter times and neighbouring frames between the frames

  std::optional<double> yfov;          ///< vertical field of view, in (0, pi)
  std::optional<double> focal_mm;      ///< with sensor_mm: the field of view
  double sensor_mm = 36;               ///< spans the image's larger side (Blender's "auto" fit)
  std::optional<double> ortho_height;  ///< orthographic, full image height
  bool ortho_fit = false;              ///< orthographic, height fitted to the bounds
  std::optional<double> znear, zfar;   ///< clip distances along the view axis
};

/// Throws std::invalid_argument naming the value for a rig no camera can follow: a non-finite
/// value, eye == target, a zero up vector or one parallel to the view direction, an elevation
/// outside [-pi/2, pi/2], a distance <= 0, a field of view outside (0, pi), a focal length,
/// sensor or orthographic height <= 0, both a field of view and a focal length, an
/// orthographic camera with either, near < 0, far <= near, turntable_frames < 0, a
/// turntable_phase that is not finite or is past 2^20 frames, or a fitted
/// orthographic height on a placement that never frames (a look-at, an orbit with a distance,
/// Euler angles at an eye; rig_camera also refuses it on a base camera's pose).
void check_rig(const CameraRig& rig);

/// True when the rig frames the bounds (fit_bounds chooses the distance or the orthographic
/// height): placement Base without a base camera, Orbit without a distance (also as a
/// turntable), and Euler without an eye.
bool rig_frames_bounds(const CameraRig& rig, bool has_base_camera);

/// The camera the rig describes, for an image of the given aspect (width / height). `base` is
/// the file's camera (nullptr: none; the default is frame_bounds' perspective camera). The
/// pose comes from the placement, the lens from the rig where it sets one and from the base
/// otherwise; a framed turntable keeps one distance for the whole turn, the largest the tight
/// fit needs at any of its frames. The clip planes are the rig's when set. Throws as
/// check_rig(), and std::invalid_argument when the camera leaves single precision (an eye,
/// field of view or height that overflows or vanishes as a float, an eye or near plane past
/// kMaxCameraReach) or the far plane is not beyond the near plane. `bounds` are read only where the rig
/// frames them (rig_frames_bounds) or orbits their centre.
Camera rig_camera(const CameraRig& rig, const Camera* base, const Bounds3f& bounds, float aspect);

/// `cam` turned to orientation `q`: u, v, w are the rotated +X, +Y, +Z axes; eye and lens kept.
Camera oriented(const Camera& cam, const Quat& q);

/// The orientation of a camera's frame (u, v, w as the columns of a rotation).
Quat camera_orientation(const Camera& cam);

/// The orientation of an orbit at (azimuth, elevation): Ry(azimuth) * Rx(-elevation).
Quat orbit_orientation(double azimuth, double elevation);

/// The orientation of turntable frame `frame` of `frames` starting at `azimuth`: slerped between
/// keys a quarter turn apart (each key an orbit_orientation), so the camera turns about +Y at
/// constant angular speed and frame `frames` is frame 0 again. `phase` (finite) adds a part of
/// a frame or whole frames: phase 1 is frame + 1 bit for bit, phase 0 is the frame itself.
/// frames >= 1.
Quat turntable_orientation(double azimuth, double elevation, long long frame, int frames, double phase = 0);

/// The vertical field of view (radians) of a lens of `focal_mm` on a sensor of `sensor_mm`
/// spanning the larger side of an image of the given aspect (width / height).
double focal_length_yfov(double focal_mm, double sensor_mm, float aspect);

}  // namespace penumbra
