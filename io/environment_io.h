// Loading an equirectangular environment map (`--env FILE.exr|.hdr`, any float format
// OpenImageIO reads) into the renderer's Environment.
#pragma once

#include <filesystem>

#include "renderer/environment.h"

namespace penumbra {

/// Largest map accepted per side (a 16k x 8k map is 1.5 GiB of float RGB plus its tables).
inline constexpr int kMaxEnvironmentSide = 16384;

/// Reads RGB (the first three channels; a single channel is grey) as linear scene values,
/// with `intensity` and `rotation_degrees` about +Y (environment.h). Throws InputError
/// naming the file for a missing or unreadable file, a size beyond kMaxEnvironmentSide, or a
/// NaN, infinite or negative texel (naming its pixel).
Environment load_environment(const std::filesystem::path& path, float intensity,
                             float rotation_degrees);

}  // namespace penumbra
