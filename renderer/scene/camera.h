// Camera ray generation (orthographic and perspective) and automatic framing.
// The image aspect always defines the horizontal extent, so pixels are square and the image
// is never distorted, whatever aspect-ratio hint the file carries.
#pragma once

#include "renderer/core/geometry.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// The farthest a camera's ray origins (each coordinate) and clip distances may lie from the
/// origin: they stay well inside what single-precision ray kernels (Embree's among them,
/// 1.8e18) accept.
inline constexpr float kMaxCameraReach = 1e18f;

/// The most sides a polygonal aperture may have.
inline constexpr int kMaxApertureBlades = 64;

/// Throws std::invalid_argument, saying what is out of range, unless every ray that
/// generate_camera_ray gives for a width x height image (each >= 1) is one every back end can
/// trace: finite axes; every ray origin within kMaxCameraReach on each axis (the eye, and for an
/// orthographic camera the image plane's corners, ymag high and ymag * width / height wide);
/// a finite znear >= 0 and a zfar > znear (or infinite); a perspective field of view strictly
/// inside (0, 180) degrees whose tangent is finite; a thin lens with a finite radius >= 0 (the
/// aperture counted in the reach), a finite focus distance > 0, 0 or 3..kMaxApertureBlades
/// blades, a finite rotation and a ratio in [0.01, 100]. Every front end calls it on the camera it
/// renders with.
void validate_camera(const Camera& cam, int width, int height);

/// Ray through raster position (x, y) of a width x height image; x to the right, y down,
/// pixel (i, j) covers [i, i+1) x [j, j+1), so its centre is (i + 0.5, j + 0.5).
/// Perspective: origin at the eye, unit direction through the image plane; tnear/tfar are
/// set so that clipping happens at the planes z = znear / zfar (not spheres).
/// Orthographic: origin on the image plane (ymag half-height, xmag' = ymag * aspect), dir = -w.
Ray generate_camera_ray(const Camera& cam, int width, int height, float x, float y);

/// The per-image terms of generate_camera_ray for one camera and image size.
struct CameraRaster {
  float width, height, aspect;
  float tan_y = 0, tan_x = 0;  ///< perspective: half-extents of the image plane at depth 1
};
CameraRaster camera_raster(const Camera& cam, int width, int height);
/// generate_camera_ray(cam, width, height, x, y), bit for bit, from camera_raster(cam, width, height).
Ray raster_ray(const Camera& cam, const CameraRaster& raster, float x, float y);

/// A point of the camera's aperture from u in [0, 1)^2, in units of the lens radius on the lens
/// plane's (u, v) axes: uniform over the unit disc by Shirley and Chiu's concentric map ("A
/// Low Distortion Map Between Disk and Square", JGT 2(3), 1997), or over the regular polygon
/// of `lens.blades` = N sides inscribed in it, its corners at lens.rotation + (k + 1/2) 2 pi / N
/// (Cycles' blade convention); then x divided by
/// lens.ratio (an anamorphic aperture, taller than wide for a ratio > 1, as Cycles' ratio).
Vec2f sample_aperture(const ThinLens& lens, Vec2f u);

/// The ray from aperture point `aperture` (sample_aperture's) that meets the pinhole ray
/// `pinhole` (raster_ray's, or generate_camera_ray's) on the plane in focus, at depth
/// cam.lens.focus_distance (pbrt-v4's thin-lens step: the origin moved on the lens plane, the
/// unit direction aimed at the point in focus). tnear and tfar still clip at the depths znear
/// and zfar. Perspective lenses sit at the eye, orthographic ones at the ray's origin on the
/// image plane. With a zero lens radius it returns `pinhole` unchanged.
Ray thin_lens_ray(const Camera& cam, const Ray& pinhole, Vec2f aperture);

/// The camera's frame as a map from camera to world space: columns u, v, w and the eye.
Affine3f camera_frame(const Camera& cam);

/// `ray`, a ray of the camera at its frame (eye, u, v, w), carried along with the camera to
/// where cam.motion puts it at shutter time `time` (the ray's origin and direction taken into
/// the camera's space, then out through the interpolated frame). `ray` itself without motion.
/// Never allocates or throws.
Ray move_camera_ray(const Camera& cam, const Ray& ray, float time);

/// The rays through (x, y), (x + step, y) and (x, y + step) (out[0..2]): a camera ray and its
/// two differential rays, exactly as three generate_camera_ray calls give them, sharing the
/// per-camera terms; all three through aperture point `aperture` (thin_lens_ray).
void generate_camera_rays(const Camera& cam, int width, int height, float x, float y, float step, Ray out[3],
                          Vec2f aperture = {0, 0});

/// The thin lens' radius in scene units for an f-number (aperture diameter = focal length /
/// fstop, scene units being metres as in glTF): the focal length is cam.focal_mm when set,
/// else that of the camera's field of view across the image's larger side on a 36 mm sensor
/// (Blender's default sensor, "auto" fit). Perspective cameras only.
float fstop_lens_radius(const Camera& cam, float fstop, int width, int height);

/// The world-to-camera (view) matrix: rows u, v, w and translation -(u.eye, v.eye, w.eye), the
/// rigid inverse [R^T  -R^T eye] of the camera's frame; camera space looks down -Z.
Transform view_matrix(const Camera& cam);

/// glTF's projection matrix (glTF 2.0, 3.10.3 "Projection Matrices") for an image of the given
/// aspect (width / height, which replaces the file's hint, as in ray generation):
/// perspective with a finite zfar maps depth znear..zfar to z/w = -1..1; with zfar infinite it
/// is the infinite projection (row 3 = [0, 0, -1, -2 znear]); orthographic uses xmag = ymag *
/// aspect, and with zfar infinite its z row is [0, 0, -1, -(znear + 1)] so that z + w is still
/// the distance past the near plane. Clip space: -w <= x, y <= w, and z + w >= 0 in front of
/// the near plane (z - w <= 0 before a finite far plane). znear <= 0 on a perspective camera
/// is taken as kMinZnear.
Transform projection_matrix(const Camera& cam, float aspect);

/// The near distance projection_matrix() uses for a perspective camera without a positive znear.
inline constexpr float kMinZnear = 1e-6f;

/// A camera at `eye` looking at `target` with approximate up vector `up` (right-handed frame).
Camera look_at(Vec3f eye, Vec3f target, Vec3f up, float yfov);

/// `view` moved so that `bounds` fits a width/height = `aspect` image tightly, as Blender's
/// "frame selected": the view direction and frame (u, v, w), projection and yfov are kept; the
/// eye moves along w on the line through the bounds' centre. Perspective: the eye distance is
/// the smallest at which all 8 corners of `bounds` project inside the image, solved per corner
/// (corner at (x, y, z) in the camera frame about the centre: distance >= z + |x| / tan_x and
/// >= z + |y| / tan_y) and maxed, so the extreme corner touches the border of the limiting axis.
/// Orthographic: ymag (and xmag = ymag * aspect) from the corners' extents, the eye in front of
/// every corner. znear is set to 1e-4 of the eye distance (perspective) or 0 (orthographic).
/// Empty bounds frame the unit sphere at the origin; a degenerate box (a point, a flat or
/// edge-on box) stays in view at a positive distance.
Camera fit_bounds(const Camera& view, const Bounds3f& bounds, float aspect);

/// Default framing used when a scene has no camera: a perspective camera with a 39.6 degree
/// vertical FOV looking at the bounds' centre from the front-right-above direction
/// (0.5, 0.4, 1), fitted to the image of the given aspect by fit_bounds().
Camera frame_bounds(const Bounds3f& bounds, float aspect);

/// The documented default key light added when a scene has no light: a white directional
/// light with illuminance pi lux (a white Lambertian surface facing it has radiance 1),
/// arriving from above, left and behind the camera (direction 0.5 u - 0.8 v - 1.0 w).
Light default_key_light(const Camera& cam);

}  // namespace penumbra
