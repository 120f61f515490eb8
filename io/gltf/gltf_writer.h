// glTF 2.0 writing: a renderer Scene (meshes and shapes placed by instances, metallic-roughness
// factors, punctual lights, cameras) as a .gltf JSON file with its geometry in one external .bin beside it,
// or as one binary .glb. Used by the benchmark scene generator, the PLY converter and `penumbra mesh`;
// load_gltf() reads the result back.
#pragma once

#include <filesystem>

#include "renderer/scene/scene.h"

namespace penumbra {

/// Writes `scene` to `file` (.gltf) and "<stem>.bin" in the same folder, both atomically
/// (a failure leaves neither half-written). Each mesh becomes one glTF mesh with one primitive
/// (POSITION, NORMAL and TEXCOORD_0 when present, uint32 indices) and each instance one node
/// using it (with a matrix unless the identity), so shared meshes stay shared; a mesh moved into
/// world space from a node (Mesh::object_from_world) is written in that node's frame under its
/// matrix; materials carry their procedural textures as PENUMBRA_procedural; lights use
/// KHR_lights_punctual; each camera becomes a node whose matrix is its (u, v, w, eye) frame.
/// Each shape instance becomes a node carrying its shape in PENUMBRA_shapes (listed in
/// extensionsUsed), CSG trees with one matrix per node that is not the identity.
/// Throws InputError naming the file if its target is refused (resolve_output) or the scene
/// cannot be expressed (a buffer over 4 GiB, an index out of range, an index count not a
/// multiple of 3, a non-finite position, an instance of a mesh that does not exist), and
/// std::runtime_error with the system's reason if a write, sync or rename fails.
void write_gltf(const Scene& scene, const std::filesystem::path& file);

/// The same document as one binary glTF (.glb, glTF 2.0 spec 4.4), written atomically: a 12-byte
/// header (magic "glTF", version 2, total length), the JSON chunk padded with spaces and the BIN
/// chunk (the geometry, absent when there is none) padded with zeros to 4 bytes, little endian;
/// the buffer has no uri. Throws as write_gltf(), and InputError for a file over 4 GiB.
void write_glb(const Scene& scene, const std::filesystem::path& file);

}  // namespace penumbra
