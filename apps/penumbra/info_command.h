// `penumbra info`: what a glTF file holds (scenes, nodes, meshes, instances, shapes, materials,
// cameras, lights, images, animations, extensions, bounds) and the statistics of the chosen
// acceleration structure built over it, as text or as one JSON document (--json).
#pragma once

#include <string>
#include <vector>

namespace penumbra::cli {

/// Prints the description on stdout: as text, or with `json` as one JSON document (the schema
/// README documents; warnings are on stderr in both, and in the document's "warnings").
/// Returns the exit code; throws for bad input like render.
int run_info(const std::string& file, int scene_index, bool allow_external, bool flatten,
             const std::string& accel_name, const std::vector<std::string>& accel_params, bool json = false);

}  // namespace penumbra::cli
