// The id AOV's name manifest: the JSON the EXR carries in penumbra:manifest, shared by the
// command and the Python module.
#pragma once

#include <string>

#include "io/gltf/loader.h"

namespace penumbra {

/// `v` as a JSON string literal (quotes, backslashes and control characters escaped).
std::string json_quote(const std::string& v);

/// {"object": {"<id>": "<node name>", ...}, "material": {...}}: the names behind object_id
/// (glTF node index + 1, for every node an instance comes from) and material_id (material
/// index + 1); 0 is the background.
std::string id_manifest(const Scene& scene, const GltfInfo& info);

}  // namespace penumbra
