// Checks on the raw glTF JSON for what tinygltf's parse would lose or accept silently: it
// truncates integer indices to int, reads a negative byteOffset or byteStride as absent, and
// keeps strings where arrays belong. Run on the nlohmann DOM before tinygltf parses the text;
// each violation is an InputError naming the JSON path. Internal to io/gltf/.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace penumbra::gltf {

/// Validates, per the glTF 2.0 schema and spec:
/// - every index property (scene, scenes[].nodes, nodes[].camera/mesh/skin/children, the
///   KHR_lights_punctual light, EXT_mesh_gpu_instancing attributes, primitive indices, material,
///   attributes and targets, accessor and sparse bufferViews, bufferView.buffer, image.bufferView,
///   texture source/sampler, material texture indices, skin joints/skeleton/inverseBindMatrices,
///   animation channel sampler/target node, sampler input/output) is an integer in
///   [0, INT_MAX] and within its array;
/// - byteOffset, byteLength and texCoord are non-negative integers (sparse byteOffsets at most
///   INT_MAX); byteStride is a multiple of 4 in [4, 252];
/// - sampler magFilter, minFilter, wrapS and wrapT hold one of the spec's enum values;
/// - extensionsUsed and extensionsRequired are arrays of strings;
/// - animation channel target paths are translation, rotation, scale or weights (or "pointer"
///   when KHR_animation_pointer is listed in extensionsUsed), sampler interpolations are
///   LINEAR, STEP or CUBICSPLINE;
/// - all primitives of a mesh have the same number of morph targets, and mesh.weights and
///   node.weights (which needs node.mesh) have exactly that many entries.
/// Throws InputError(file, JSON path, reason).
void check_gltf_json(const nlohmann::json& doc, const std::string& file);

}  // namespace penumbra::gltf
