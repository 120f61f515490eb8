// 3D Gaussian splats (Kerbl et al., "3D Gaussian Splatting for Real-Time Radiance Field
// Rendering", SIGGRAPH 2023) as glTF's KHR_gaussian_splatting stores them: per splat a centre, a
// unit rotation quaternion and linear scales that factor its covariance (Sigma = R S S^T R^T), an
// opacity in [0, 1] and real spherical-harmonic colour coefficients up to degree 3. Plain data
// and the closed forms a renderer needs: the covariance, the colour seen from a direction (with
// the extension's 0.5 bias), the response along a ray at its maximum (Moenne-Loccoz et al.,
// "3D Gaussian Ray Tracing", SIGGRAPH Asia 2024), and a bounding box at a Mahalanobis cut-off.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/core/geometry.h"
#include "renderer/core/math.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

/// What the splats' colours are (KHR_gaussian_splatting colorSpace): display-referred BT.709,
/// sRGB-encoded or linear. Both are converted to scene-linear BT.709 to render.
enum class SplatColorSpace : uint8_t { SrgbRec709Display, LinRec709Display };

/// Coefficients per splat for SH degree d: (d + 1)^2 (1, 4, 9, 16).
inline int sh_coefficient_count(int degree) {
  return (degree + 1) * (degree + 1);
}

/// One KHR_gaussian_splatting primitive's splats in its mesh's space.
struct SplatCloud {
  std::string name;  ///< "meshName[prim]" for messages
  std::vector<Vec3f> positions;
  std::vector<Vec4f> rotations;  ///< unit quaternions (x, y, z, w), local -> mesh space
  std::vector<Vec3f> scales;     ///< standard deviations along the local axes, >= 0
  std::vector<float> opacities;  ///< in [0, 1]
  int sh_degree = 0;             ///< 0 to 3
  /// sh_coefficient_count(sh_degree) RGB coefficients per splat, splat after splat, in the
  /// extension's order: degree 0, then degree 1 (m = -1, 0, 1), ...
  std::vector<Vec3f> sh;
  SplatColorSpace color_space = SplatColorSpace::SrgbRec709Display;
  int mesh = -1, primitive = -1;  ///< the glTF mesh and primitive it came from
};

/// One placement of a cloud in the world (a glTF node using its mesh, or an instance of it).
struct SplatInstance {
  int cloud = 0;  ///< index into the scene's splat clouds
  Affine3f to_world;
  int node = -1;  ///< glTF node, -1 if not from glTF
};

/// Below this transmittance a layer of splats stops (3DGRT): what lies behind it is hidden.
inline constexpr float kSplatMinTransmittance = 1e-3f;

/// A symmetric 3 x 3 matrix, row-major.
using Mat3 = std::array<std::array<double, 3>, 3>;

/// The rotation of a unit quaternion (x, y, z, w), as the extension's formula writes it.
Mat3 quaternion_matrix(Vec4f q);

/// Splat i's covariance R S S^T R^T in its cloud's space.
Mat3 splat_covariance(const SplatCloud& cloud, size_t i);

/// Splat i's colour seen along unit direction `dir` (from the viewer towards the splat, in the
/// cloud's space, as the reference implementation evaluates it): the real spherical harmonics
/// with the Condon-Shortley phase and the constants of the extension's Appendix A at dir's
/// (x, y, z), summed over the cloud's degrees, plus 0.5, clamped at 0; in the cloud's colour
/// space (splat_linear_color linearises it).
Vec3f splat_sh_color(const SplatCloud& cloud, size_t i, Vec3f dir);

/// The cloud's colour space's value `c` as scene-linear BT.709 (the sRGB curve undone for
/// SrgbRec709Display).
Vec3f splat_linear_color(SplatColorSpace space, Vec3f c);

/// Splat i as the Splat shape the structures hold (make_splat_shape), reporting prim_id `element`.
Shape splat_shape(const SplatCloud& cloud, size_t i, uint32_t element);

/// The response of splat i along ray o + t d at its maximum (3DGRT): t* = -(o'.d')/(d'.d') in the
/// splat's whitened frame (o' = S^-1 R^T (o - mu), d' = S^-1 R^T d), and
/// alpha = opacity exp(-|o' + t* d'|^2 / 2) (splat_response over splat_shape: scales below 1e-3
/// of the largest raised to it). Returns false (and alpha 0) for a splat without a positive
/// scale or opacity, or a zero direction.
bool splat_ray_response(const SplatCloud& cloud, size_t i, const Ray& ray, float& t_max, float& alpha);

/// The box holding splat i out to kSplatSigmas standard deviations along each of its axes (the
/// extension's ellipse kernel cuts off at 3).
Bounds3f splat_bounds(const SplatCloud& cloud, size_t i);

/// A splat field fitted to a sphere, with a known colour pattern: the generator of test scenes
/// and of the shipped splat scene.
struct SplatSphereConfig {
  Vec3f centre{0, 0, 0};
  float radius = 1;         ///< > 0
  int count = 2000;         ///< splats, >= 1, on a Fibonacci lattice
  float tangent_scale = 0;  ///< standard deviation along the surface; 0: 0.6 x the lattice
                            ///< spacing sqrt(4 pi radius^2 / count)
  float normal_scale = 0;   ///< standard deviation across it; 0: tangent_scale / 10
  float opacity = 1;        ///< of every splat, in [0, 1]
};

/// The sphere: splat i at centre + radius n_i (n_i the i-th Fibonacci lattice direction), its
/// local z axis along n_i, and the colour 0.5 + 0.5 n_i from every direction (degree 0, linear
/// BT.709: the DC coefficient is (colour - 0.5) / 0.2820948). Throws std::invalid_argument for
/// parameters outside the ranges above.
SplatCloud make_splat_sphere(const SplatSphereConfig& config);

/// The i-th of n Fibonacci lattice directions on the unit sphere (y from near 1 down to near -1).
Vec3f fibonacci_direction(int i, int n);

}  // namespace penumbra
