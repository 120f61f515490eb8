// Image output: scene-linear RGBA OpenEXR through OpenImageIO, and display-referred images
// (PNG, JPEG, TIFF) through an OpenColorIO display/view transform. Both written atomically.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "renderer/film/film.h"

namespace penumbra {

/// How an extra channel is stored in the file.
enum class ChannelType : uint8_t { Half, Float, Uint };

/// An extra EXR channel (an AOV such as "cost.nodes" or "N.X"): element `offset` of every
/// `stride` floats of `data` (width x height x stride floats, row-major, top row first).
/// Float by default so data and counts stay exact; Uint for integer ids (values must be
/// whole numbers >= 0), Half for colour layers.
struct ExrChannel {
  std::string name;
  const std::vector<float>* data = nullptr;
  ChannelType type = ChannelType::Float;
  int stride = 1;
  int offset = 0;
};

struct ExrOptions {
  bool half = true;                 ///< 16-bit half R, G, B, A; false = 32-bit float
  std::vector<ExrChannel> extra;    ///< AOV channels after R, G, B, A
  std::string compression = "zip";  ///< any OpenEXR compression OIIO accepts; with multipart,
                                    ///< lossy codecs apply to colour parts only (data: zip)
  bool multipart = false;           ///< one part per layer ("rgba", "albedo", "N", "Z", ...)
  std::vector<std::pair<std::string, std::string>> metadata;  ///< extra string attributes
  std::vector<std::pair<std::string, float>> float_metadata;  ///< extra float attributes
  /// 4x4 matrix attributes (M44f, row-major, row vectors: p' = p M, as OpenEXR's
  /// worldToCamera and worldToNDC).
  std::vector<std::pair<std::string, std::array<float, 16>>> matrix_metadata;
};

/// Writes channels R, G, B, A (colour premultiplied by A) and the extra channels to `path`.
/// Throws std::runtime_error naming the file if OpenImageIO fails, std::invalid_argument if an
/// extra channel has the wrong size.
/// If `sha256` is not null it receives the SHA-256 of the file's bytes.
void write_exr(const Film& film, const std::filesystem::path& path, const ExrOptions& options,
               std::string* sha256 = nullptr);

/// The beauty (R, G, B, A of the first part, premultiplied) of an EXR as a whole-frame film, to
/// make a display image of a merged frame. Throws InputError naming the file when it is not a
/// readable EXR with those channels or its pixels need more than `max_bytes`.
Film read_exr_beauty(const std::filesystem::path& path, uint64_t max_bytes);

struct DisplayOptions {
  std::string ocio_config;  ///< config file; empty = $OCIO if set, else Penumbra's shipped config
  std::string display;      ///< empty = the config's default display
  std::string view;         ///< empty = the display's default view
  std::string look;         ///< an OCIO look applied in scene-linear before the view; empty = none
  float exposure = 0;       ///< stops applied in scene-linear before the view transform
  /// Round the beauty to half floats first, as a half EXR stores it: the display image of a
  /// render then equals the one made from its EXR (a merged farm frame's).
  bool half_beauty = false;
  /// Keep the beauty's alpha: RGBA with straight (un-premultiplied) colour, the view applied to
  /// the un-premultiplied scene-linear colour. PNG and TIFF only.
  bool alpha = false;
};

/// What a display image was made with, as recorded in its metadata and the EXR's.
struct DisplayDescription {
  std::string config;  ///< the config's name (its `name:` field), else its file, else "penumbra-default"
  std::string source;  ///< the config's file, "$OCIO=<file>", or "<shipped config>"
  std::string display, view, look;  ///< resolved (defaults filled in); look empty = none
  std::string colorspace;           ///< the view's colour space
  float exposure = 0;
  bool srgb = false;  ///< the encoding is sRGB (the view's colour space or the display is named sRGB and
                      ///< is not data): only then does the image carry sRGB tags
};

/// Resolves `options` against its config as write_display_image does. Throws InputError as
/// check_display_output.
DisplayDescription describe_display(const DisplayOptions& options);

/// The metadata attributes of a display description: "penumbra:ocio_config", ..._display,
/// ..._view, ..._look, ..._colorspace and "penumbra:exposure" (as text).
std::vector<std::pair<std::string, std::string>> display_metadata(const DisplayDescription& d);

/// Writes the beauty (over black, or with its alpha under options.alpha) through the
/// display/view transform as 8-bit RGB(A) (16-bit for TIFF). The format follows the extension
/// (.png, .jpg/.jpeg, .tif/.tiff). The file records display_metadata(); it is tagged sRGB only
/// when the description says so; a crop or tile keeps its offset in the full frame (PNG oFFs,
/// TIFF XPosition/YPosition). Throws InputError for a bad config/display/view and
/// std::runtime_error for write failures.
/// If `sha256` is not null it receives the SHA-256 of the file's bytes.
void write_display_image(const Film& film, const std::filesystem::path& path, const DisplayOptions& options,
                         std::string* sha256 = nullptr);

/// Checks, before any rendering, that `path` has a display-image extension (.png, .jpg,
/// .jpeg, .tif, .tiff; with options.alpha not JPEG) and that the config, display and view resolve. Throws
/// InputError naming the file or config and, for an unknown display or view, listing the valid ones.
void check_display_output(const std::filesystem::path& path, const DisplayOptions& options);

/// Writes `values` (width x height, row-major) as an 8-bit sRGB heat map (.png, .jpg, .tif):
/// linear from 0 (dark blue) to the image's maximum (yellow) on the viridis ramp, with a legend
/// strip below it: `title`, the colour bar and its scale (0, quarters, maximum). Written
/// atomically. Throws std::runtime_error naming the file if OpenImageIO fails.
void write_heatmap(const std::vector<float>& values, int width, int height, const std::filesystem::path& path,
                   const std::string& title, std::string* sha256 = nullptr);

/// Penumbra's shipped OCIO config text (io/ocio/config.ocio, embedded at build time).
const char* shipped_ocio_config();

/// Applies the display transform to `rgb` (width*height*3 floats, in place).
void apply_display_transform(std::vector<float>& rgb, int width, int height, const DisplayOptions& options);

}  // namespace penumbra
