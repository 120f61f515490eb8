// The path tracer's resume state on disk (`--checkpoint`, `--resume`): the per-pixel running
// sums of render.h's PathAccumulators behind a header and the canonical text of the settings
// they belong to, sealed by a SHA-256 of all of it. Reading verifies the checksum, the settings
// and the consistency of the sums, so a damaged or foreign file can never be resumed from.
#pragma once

#include <cstdint>
#include <filesystem>

#include "io/farm/render_settings.h"
#include "renderer/integrators/render.h"

namespace penumbra {

/// Largest resume state file read_checkpoint opens (16k x 16k pixels with light groups fit).
inline constexpr uint64_t kMaxCheckpointBytes = uint64_t(64) << 30;

/// Largest canonical settings text a resume state file may hold.
inline constexpr uint64_t kMaxCheckpointSettingsBytes = uint64_t(1) << 20;

/// Writes `state` and canonical_text(`settings`) to `path` atomically, in the format
/// "PNMBRCK3": magic, fixed little-endian header (window, reached, passes, complete, pixel
/// record size, pixel, light-group, odd-sample and settings byte counts), settings text, pixel
/// records, light-group sums, odd-sample sums, then the SHA-256 of every preceding byte. Throws
/// std::runtime_error naming the file if writing fails (no file is left under `path` then).
void write_checkpoint(const std::filesystem::path& path, const PathAccumulators& state,
                      const RenderSettings& settings);

/// Reads a resume state written by write_checkpoint. Throws InputError naming the file, and
/// trusts no field before its check, when it:
///  - is not a regular file of at most kMaxCheckpointBytes (a FIFO or device is never opened);
///  - is not a Penumbra resume state, or is one in an older format (PNMBRCK1, PNMBRCK2);
///  - has a size other than its header's counts describe ("truncated or corrupt");
///  - fails its SHA-256 checksum (any flipped byte: "checksum mismatch");
///  - was written for settings other than `expected` (the message lists each differing key
///    with both values, as describe_differences);
///  - is inconsistent: an empty window or one that does not match the pixel count, light-group
///    sums neither absent nor kLightGroupChannels per pixel, odd-sample sums neither absent nor 4
///    per pixel, a negative or non-finite sum, coverage above the sample count (an odd-sample sum
///    above the pixel's, odd coverage above half the samples), a pixel with more samples than `reached` (or
///    an active pixel with fewer), passes < 0 or above `reached`, no passes but samples, or complete without
///    a pass.
PathAccumulators read_checkpoint(const std::filesystem::path& path, const RenderSettings& expected);

}  // namespace penumbra
