// Feature-guided denoising of a Monte Carlo render from two independent halves of its samples:
// NFOR (Bitterli et al. 2016, "Nonlinearly Weighted First-order Regression for Denoising Monte
// Carlo Renderings"), and a cross-bilateral filter on the same features as the baseline.
#pragma once

// NFOR in four steps, each a pass over the image in tiles, after firefly removal (a pixel of
// one half brighter than twice the brightest of the other half's 5 x 5 neighbourhood is scaled
// down to that bound: a rare path found by one half only, which the regression would spread
// over whole windows; biased, as a clamp is) and with isolated glints set aside (a pixel
// brighter in both halves than 4 times the third brightest of its 8 neighbours is scaled down
// to that bound, and the excess added to the result, so that it does not glow):
//   1. Feature prefiltering: each half of each feature (albedo, normal, depth, one group at a
//      time) filtered by non-local means (Buades et al. 2005) with weights from the other
//      half's same group, so that noisy
//      features (depth of field, motion blur, antialiased edges) do not carry noise into the
//      regression.
//   2. Collaborative first-order regression: for every pixel c, a weighted least-squares fit of
//      colour = a + B (f - f(c)) over a (2R+1)^2 window, with non-local-means weights between
//      c's and each neighbour's patch in the *other* half (Rousselle et al. 2012's
//      variance-cancelling distance), so that weights and data are independent; the fit is
//      evaluated at every neighbour, each estimate clamped to the colour range of the 3 x 3
//      pixels around the neighbour (a fit extrapolated from a bright spot the features do not
//      explain would streak), and the estimates a pixel receives are averaged. Run for each
//      half with bandwidths k = 0.5 and 1.
//   3. Bandwidth selection: per pixel, the candidate whose error, estimated from the other
//      half (E[(F_A - B)^2] - Var B), smoothed by non-local means, is lower; the selection map
//      is smoothed in turn.
//   4. A second regression of the two selected halves' mean, guided by itself, with features
//      and variance from the halves.
// Variances come from the halves alone (per channel, (A - B)^2 / 2 for a half, averaged over
// 3 x 3 pixels), so a denoise needs only what the EXR stores. Every step is a combination of
// pixels with weights summing to one (clamped to ranges of the image), so a constant image stays
// constant.
// Deterministic: tiles scatter into private buffers that are added in tile order, so the output
// is bit-identical for any thread count.

#include <cstddef>
#include <functional>
#include <vector>

namespace penumbra {

/// Feature channels per pixel, in this order: albedo RGB, normal XYZ, depth.
inline constexpr int kDenoiseFeatures = 7;

/// What the denoiser reads: the render's colour and features, each as the means of two
/// disjoint halves of every pixel's samples (even and odd sample indices). Row-major, top row
/// first. Depth may be +inf where the camera sample missed; non-finite colour or features are
/// read as 0 (the caller reports them).
struct DenoiseInput {
  int width = 0, height = 0;
  std::vector<float> color[2];     ///< 3 floats per pixel (RGB, premultiplied), per half
  std::vector<float> features[2];  ///< kDenoiseFeatures floats per pixel, per half
};

/// NFOR's parameters (defaults: the paper's).
struct DenoiseConfig {
  int window_radius = 9;               ///< R: the regression window is (2R+1)^2 pixels, 1..20
  int patch_radius = 3;                ///< F: non-local-means patches are (2F+1)^2 pixels, 0..10
  float bandwidths[2] = {0.5f, 1.0f};  ///< k of the two candidate filters (> 0)
  int feature_window_radius = 5;       ///< window of the feature prefilter, 0..20 (0: none)
  float feature_bandwidth = 0.5f;      ///< its k
  bool second_pass = true;             ///< step 4
  int threads = 0;                     ///< worker threads (thread_count)
  int tile_size = 32;                  ///< tiles of the passes (the output depends on it)
};

/// Empty if valid, else what is wrong (the CLI and Python report it).
const char* validate(const DenoiseConfig& config);
/// Empty if the buffers have the sizes of width x height, else what is wrong.
const char* validate(const DenoiseInput& input);

/// The denoised colour (3 floats per pixel) of a valid input under a valid config. Never
/// throws for valid input; allocates about 67 floats per pixel, padded copies of the weights'
/// guides and per-thread tile buffers (denoise_bytes).
/// `progress`, if set, is called from the calling thread with (steps done, steps) after the
/// feature prefilter, the selected halves and the second pass.
std::vector<float> denoise_nfor(const DenoiseInput& input, const DenoiseConfig& config,
                                const std::function<void(int done, int total)>& progress = {});

/// Bytes denoise_nfor allocates at most for an image of width x height.
size_t denoise_bytes(int width, int height, const DenoiseConfig& config);

/// The cross-bilateral baseline: each pixel the weighted mean of the halves' mean colour over
/// a (2R+1)^2 window (R below 1 is read as 1), with Gaussian weights in pixel distance (sigma
/// max(1, R/2)) and in each feature's
/// difference (albedo 0.1, normal 0.2, depth 2% of the pixel's depth). Same input and output.
std::vector<float> denoise_cross_bilateral(const DenoiseInput& input, int window_radius, int threads);

}  // namespace penumbra
