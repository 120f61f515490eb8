// Deep OpenEXR output: a DeepImage (renderer/film/deep.h) as a deep scanline file of 32-bit float
// channels R G B A Z ZBack id N.X N.Y N.Z albedo.R albedo.G albedo.B, samples sorted front to
// back and never overlapping (OpenEXR's "tidy" state), colour premultiplied by A as OpenEXR's
// deep rules require, through OpenImageIO's deep API. `penumbra merge` assembles deep stripes
// (io/image/exr_merge.h).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "io/image/image_output.h"
#include "renderer/film/deep.h"

namespace penumbra {

/// Writes `image` atomically (data window = its window in the full frame) with the metadata of
/// `options` (its string, float and matrix attributes), compressed per scanline with zip (zips),
/// or not at all when options.compression is "none" (OpenImageIO writes deep data with these two). Throws
/// std::runtime_error naming the file if OpenImageIO fails; `sha256`, if not null, receives the file's
/// SHA-256.
void write_deep_exr(const DeepImage& image, const std::filesystem::path& path, const ExrOptions& options,
                    std::string* sha256 = nullptr);

/// Reads a deep EXR with the channels write_deep_exr writes (any order, float or half) into a
/// DeepImage. Throws InputError naming the file (and the channel and pixel) when it is not one,
/// lacks a channel, holds an alpha outside [0, 1], a NaN or negative depth, a ZBack before its Z or
/// samples out of depth order, or its samples would need more than `max_bytes`.
DeepImage read_deep_exr(const std::filesystem::path& path, uint64_t max_bytes);

}  // namespace penumbra
