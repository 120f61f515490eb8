// Draco mesh decoding behind a narrow interface. It is built as its own shared library with
// hidden symbols, because Debian's Draco carries a copy of tinygltf of another version whose
// inline functions would otherwise replace the loader's at link time. Internal to io/gltf/.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace penumbra::gltf {

/// One attribute to read from a Draco stream: its unique id, the glTF componentType and
/// component count to convert to, and (out) its values, point-major, tightly packed.
struct DracoAttribute {
  uint32_t id = 0;
  int component_type = 0;
  int components = 0;
  std::vector<unsigned char> data;
};

/// What decode_draco() found: an error (empty on success), the stream's point and face counts,
/// and the triangle list (3 point indices per face).
struct DracoMesh {
  std::string error;
  uint64_t points = 0, faces = 0;
  std::vector<uint32_t> indices;
};

/// Decodes `bytes` bytes of a Draco mesh stream. Fills the indices and `attributes` only if the
/// stream holds exactly `expected_points` points and `expected_faces` faces (else only the
/// counts, for the caller's message); error names what failed (a malformed stream, an id the
/// stream lacks, a component count that differs, a conversion Draco cannot make).
__attribute__((visibility("default"))) DracoMesh decode_draco(const unsigned char* data, uint64_t bytes,
                                                              uint64_t expected_points,
                                                              uint64_t expected_faces,
                                                              std::vector<DracoAttribute>& attributes);

}  // namespace penumbra::gltf
