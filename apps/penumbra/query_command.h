// `penumbra query`: spatial queries on a glTF scene without rendering — the k primitives nearest
// to points, every primitive within a distance or meeting a box or a ball, and the first hit of
// a ray — answered by any acceleration structure, as text or one JSON document.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace penumbra::cli {

/// The flags of `penumbra query nearest|within|overlap|ray`.
struct QueryArgs {
  std::string file, accel = "embree";
  std::vector<std::string> accel_params;
  int scene = -1;
  bool allow_external = false, flatten = false, json = false;
  std::string at, points_file;  ///< nearest, within: one point "X,Y,Z", or a file of points
  int k = 1;                    ///< nearest
  double max_distance = -1;     ///< nearest: -1 = unlimited
  double radius = -1;           ///< within
  std::string box, sphere;      ///< overlap
  std::string from, dir;        ///< ray
  int threads = 0;
};

/// Declares `query` and its subcommands on `app`, bound to `args`; returns the `query` command.
CLI::App* add_query_command(CLI::App& app, QueryArgs& args);

/// Runs the subcommand `query` parsed. Prints on stdout; returns the exit code; throws for bad
/// input like render.
int run_query(const CLI::App& query, const QueryArgs& args);

}  // namespace penumbra::cli
