// `penumbra render`'s flags and their validation: RenderArgs holds what was typed; check_render_args
// turns it, before anything is loaded, into a RenderRequest of checked values (outputs resolved
// and distinct, display transform found, integrator options consistent, AOVs known) with the
// render spec (render/spec.h) the render session renders, so a typo never costs a render.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "apps/penumbra/camera_options.h"
#include "io/image/image_output.h"
#include "render/spec.h"
#include "renderer/accel/factory.h"
#include "renderer/integrators/render.h"

namespace penumbra::cli {

/// The flags of `penumbra render` as typed (defaults as README documents them).
struct RenderArgs {
  std::string scene_file, output, png;
  bool multipart = false;
  bool no_png = false, use_float = false, quiet = false, allow_external = false, flatten = false;
  int scene = -1;
  RenderSpec spec;         ///< every flag of the render spec's table (render/spec.h), as typed
  std::string camera;      ///< index or name; empty = the first camera, or framing
  std::string variant;     ///< KHR_materials_variants name; empty = the primitives' own materials
  std::string seed = "0";  ///< parsed as an unsigned 64-bit integer
  float exposure = 0;
  std::string compression = "zip", ocio_config, display, view, background = "0", ambient = "0.05";
  std::string max_memory, debug_pixel, cost_png;
  std::string deep;  ///< --deep: the deep EXR's path; empty = none
  std::vector<std::string> accel_params, aovs;
  std::string command_line, look;
  std::vector<std::string> crop;  ///< x0 x1 y0 y1, pixels or fractions
  std::string tile;               ///< "i/N"
  double checkpoint = 0;          ///< seconds between checkpoints; 0 = none
  std::string stats_json;
  bool resume = false;
  std::string env;  ///< --env: a radiance r,g,b or grey, or a map file
  bool spp_given = false, depth_given = false, background_given = false, ambient_given = false;
  bool raster_shadows_given = false, shadow_map_size_given = false;
  bool crypto_depth_given = false;
  bool png_alpha = false;             ///< the display image keeps the beauty's alpha (RGBA)
  std::optional<double> time;         ///< --time, seconds
  std::optional<std::string> frame;   ///< --frame, an integer, converted with --fps
  std::optional<std::string> frames;  ///< --frames A-B[:STEP] or N, each frame as --frame
  bool skip_existing = false;         ///< keep a frame whose -o is already a complete EXR
  bool overwrite = false;             ///< the default, accepted explicitly
  bool reproducible = false;          ///< no command line or timing in the EXR: equal renders, equal files
  std::string progress = "auto";      ///< --progress: auto, text, json or none (see progress.h)
  std::string contact_sheet;          ///< --contact-sheet: the frames' display images tiled into one
  int contact_sheet_columns = 0;      ///< 0: as many as keep the sheet no taller than wide
  CameraArgs cam;                     ///< --look-at, --orbit, --turntable, --fov, ... (camera_options.h)
};

/// Declares every flag of `render` on `render`, bound to `args`.
void add_render_options(CLI::App& render, RenderArgs& args);

/// After parsing: which defaults were overridden, and the command line for the EXR metadata.
void note_given_options(const CLI::App& render, int argc, char** argv, RenderArgs& args);

/// The checked values of a render request, everything that can be known before loading.
struct RenderRequest {
  bool path = false;    ///< --integrator path
  bool raster = false;  ///< --integrator raster
  std::filesystem::path out;
  std::optional<std::filesystem::path> png, cost_png;
  std::optional<std::filesystem::path> deep;  ///< --deep
  bool out_streams = false;                   ///< -o is a device or FIFO (no resume state beside it)
  bool paths_to_stdout = true;                ///< false when an output streams to stdout
  DisplayOptions display;
  Vec3f background, ambient;
  FilterType filter_type = FilterType::Box;
  float filter_width = 1;
  std::optional<Vec3f> env_colour;  ///< --env as a radiance; unset: a map file or none
  int debug_x = -1, debug_y = -1;   ///< --debug-pixel (range-checked once the size is known)
  AccelConfig accel_config;
  uint64_t seed = 0;
  uint64_t budget = 0;  ///< --max-memory in bytes
  std::set<std::string> aovs;
  bool cost_aov = false, data_aovs = false;
  std::vector<std::string>
      crypto;  ///< Cryptomatte layers asked for: CryptoObject, CryptoMaterial, CryptoAsset
  int crypto_depth = 6;
  std::optional<double> time;  ///< animation time from --time or --frame / --fps (not a turntable's frame)
  CameraRig rig;               ///< the camera flags, checked; for a turntable at this frame
  /// Every file the run writes, named by its option, for the collision checks (also against
  /// the files the scene loads, once they are known).
  std::vector<std::pair<std::string, std::filesystem::path>> outputs;
  bool state_beside_output = false;  ///< the resume state path can hold a regular file
  /// The render spec the flags describe, validated (its window is set once the image size is
  /// known, by parse_window).
  RenderSpec spec;
};

/// Validates every flag in the order README lists the checks. Throws UsageError or InputError
/// (exit 2) naming the flag; writes nothing.
RenderRequest check_render_args(const RenderArgs& args);

/// --crop x0 x1 y0 y1 (integers: pixels; with a '.': fractions of the width or height; x1, y1
/// exclusive) or --tile i/N (stripe i of N equal bands of rows, top first); empty if neither.
PixelWindow parse_window(const RenderArgs& args, int width, int height);

}  // namespace penumbra::cli
