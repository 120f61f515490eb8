// `penumbra merge`: assembling the EXRs of a frame's crops or farm tiles (`--crop`, `--tile`)
// into the full frame, byte for byte. Parts must prove they belong together: the same scene
// and settings (from their Penumbra metadata), display window and channels, no overlap, no gap.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace penumbra {

/// String attribute of a tile: SHA-256 (hex) of the scene it was rendered from.
inline constexpr const char* kSceneHashAttribute = "penumbra:scene_sha256";
/// String attribute of a tile: canonical_text (io/render_settings.h) of its render settings
/// without the keys that differ between tiles of one frame (window, crop, tile).
inline constexpr const char* kSettingsAttribute = "penumbra:settings";

/// Largest part file merge_exr_parts opens.
inline constexpr uint64_t kMaxMergePartBytes = uint64_t(16) << 30;

struct MergeOptions {
  bool force = false;  ///< accept parts without or with differing Penumbra metadata (from other tools)
  /// Bound on the decoded full frame (every EXR part) plus one part's decoded pixels.
  uint64_t max_memory_bytes = uint64_t(8) << 30;
};

/// Reads every part (an OpenEXR file whose data window lies inside its display window) and
/// writes the full frame to `out` atomically, with each part's pixels copied unchanged (native
/// channel types) and the first part's metadata. Throws InputError naming the part (or the
/// first uncovered pixel), and writes nothing, unless:
///  - every part is a regular file of at most kMaxMergePartBytes (checked before any is opened,
///    so a FIFO or /dev/zero is refused at once);
///  - without `force`: every part carries kSceneHashAttribute and kSettingsAttribute, equal to
///    the first part's (the message shows both hashes, or each differing settings key, and
///    suggests --force for parts from other tools);
///  - all share the display window and the channel list (names and types) of every EXR part;
///  - they do not overlap and together cover the whole display window;
///  - the frame fits in `options.max_memory_bytes`.
void merge_exr_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out,
                     const MergeOptions& options = {});

}  // namespace penumbra
