// Shared pieces of the reference structures: gathering triangles into one packed array.
#include "renderer/accel/common.h"

namespace penumbra {

std::vector<TriangleRecord> gather_triangles(std::span<const TriangleMeshView> meshes) {
  size_t n = 0;
  for (const auto& m : meshes) n += m.indices.size() / 3;
  std::vector<TriangleRecord> tris;
  tris.reserve(n);
  for (uint32_t g = 0; g < meshes.size(); ++g) {
    const auto& m = meshes[g];
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
      TriangleRecord t{m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                       m.positions[m.indices[i + 2]], g, uint32_t(i / 3)};
      if (is_finite(t.a) && is_finite(t.b) && is_finite(t.c)) tris.push_back(t);
    }
  }
  return tris;
}

}  // namespace penumbra
