// Loading an equirectangular environment map (`--env FILE.exr|.hdr`, any float format
// OpenImageIO reads) into the renderer's Environment.
#pragma once

#include <cstdint>
#include <filesystem>

#include "renderer/lights/environment.h"

namespace penumbra {

/// Largest map accepted per side (a 16k x 8k map is 1.5 GiB of float RGB plus its tables).
inline constexpr int kMaxEnvironmentSide = 16384;
/// Largest environment map file read (16384 x 8192 RGBA float with room for the container).
inline constexpr uint64_t kMaxEnvironmentFileBytes = 4ull << 30;

/// Bytes load_environment needs for a width x height map of `channels` channels (decoded
/// pixels, texels and sampling tables).
uint64_t environment_bytes(int width, int height, int channels);

/// Reads RGB (the first three channels; a single channel is grey) as linear scene values,
/// with `intensity` and `rotation_degrees` about +Y (environment.h). Throws InputError
/// naming the file for a missing or unreadable file, a size beyond kMaxEnvironmentSide or
/// one needing more than `max_bytes` (environment_bytes), or a NaN, infinite or negative
/// texel (naming its pixel).
Environment load_environment(const std::filesystem::path& path, float intensity, float rotation_degrees,
                             uint64_t max_bytes = uint64_t(8) << 30);

}  // namespace penumbra
