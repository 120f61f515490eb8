// `penumbra merge`: assembling the EXRs of a frame's crops or farm tiles (`--crop`, `--tile`)
// into the full frame, byte for byte. Parts must prove they belong together: the same scene
// and settings (from their Penumbra metadata), display window and channels, no overlap, no gap.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/farm/render_settings.h"

namespace penumbra {

/// Path tracer statistics of a render, as strings: the camera samples taken, their mean per
/// pixel (format_mean_spp) and the passes. A merged frame holds the sum of its parts' samples,
/// their mean over the whole frame and the most passes of any part, as one render of the frame
/// records them.
inline constexpr const char* kSamplesAttribute = "penumbra:samples";
inline constexpr const char* kMeanSppAttribute = "penumbra:mean_spp";
inline constexpr const char* kPassesAttribute = "penumbra:passes";
/// Float attribute: seconds spent rendering; a merged frame holds the sum of its parts'.
inline constexpr const char* kRenderSecondsAttribute = "penumbra:render_seconds";

/// `samples` / `pixels` with three decimals, as kMeanSppAttribute records it ("0.000" for no pixels).
std::string format_mean_spp(uint64_t samples, uint64_t pixels);

/// Largest part file merge_exr_parts opens.
inline constexpr uint64_t kMaxMergePartBytes = uint64_t(16) << 30;

struct MergeOptions {
  bool force = false;  ///< accept parts without or with differing Penumbra metadata (from other tools)
  /// Bound on the decoded full frame (every EXR part) plus one part's decoded pixels.
  uint64_t max_memory_bytes = uint64_t(8) << 30;
  int threads = 0;  ///< the denoiser's, for parts rendered with denoise (0: every hardware thread)
  std::function<void(int done, int total)> denoise_progress;  ///< the denoiser's steps; may be empty
};

/// Reads every part (an OpenEXR file whose data window lies inside its display window) and
/// writes the full frame to `out` atomically, with each part's pixels copied unchanged (native
/// channel types) and the first part's metadata, except for the statistics that add up over
/// the parts (kSamplesAttribute and the attributes beside it, when every part has them): the
/// merge of a frame's tiles equals a render of the whole frame byte for byte when the renders
/// record no command line or timing (`render --reproducible`). Throws InputError naming the part (or the
/// first uncovered pixel), and writes nothing, unless:
///  - every part is a regular file of at most kMaxMergePartBytes (checked before any is opened,
///    so a FIFO or /dev/zero is refused at once);
///  - without `force`: every part carries kSceneHashAttribute and kSettingsAttribute, equal to
///    the first part's (the message shows both hashes, or each differing settings key, and
///    suggests --force for parts from other tools);
///  - all share the display window and the channel list (names and types) of every EXR part;
///  - they do not overlap and together cover the whole display window;
///  - the frame fits in `options.max_memory_bytes`.
/// Deep parts (`render --deep` stripes: single-part deep files with the same channels) merge
/// into one deep frame, each pixel's samples copied unchanged; flat and deep parts do not mix.
/// Parts rendered with `denoise` (their settings say so) hold the noisy beauty and the halves
/// layers: the merged frame is denoised (denoise_through_file, within the same memory bound)
/// and written as `penumbra render --denoise` writes the whole frame.
void merge_exr_parts(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out,
                     const MergeOptions& options = {});

}  // namespace penumbra
