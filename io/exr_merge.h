// `penumbra merge`: assembling the EXRs of a frame's crops or farm tiles (`--crop`, `--tile`)
// into the full frame, byte for byte.
#pragma once

#include <filesystem>
#include <vector>

namespace penumbra {

/// Reads every part (an EXR whose data window lies inside its display window), checks that
/// all share the display window and the channel list (names and types), that they do not
/// overlap and that together they cover the whole display window, and writes the full frame
/// to `out` atomically, with each part's pixels copied unchanged (native channel types) and
/// the first part's metadata. Throws InputError naming the part (or the first uncovered pixel)
/// when a check fails; nothing is written then.
void merge_exr_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out);

}  // namespace penumbra
