// Output paths of animation frames: `--frames A-B[:STEP]` ranges, Blender-style `#` patterns
// (a run of k '#' is the frame number zero-padded to k characters), and whether a frame's EXR
// is already complete on disk. No rendering and no scene knowledge here.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace penumbra {

/// Largest |frame number| a range or --frame may name (frame / fps stays exact in a double).
inline constexpr int64_t kMaxFrameNumber = int64_t(1) << 40;
/// Most frames one range may hold.
inline constexpr int64_t kMaxFramesPerRange = 100000;

/// An inclusive range of frames: first, first + step, ... up to and including last.
struct FrameRange {
  int64_t first = 0;
  int64_t last = 0;
  int64_t step = 1;  ///< >= 1
  int64_t count() const { return (last - first) / step + 1; }
};

/// "N", "A-B" or "A-B:STEP" (A, B may be negative: "-5--1"). Throws std::invalid_argument
/// naming --frames
/// for text that is not such a range, B < A, STEP < 1, a number outside +-kMaxFrameNumber or
/// more than kMaxFramesPerRange frames.
FrameRange parse_frame_range(const std::string& text);

/// True when `path` holds at least one '#'.
bool has_frame_pattern(const std::string& path);

/// `path` with every run of k '#' replaced by `frame` padded with zeros to k characters, the
/// sign counted (k = 4: 12 -> "0012", -1 -> "-001"); a longer number is written in full.
std::string substitute_frame(const std::string& path, int64_t frame);

/// True when `path` is a regular file that OpenImageIO opens as an OpenEXR, whose every part's
/// pixels (or deep samples) read back, that is not an unfinished render (Penumbra's settings metadata saying
/// complete=0, or a PATH.resume state beside it); otherwise false with the reason in `problem`
/// (missing, truncated, not an EXR, unfinished). Never throws for a bad file.
bool is_complete_exr(const std::filesystem::path& path, std::string& problem);

}  // namespace penumbra
