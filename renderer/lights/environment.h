// The environment light of the path tracer: a constant radiance, or an equirectangular
// (latitude-longitude) HDR map with a rotation about +Y and an intensity multiplier,
// importance sampled by a piecewise-constant 2D distribution proportional to
// luminance x sin(theta) (pbrt-v3 14.2.4, "Infinite Area Lights").
#pragma once

// Map convention (glTF is +Y up, cameras look down -Z): the image centre (u = 0.5) is the -Z
// direction, u increases towards +X (so the map is not mirrored when seen from inside), the
// top row is +Y. A rotation of R degrees turns the map counter-clockwise seen from above
// (about +Y).

#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

struct Environment {
  Vec3f color{0, 0, 0};  ///< constant radiance (used when the map is empty)
  int width = 0, height = 0;
  std::vector<Vec3f> texels;  ///< linear RGB, row-major, row 0 = +Y; empty = constant
  float intensity = 1;        ///< multiplies the map
  float rotation = 0;         ///< radians about +Y
  // Sampling tables (make_map_environment fills them).
  std::vector<float> marginal_cdf;     ///< height + 1 entries
  std::vector<float> conditional_cdf;  ///< height rows of width + 1 entries
  std::vector<float> texel_pdf;        ///< per texel: probability / (texel's uv area)
  bool map_emits = false;              ///< some texel has luminance > 0 (set with the tables)
};

Environment make_constant_environment(Vec3f radiance);
/// Requires width, height >= 1, texels.size() == width * height, finite non-negative values,
/// finite intensity >= 0 and rotation (radians). Builds the sampling tables.
Environment make_map_environment(int width, int height, std::vector<Vec3f> texels, float intensity,
                                 float rotation);

/// True if the environment emits nothing (then it is neither sampled nor looked up). O(1).
bool is_black(const Environment& env);

/// Radiance arriving from unit direction `dir` (the direction away from the scene).
Vec3f env_eval(const Environment& env, Vec3f dir);
/// Solid-angle density with which env_sample() picks `dir`.
float env_pdf(const Environment& env, Vec3f dir);
/// A direction from u in [0,1)^2 with its radiance and density; false if the environment is
/// black. Never allocates.
bool env_sample(const Environment& env, Vec2f u, Vec3f& dir, Vec3f& radiance, float& pdf);

/// A width x height map in this file's convention resampled from a cube map (nearest texel):
/// six square faces of face_size texels in the order +X, -X, +Y, -Y, +Z, -Z, each row-major
/// from its top row, oriented as OpenGL cube maps are (face +X: s along -Z, t along -Y; +Y: s
/// along +X, t along +Z; ...). The texel for world direction d is the cube's at R^-1 d, R the
/// unit quaternion `rotation` (x, y, z, w): the cube map turned by R. Requires face_size >= 1
/// and each face of face_size^2 texels.
std::vector<Vec3f> equirect_from_cube(const std::vector<Vec3f> (&faces)[6], int face_size, int width,
                                      int height, Vec4f rotation);

/// The map's (u, v) for a direction (u, v in [0, 1], v = 0 at +Y) and back, including rotation.
Vec2f env_direction_to_uv(const Environment& env, Vec3f dir);
Vec3f env_uv_to_direction(const Environment& env, Vec2f uv);

}  // namespace penumbra
