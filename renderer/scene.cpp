// Scene helpers.
#include "renderer/scene.h"

namespace penumbra {

Bounds3f compute_bounds(const Scene& scene) {
  Bounds3f b;
  for (const auto& m : scene.meshes)
    for (Vec3f p : m.positions) b = merge(b, p);
  return b;
}

uint64_t count_triangles(const Scene& scene) {
  uint64_t n = 0;
  for (const auto& m : scene.meshes) n += m.indices.size() / 3;
  return n;
}

std::vector<TriangleMeshView> mesh_views(const Scene& scene) {
  std::vector<TriangleMeshView> views;
  views.reserve(scene.meshes.size());
  for (const auto& m : scene.meshes) views.push_back({m.positions, m.indices});
  return views;
}

std::vector<Vec3f> compute_smooth_normals(std::span<const Vec3f> positions,
                                          std::span<const uint32_t> indices) {
  std::vector<Vec3f> n(positions.size());
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    const uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    // |cross| = 2 x area, so summing unnormalised cross products weights by area.
    const Vec3f face = cross(positions[b] - positions[a], positions[c] - positions[a]);
    n[a] += face;
    n[b] += face;
    n[c] += face;
  }
  for (auto& v : n) {
    v = normalize(v);
    if (!(dot(v, v) > 0)) v = {0, 0, 1};
  }
  return n;
}

}  // namespace penumbra
