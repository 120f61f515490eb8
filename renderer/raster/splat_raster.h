// Gaussian splats rasterised: elliptical weighted average splatting (Zwicker et al., "EWA
// Volume Splatting", IEEE Visualization 2001) as 3D Gaussian Splatting (Kerbl et al. 2023)
// projects a splat: its covariance taken to camera space (W Sigma W^T) and through the Jacobian
// J of the projection at its centre, giving a 2D Gaussian on the image (J W Sigma W^T J^T) cut at
// the 3-sigma ellipse; the splats sorted by the depth of their centres and binned into screen
// cells, then blended front to back per sample, depth-composited with the surfaces' fragments.
// Each sample evaluates the 2D Gaussian at its own position (no low-pass dilation: the pixel's
// samples filter it, as they do the ray tracer's).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/core/parallel.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// A symmetric 2 x 2 matrix (xx, xy, yy).
struct Sym2 {
  double xx = 0, xy = 0, yy = 0;
};

/// One placed splat on the image.
struct ProjectedSplat {
  Vec2f centre;         ///< raster position of its centre (x right, y down, pixels)
  float conic[3] = {};  ///< the inverse of its 2D covariance (xx, xy, yy)
  Vec2f lo, hi;         ///< raster box of its 3-sigma ellipse
  float depth = 0;      ///< view depth of its centre (along -w)
  float opacity = 0;
  Vec3f color;  ///< scene-linear, its spherical harmonics seen from the eye towards its centre
  uint32_t instance = 0, splat = 0;
};

/// Splat i of splat instance `inst` on a width x height image of `camera`: the 2D covariance
/// J W Sigma_world W^T J^T in pixels^2 (Sigma_world = A R S S^T R^T A^T for the instance's linear
/// part A, scales raised as splat_shape raises them), J the projection's Jacobian at the
/// centre (perspective: (f_x / z, 0, -f_x x / z^2; 0, -f_y / z, f_y y / z^2); orthographic: the
/// constant scale). False when the centre is not in front of the camera (depth <= max(znear,
/// 1e-6)) or the covariance is not positive definite.
bool project_splat(const Scene& scene, const Camera& camera, int width, int height, uint32_t inst, uint32_t i,
                   ProjectedSplat& out, Sym2* covariance = nullptr);

/// Every placed splat that projects (project_splat) and reaches `window` widened by `margin`
/// pixels (how far samples lie outside their pixel), sorted by (depth, instance, splat): the
/// same order for any thread count.
std::vector<ProjectedSplat> project_splats(const Scene& scene, const Camera& camera, int width, int height,
                                           const PixelWindow& window, float margin, int threads);

/// The splats of each cell x cell square of a window, in the projected order.
struct SplatBins {
  PixelWindow window;
  int cell = 16, columns = 0, rows = 0;
  std::vector<uint32_t> begin;  ///< per cell (row-major), plus one: its range in `refs`
  std::vector<uint32_t> refs;   ///< indices into the projected splats
  /// The cell holding raster position p (clamped to the window's cells).
  size_t cell_of(Vec2f p) const;
};
/// Each splat goes to the cells its box meets, widened by `margin` + 1 pixels (samples outside
/// the window fall in its edge cells).
SplatBins bin_splats(std::span<const ProjectedSplat> splats, const PixelWindow& window, float margin,
                     int cell = 16);

/// Bytes project_splats and bin_splats hold for `scene` when each placed splat is projected and
/// referenced by 16 cells (an estimate for memory budgets: a splat wider than 64 pixels is
/// referenced by more).
uint64_t splat_raster_bytes(const Scene& scene);

/// The splat's alpha at raster position p: opacity exp(-q / 2), q = d^T conic d, d = p - centre;
/// 0 outside the 3-sigma ellipse (q > 9) or below kSplatMinAlpha.
float splat_alpha_at(const ProjectedSplat& s, Vec2f p);

/// Front-to-back blending of a sample's splats, in the projected order, depth-composited with
/// the surfaces' fragments: advance(zmax, sum, remaining) blends the splats in front of depth
/// zmax not yet blended into `sum` (each adds colour x alpha x remaining) and takes their
/// share from `remaining` (the sample's transmittance so far, splats and Blend layers alike;
/// set to 0 once below kSplatMinTransmittance).
struct SplatCursor {
  std::span<const ProjectedSplat> splats;
  const uint32_t* next = nullptr;  ///< the sample's cell's references still to blend
  const uint32_t* end = nullptr;
  Vec2f p;
  /// The splat with which `remaining` fell below 1/2 (the layer's median), null until then.
  const ProjectedSplat* median = nullptr;
  void advance(float zmax, Vec3f& sum, float& remaining);
};
SplatCursor splat_cursor(std::span<const ProjectedSplat> splats, const SplatBins& bins, Vec2f p);

}  // namespace penumbra
