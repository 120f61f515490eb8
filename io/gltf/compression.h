// Geometry compression extensions, decoded into plain buffers before conversion:
// EXT_meshopt_compression and KHR_meshopt_compression (meshoptimizer's vertex and index codecs
// and filters on bufferViews) and KHR_draco_mesh_compression (Draco-coded primitives). After
// decompress_model() every bufferView and accessor the converters read is uncompressed, so the
// accessor checks of accessors.h apply to decoded data as to any other. Internal to io/gltf/.
#pragma once

#include <string>
#include <vector>

#include "io/gltf/context.h"

namespace tinygltf {
class Model;
}

namespace penumbra::gltf {

/// The compression extensions decompress_model() decodes.
std::vector<std::string> compression_extensions();

/// Decodes every compressed bufferView and Draco primitive of `model` in place: decoded bytes go
/// into new buffers, compressed bufferViews are pointed at them, and each Draco primitive's
/// attributes and indices get new accessors over its decoded data (the extension is then removed
/// from the primitive). Every decoded size is checked against the accessor or bufferView that
/// declares it and charged to `budget` before it is allocated. Throws InputError(file, element)
/// for a malformed stream, a declared size the stream does not match, or a size over the budget.
void decompress_model(tinygltf::Model& model, const std::string& file, MemoryBudget& budget);

}  // namespace penumbra::gltf
