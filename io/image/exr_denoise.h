// `penumbra denoise`: the NFOR denoiser (renderer/film/denoise.h) run on a Penumbra EXR that
// holds the halves layers, written as a new EXR with every other channel, part and attribute
// kept. The halves layers, as `--aovs halves` (and `--denoise`) write them in 32-bit float:
//   even.RGB, odd.RGB                 the mean colour of the even- and odd-numbered samples
//   even_albedo.RGB, odd_albedo.RGB   the halves' albedo
//   even_N.XYZ, odd_N.XYZ             the halves' shading normal
//   even_Z.Z, odd_Z.Z                 the halves' nearest depth (+inf where nothing is hit)
// Compositing convention: by default R, G, B hold the denoised beauty, A the render's coverage
// (unchanged: the denoiser filters colour only) and noisy.RGBA the render's beauty as it was;
// with `noisy_main` R, G, B, A stay the render's and the denoised beauty is denoised.RGBA. Light
// groups, data AOVs, Cryptomatte and every other layer are copied unchanged.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "renderer/film/denoise.h"
#include "renderer/film/film.h"

namespace penumbra {

/// Channels per half the denoiser reads: colour RGB, albedo RGB, N XYZ, Z.
inline constexpr int kDenoiseChannelsPerHalf = 3 + kDenoiseFeatures;

/// The EXR name of channel `k` (0 .. kDenoiseChannelsPerHalf - 1, in the order above) of half
/// `half` (0: even samples, 1: odd): "even.R", ..., "odd_Z.Z".
std::string denoise_channel_name(int half, int k);

/// String attribute of a denoised EXR: the method ("nfor").
inline constexpr const char* kDenoiserAttribute = "penumbra:denoiser";
/// String attribute of a denoised EXR: which beauty is the main layer, "denoised" or "noisy".
inline constexpr const char* kDenoiseMainAttribute = "penumbra:denoise_main";

struct ExrDenoiseOptions {
  bool noisy_main = false;  ///< keep R, G, B, A noisy and write the denoised beauty as denoised.RGBA
  DenoiseConfig config;     ///< NFOR's parameters (the render's defaults)
  uint64_t max_memory_bytes = uint64_t(8) << 30;      ///< the file's pixels, the output's and the denoiser's
  std::function<void(int done, int total)> progress;  ///< denoise_nfor's steps; may be empty
};

/// Bytes denoise_exr needs for a width x height image besides the file's pixels (which it
/// holds twice): the decoded halves, the output and the denoiser's buffers (denoise_bytes).
uint64_t exr_denoise_bytes(int width, int height, const DenoiseConfig& config);

/// Denoises `in` into `out` (written atomically; nothing is written on error) and returns the
/// main beauty as written (RGBA of the data window, before rounding to the file's types).
/// Works on single- and multi-part files (the second beauty becomes one more part), crops and
/// stripes (their data window alone). Throws InputError naming `in` and the element, before
/// writing anything, when:
///  - it is not a regular, readable OpenEXR file of at most 16 GiB with R, G, B, A;
///  - it lacks a channel of the halves layers (the message names the missing layers);
///  - it is already denoised (kDenoiserAttribute, or a noisy.* or denoised.* layer);
///  - a halves channel holds a NaN or an infinity (depth: NaN or -inf), naming the pixel;
///  - its pixels, the output's and the denoiser's buffers exceed options.max_memory_bytes.
Film denoise_exr(const std::filesystem::path& in, const std::filesystem::path& out,
                 const ExrDenoiseOptions& options, std::string* sha256 = nullptr);

/// Writes the noisy EXR through `write_noisy` to a temporary file beside `out`, then
/// denoise_exr(temporary, out): how a render and a merge that ask for denoising write their
/// frame, so that either gives the bytes `penumbra denoise` gives on the noisy frame. The
/// temporary is removed however it ends.
Film denoise_through_file(const std::filesystem::path& out,
                          const std::function<void(const std::filesystem::path& noisy)>& write_noisy,
                          const ExrDenoiseOptions& options, std::string* sha256 = nullptr);

}  // namespace penumbra
