// Denoising a render in memory: the denoiser's input from the path tracer's colour halves and
// the data AOVs' feature halves, and the denoised beauty (alpha kept). What render_scene runs for
// spec.denoise; io/image/exr_denoise.h does the same from an EXR's layers.
#pragma once

#include <functional>
#include <vector>

#include "render/session.h"
#include "renderer/film/denoise.h"

namespace penumbra {

/// The denoiser's configuration for a render: NFOR's defaults with the render's threads.
DenoiseConfig denoise_config(const RenderConfig& config);

/// The denoiser's input from a render made with RenderConfig::halves: colour from image.halves,
/// features from data.halves. Throws std::invalid_argument when either is missing or does not
/// cover image.film.
DenoiseInput denoise_input(const RenderImage& image, const DataAovs& data);

/// `film` with its R, G, B replaced by `rgb` (3 floats per pixel, the denoiser's output); alpha
/// and the window are kept.
Film with_colour(const Film& film, const std::vector<float>& rgb);

/// The denoised beauty of a render made with RenderConfig::halves (denoise_input, denoise_nfor
/// under denoise_config, with_colour). `progress` as denoise_nfor's.
Film denoise_render(const RenderImage& image, const DataAovs& data, const RenderConfig& config,
                    const std::function<void(int done, int total)>& progress = {});

}  // namespace penumbra
