// `penumbra info`: what a glTF file holds (scenes, nodes, meshes, instances, shapes, materials,
// cameras, lights, images, animations, extensions, bounds) and the statistics of the chosen
// acceleration structure built over it, as text or as one JSON document (--json).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "apps/penumbra/camera_options.h"

namespace penumbra::cli {

/// The flags of `penumbra info`.
struct InfoArgs {
  std::string file, accel = "embree";
  std::vector<std::string> accel_params;
  int scene = -1;
  bool allow_external = false, flatten = false, json = false;
  bool volumes = false;       ///< add each instance's enclosed volume
  std::string camera;         ///< as render's --camera
  int width = 0, height = 0;  ///< as render's: the image the view is described for
  std::string frame;          ///< the turntable frame (default 0)
  CameraArgs cam;             ///< render's camera flags
};

/// Declares info's flags on `info`, bound to `args`.
void add_info_options(CLI::App& info, InfoArgs& args);

/// Prints the description on stdout: as text, or with `json` as one JSON document (the schema
/// README documents; warnings are on stderr in both, and in the document's "warnings").
/// The view section describes the camera render would use with the same camera flags and image
/// size: its frame, lens, and view and projection matrices. Returns the exit code; throws for
/// bad input like render.
int run_info(const InfoArgs& args);

}  // namespace penumbra::cli
