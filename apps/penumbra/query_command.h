// `penumbra query`: spatial queries on a glTF scene without rendering — the k primitives nearest
// to points, every primitive within a distance or meeting a box or a ball, the first hit of a
// ray, and what the camera sees through a pixel — answered by any acceleration structure, as
// text or one JSON document printed result by result.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/penumbra/camera_options.h"

namespace penumbra::cli {

/// The flags of `penumbra query nearest|within|overlap|ray|pick`.
struct QueryArgs {
  std::string file, accel = "embree";
  std::vector<std::string> accel_params;
  int scene = -1;
  bool allow_external = false, flatten = false, json = false;
  std::optional<double> time;   ///< the animation's pose, seconds (default: the static pose)
  std::string variant;          ///< KHR_materials_variants variant
  std::string max_memory;       ///< budget for the scene, the structure, the points and the answers
  std::string at, points_file;  ///< nearest, within: one point "X,Y,Z", or a file of points
  int k = 1;                    ///< nearest
  double max_distance = -1;     ///< nearest: -1 = unlimited
  double radius = -1;           ///< within
  std::string box, sphere;      ///< overlap
  std::string from, dir;        ///< ray
  std::string pixel;            ///< pick: "X,Y"
  std::string camera;           ///< pick: as render's --camera
  int width = 0, height = 0;    ///< pick: as render's --width, --height
  std::string frame;            ///< pick: the --turntable frame
  CameraArgs cam;               ///< pick: render's camera flags
  int threads = 0;
};

/// Declares `query` and its subcommands on `app`, bound to `args`; returns the `query` command.
CLI::App* add_query_command(CLI::App& app, QueryArgs& args);

/// Runs the subcommand `query` parsed. Prints on stdout; returns the exit code; throws for bad
/// input like render.
int run_query(const CLI::App& query, const QueryArgs& args);

}  // namespace penumbra::cli
