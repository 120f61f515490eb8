// The camera flags: declaration, parsing and the checks that need no scene.
#include "apps/penumbra/camera_options.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <tuple>

#include "apps/penumbra/cli_support.h"
#include "apps/penumbra/scene_setup.h"
#include "io/files/error.h"
#include "renderer/scene/camera.h"

namespace penumbra::cli {

namespace {

/// Most turntable frames per turn.
constexpr long long kMaxTurntableFrames = 36000;

constexpr double kDegree = M_PI / 180;

/// The largest magnitude a camera number may have: the largest finite float.
constexpr double kMaxSingle = std::numeric_limits<float>::max();

/// The largest azimuth or Euler angle, in degrees.
constexpr double kMaxAngleDegrees = 1e6;

/// True when all of `text` is a finite number, then stored in `v`.
bool read_number(const std::string& text, double& v) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, v);
  return !text.empty() && ec == std::errc() && ptr == end && std::isfinite(v);
}

/// A finite number within single precision, all of `text`; throws UsageError naming `option` and
/// `what`.
double parse_number(const std::string& text, const std::string& option, const std::string& what) {
  double v = 0;
  if (!read_number(text, v))
    throw UsageError(option + ": " + what + " '" + text + "' is not a finite number");
  if (!(std::fabs(v) <= kMaxSingle))
    throw UsageError(option + ": " + what + " '" + text + "' is out of single-precision range");
  return v;
}

/// The comma-separated items of `text`.
std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    items.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return items;
    start = comma + 1;
  }
}

/// Comma-separated finite numbers within single precision, between `lo` and `hi` of them.
std::vector<double> parse_list(const std::string& text, const std::string& option, size_t lo, size_t hi,
                               const std::string& expected) {
  std::vector<double> v;
  for (const std::string& item : split_list(text)) v.push_back(parse_number(item, option, "value"));
  if (v.size() < lo || v.size() > hi)
    throw UsageError(option + ": expected " + expected + ", got '" + text + "'");
  return v;
}

/// An angle of `option` in degrees, checked to lie within kMaxAngleDegrees.
double check_angle(double degrees, const std::string& option, const std::string& what) {
  if (!(std::fabs(degrees) <= kMaxAngleDegrees))
    throw UsageError(option + ": " + what + " " + exact(degrees) + " is outside [-1e6, 1e6] degrees");
  return degrees;
}

Vec3f parse_point(const std::string& text, const std::string& option, const std::string& what) {
  const std::vector<std::string> items = split_list(text);
  double v[3] = {};
  if (items.size() != 3 || !read_number(items[0], v[0]) || !read_number(items[1], v[1]) ||
      !read_number(items[2], v[2]))
    throw UsageError(option + ": " + what + " '" + text + "' is not X,Y,Z (three finite numbers)");
  if (!(std::fabs(v[0]) <= kMaxSingle && std::fabs(v[1]) <= kMaxSingle && std::fabs(v[2]) <= kMaxSingle))
    throw UsageError(option + ": " + what + " '" + text + "' is out of single-precision range");
  return {float(v[0]), float(v[1]), float(v[2])};
}

/// The placement flags: --look-at, --orbit, --euler and --position.
void check_placement(const CameraArgs& a, CameraRig& rig) {
  const int placements = int(!a.look_at.empty()) + int(!a.orbit.empty()) + int(!a.euler.empty());
  if (placements > 1) throw UsageError("--look-at, --orbit and --euler each place the camera: give one");
  if (!a.position.empty() && a.euler.empty())
    throw UsageError("--position places the camera of --euler (--look-at gives its own eye)");
  if (!a.look_at.empty()) {
    if (a.look_at.size() < 2 || a.look_at.size() > 3)
      throw UsageError("--look-at: expected EX,EY,EZ TX,TY,TZ [UX,UY,UZ]");
    rig.placement = CameraPlacement::LookAt;
    rig.eye = parse_point(a.look_at[0], "--look-at", "eye");
    rig.target = parse_point(a.look_at[1], "--look-at", "target");
    if (a.look_at.size() == 3)
      rig.up = parse_point(a.look_at[2], "--look-at", "up vector (give the scene file before --look-at)");
    // Directions scaled by their largest component first, so that no square overflows.
    const auto direction = [](Vec3f d) {
      const float m = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
      return m > 0 && std::isfinite(m) ? normalize(d / m) : Vec3f{};
    };
    const Vec3f view = direction(rig.target - rig.eye), up = direction(rig.up);
    if (!(length(view) > 0)) throw UsageError("--look-at: the eye and the target are the same point");
    if (!(length(up) > 0)) throw UsageError("--look-at: the up vector is zero");
    if (!(length(cross(view, up)) > 1e-6f))
      throw UsageError("--look-at: the up vector is parallel to the view direction");
  }
  if (!a.orbit.empty()) {
    const std::vector<double> v = parse_list(a.orbit, "--orbit", 2, 3, "AZ,EL[,DIST] (degrees, scene units)");
    rig.placement = CameraPlacement::Orbit;
    rig.azimuth = check_angle(v[0], "--orbit", "azimuth") * kDegree;
    if (std::fabs(v[1]) > 90)
      throw UsageError("--orbit: elevation " + exact(v[1]) + " is outside [-90, 90] degrees");
    rig.elevation = v[1] * kDegree;
    if (v.size() == 3) {
      if (!(v[2] > 0 && v[2] < 1e30)) throw UsageError("--orbit: the distance must be > 0 (and below 1e30)");
      rig.distance = v[2];
    }
  }
  if (!a.euler.empty()) {
    const std::vector<double> v = parse_list(a.euler, "--euler", 3, 3, "YAW,PITCH,ROLL (degrees)");
    rig.placement = CameraPlacement::Euler;
    rig.euler = {check_angle(v[0], "--euler", "yaw") * kDegree,
                 check_angle(v[1], "--euler", "pitch") * kDegree,
                 check_angle(v[2], "--euler", "roll") * kDegree};
    if (!a.position.empty()) {
      rig.eye = parse_point(a.position, "--position", "position");
      rig.has_eye = true;
    }
  }
}

/// --turntable and --turntable-elevation.
void check_turntable(const CameraArgs& a, CameraRig& rig, long long frame) {
  if (a.turntable.empty()) {
    if (!a.turntable_elevation.empty()) throw UsageError("--turntable-elevation needs --turntable N");
    return;
  }
  if (!a.look_at.empty() || !a.euler.empty())
    throw UsageError(
        "--turntable orbits the bounds: not with --look-at or --euler (--orbit AZ,EL,DIST sets "
        "its start, elevation and distance)");
  rig.turntable_frames = turntable_frames(a);
  rig.turntable_frame = frame;
  rig.placement = CameraPlacement::Orbit;  // at --orbit's start, elevation and distance if given
  if (!a.turntable_elevation.empty()) {
    if (!a.orbit.empty())
      throw UsageError("--turntable-elevation and --orbit both give the elevation: give one");
    const double el = parse_number(a.turntable_elevation, "--turntable-elevation", "elevation");
    if (std::fabs(el) > 90)
      throw UsageError("--turntable-elevation: " + a.turntable_elevation + " is outside [-90, 90]");
    rig.elevation = el * kDegree;
  }
}

/// --fov, --focal-length, --sensor, --ortho, --near and --far.
void check_lens(const CameraArgs& a, CameraRig& rig) {
  if (!a.fov.empty() && !a.focal_length.empty())
    throw UsageError("--fov and --focal-length both set the field of view: give one");
  if (!a.sensor.empty() && a.focal_length.empty()) throw UsageError("--sensor needs --focal-length");
  if (!a.ortho.empty() && (!a.fov.empty() || !a.focal_length.empty()))
    throw UsageError("--ortho is an orthographic camera: it has no --fov or --focal-length");
  if (!a.fov.empty()) {
    const double deg = parse_number(a.fov, "--fov", "field of view");
    if (!(deg > 0 && deg < 180)) throw UsageError("--fov: " + a.fov + " degrees is outside (0, 180)");
    rig.yfov = deg * kDegree;
  }
  if (!a.focal_length.empty()) {
    rig.focal_mm = parse_number(a.focal_length, "--focal-length", "focal length");
    if (!(*rig.focal_mm > 0)) throw UsageError("--focal-length: must be > 0 millimetres");
  }
  if (!a.sensor.empty()) {
    rig.sensor_mm = parse_number(a.sensor, "--sensor", "sensor size");
    if (!(rig.sensor_mm > 0)) throw UsageError("--sensor: must be > 0 millimetres");
  }
  if (a.ortho == "fit") {
    rig.ortho_fit = true;
  } else if (!a.ortho.empty()) {
    rig.ortho_height = parse_number(a.ortho, "--ortho", "height");
    if (!(*rig.ortho_height > 0 && *rig.ortho_height < 1e30))
      throw UsageError("--ortho: the height must be > 0 (and below 1e30), or 'fit'");
  }
  if (!a.near.empty()) {
    rig.znear = parse_number(a.near, "--near", "distance");
    if (*rig.znear < 0) throw UsageError("--near: must be >= 0");
  }
  if (a.far == "inf") {
    rig.zfar = double(kInfinity);
  } else if (!a.far.empty()) {
    rig.zfar = parse_number(a.far, "--far", "distance");
    if (!(*rig.zfar > 0)) throw UsageError("--far: must be > 0 (or inf)");
  }
  if (rig.znear && rig.zfar && !(*rig.zfar > *rig.znear)) throw UsageError("--far must be beyond --near");
  const bool never_framed = !a.look_at.empty() || (!a.orbit.empty() && rig.distance) || !a.position.empty();
  if (rig.ortho_fit && never_framed)
    throw UsageError("--ortho fit frames the bounds: not with --look-at, an --orbit distance or --position");
}

}  // namespace

void add_camera_options(CLI::App& app, CameraArgs& a) {
  const char* group = "Camera";
  app.add_option("--look-at", a.look_at,
                 "place the camera at EYE looking at TARGET, with UP (default 0,1,0) upwards in the image")
      ->expected(2, 3)
      ->type_name("EX,EY,EZ TX,TY,TZ [UX,UY,UZ]")
      ->group(group);
  app.add_option("--orbit", a.orbit,
                 "orbit the bounds' centre: azimuth about +Y from +Z towards +X, elevation above the "
                 "centre (degrees), distance (default: the tight fit of the bounds)")
      ->type_name("AZ,EL[,DIST]")
      ->group(group);
  app.add_option("--euler", a.euler,
                 "orientation: yaw about +Y, then pitch about the camera's X, then roll about its view "
                 "axis (degrees; 0,0,0 looks down -Z); framed on the bounds unless --position")
      ->type_name("YAW,PITCH,ROLL")
      ->group(group);
  app.add_option("--position", a.position, "the eye for --euler")->type_name("X,Y,Z")->group(group);
  app.add_option("--turntable", a.turntable,
                 "orbit 360 degrees about +Y through the bounds' centre in N frames (frames 0..N-1 unless "
                 "--frames/--frame; outputs need '#'); --orbit sets the start azimuth, elevation, distance")
      ->type_name("N")
      ->group(group);
  app.add_option("--turntable-elevation", a.turntable_elevation,
                 "the turntable's elevation in degrees (default 0)")
      ->type_name("DEG")
      ->group(group);
  app.add_option("--fov", a.fov, "vertical field of view in degrees, in (0, 180)")
      ->type_name("DEG")
      ->group(group);
  app.add_option("--focal-length", a.focal_length, "focal length in mm (field of view with --sensor)")
      ->type_name("MM")
      ->group(group);
  app.add_option("--sensor", a.sensor, "sensor size in mm across the image's larger side (default 36)")
      ->type_name("MM")
      ->group(group);
  app.add_option("--ortho", a.ortho,
                 "orthographic camera showing HEIGHT scene units vertically, or 'fit' to frame the bounds")
      ->type_name("HEIGHT|fit")
      ->group(group);
  app.add_option("--near", a.near, "near clip distance along the view axis")->type_name("D")->group(group);
  app.add_option("--far", a.far, "far clip distance along the view axis, or inf")
      ->type_name("D")
      ->group(group);
  // An empty value would read as a flag not given.
  for (const char* name :
       {"--look-at", "--orbit", "--euler", "--position", "--turntable", "--turntable-elevation", "--fov",
        "--focal-length", "--sensor", "--ortho", "--near", "--far"})
    app.get_option(name)->check([](const std::string& value) {
      return value.empty() ? std::string("the value is empty") : std::string();
    });
}

bool places_camera(const CameraArgs& a) {
  return !a.look_at.empty() || !a.orbit.empty() || !a.euler.empty() || !a.turntable.empty();
}

int turntable_frames(const CameraArgs& a) {
  if (a.turntable.empty()) return 0;
  return int(parse_integer(a.turntable, 1, kMaxTurntableFrames, "--turntable"));
}

CameraRig check_camera_args(const CameraArgs& a, long long frame) {
  CameraRig rig;
  check_placement(a, rig);
  check_turntable(a, rig, frame);
  check_lens(a, rig);
  try {
    check_rig(rig);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("camera: ") + e.what());
  }
  return rig;
}

int base_camera_index(const Scene& scene, const std::string& camera, const CameraArgs& args,
                      const std::string& file) {
  if (!camera.empty()) return find_camera(scene, camera, file);
  return scene.cameras.empty() || places_camera(args) ? -1 : 0;
}

std::pair<int, int> image_size(int width, int height, float hint) {
  if (!width && !height) width = 960;
  if (!height) height = std::max(1, int(std::lround(width / hint)));
  if (!width) width = std::max(1, int(std::lround(height * hint)));
  if (width > 16384 || height > 16384)
    throw UsageError("image size " + std::to_string(width) + "x" + std::to_string(height) +
                     " exceeds 16384 per side");
  return {width, height};
}

float aspect_hint(const Scene& scene, int index) {
  return index >= 0 && scene.cameras[size_t(index)].aspect > 0 ? scene.cameras[size_t(index)].aspect
                                                               : 16.0f / 9.0f;
}

Camera choose_camera(const CameraRig& rig, const Scene& scene, int index, int width, int height,
                     const Bounds3f* bounds) {
  const Camera* base = index >= 0 ? &scene.cameras[size_t(index)] : nullptr;
  try {
    // The bounds only where the rig uses them: framing, or an orbit's centre.
    const bool uses_bounds =
        rig.placement == CameraPlacement::Orbit || rig_frames_bounds(rig, base != nullptr);
    return rig_camera(rig, base,
                      !uses_bounds ? Bounds3f{}
                      : bounds     ? *bounds
                                   : compute_bounds(scene),
                      float(width) / float(height));
  } catch (const std::invalid_argument& e) {
    // What only the scene decides: the framed near plane against --far, single-precision limits.
    throw UsageError(
        std::string("camera (--near, --far, --fov, --focal-length, --ortho or the placement): ") + e.what());
  }
}

ChosenView choose_view(const Scene& scene, const std::string& file, const std::string& camera,
                       const CameraArgs& args, int width, int height, long long frame) {
  ChosenView v;
  v.rig = check_camera_args(args, frame);
  v.index = base_camera_index(scene, camera, args, file);
  std::tie(v.width, v.height) = image_size(width, height, aspect_hint(scene, v.index));
  v.camera = choose_camera(v.rig, scene, v.index, v.width, v.height);
  try {
    validate_camera(v.camera, v.width, v.height);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, v.index >= 0 ? "cameras[" + std::to_string(v.index) + "]" : "the view", e.what());
  }
  return v;
}

}  // namespace penumbra::cli
