// The glTF loader's parse phase: the scene file read under the memory budget, the GLB container,
// the JSON depth guard, the raw-JSON checks (json_checks.h), element and buffer charges, URI
// resolution, then tinygltf parsing through the file sandbox (file_access.h). What follows it
// (validation and conversion into a Scene) is in loader.cpp.
#pragma once

#include <filesystem>

#include "io/gltf/context.h"
#include "io/gltf/procedural.h"
#include "io/gltf/shapes.h"

namespace tinygltf {
class Model;
}

namespace penumbra::gltf {

/// What the vendor extensions describe, read from the raw JSON: the nodes' PENUMBRA_shapes
/// (read_node_shapes()) and the materials' PENUMBRA_procedural (read_material_procedurals()).
struct VendorExtensions {
  std::vector<NodeShape> shapes;
  std::vector<MaterialProcedural> procedurals;
};

/// Parses `file` into `model`, and the vendor extensions into `vendor`. GLB chunk warnings and tinygltf's
/// warnings go to out.warnings; every file read goes to out.info.source_files (the scene file first). What
/// parsing holds is charged to `budget`. Throws InputError.
void parse_gltf(const std::filesystem::path& file, const GltfLoadOptions& options, MemoryBudget& budget,
                LoadedScene& out, tinygltf::Model& model, VendorExtensions& vendor);

}  // namespace penumbra::gltf
