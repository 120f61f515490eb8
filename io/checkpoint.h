// The path tracer's resume state on disk (`--checkpoint`, `--resume`): the per-pixel running
// sums of render.h's PathAccumulators as raw little-endian bytes behind a header that records
// the settings they belong to, so a resumed render cannot silently mix different renders.
#pragma once

#include <filesystem>
#include <string>

#include "renderer/render.h"

namespace penumbra {

/// Writes `state` and the settings `fingerprint` to `path` atomically.
void write_checkpoint(const std::filesystem::path& path, const PathAccumulators& state,
                      const std::string& fingerprint);

/// Reads a checkpoint. Throws InputError naming the file if it is unreadable, truncated, not a
/// Penumbra checkpoint, or was written for other settings (the message shows both).
PathAccumulators read_checkpoint(const std::filesystem::path& path, const std::string& fingerprint);

}  // namespace penumbra
