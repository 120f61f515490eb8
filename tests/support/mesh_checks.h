// Invariants of indexed triangle meshes for tests: closed and consistently oriented (every
// directed edge once, with its reverse), manifold vertices (each vertex's link one cycle), the
// Euler characteristic, surface area and enclosed volume (divergence theorem).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra::test {

struct MeshTopology {
  uint64_t directed_edges_repeated = 0;  ///< directed edges used by more than one triangle
  uint64_t edges_without_twin = 0;       ///< directed edges whose reverse no triangle uses
  uint64_t nonmanifold_vertices = 0;     ///< vertices whose link is not one cycle
  uint64_t unused_vertices = 0;
  uint64_t bad_indices = 0;  ///< indices >= vertex count, or a triangle repeating a vertex
  int64_t euler = 0;         ///< V - E + F (V counts used vertices)
  bool closed_manifold() const {
    return directed_edges_repeated == 0 && edges_without_twin == 0 && nonmanifold_vertices == 0 &&
           bad_indices == 0;
  }
};

inline MeshTopology mesh_topology(size_t vertex_count, std::span<const uint32_t> indices) {
  MeshTopology m;
  std::unordered_map<uint64_t, int> directed;
  directed.reserve(indices.size() * 2);
  std::vector<uint8_t> used(vertex_count, 0);
  struct LinkEdge {
    uint32_t vertex, from, to;
  };
  std::vector<LinkEdge> links;
  links.reserve(indices.size());
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
    if (v[0] >= vertex_count || v[1] >= vertex_count || v[2] >= vertex_count || v[0] == v[1] ||
        v[1] == v[2] || v[0] == v[2]) {
      ++m.bad_indices;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      used[v[k]] = 1;
      ++directed[(uint64_t(v[k]) << 32) | v[(k + 1) % 3]];
      links.push_back({v[k], v[(k + 1) % 3], v[(k + 2) % 3]});
    }
  }
  for (const auto& [key, count] : directed) {
    if (count > 1) ++m.directed_edges_repeated;
    if (!directed.count((key << 32) | (key >> 32))) ++m.edges_without_twin;
  }
  // Each vertex's link: the edges opposite it in its triangles must chain into a single cycle.
  std::sort(links.begin(), links.end(), [](const LinkEdge& a, const LinkEdge& b) {
    return a.vertex != b.vertex ? a.vertex < b.vertex : a.from < b.from;
  });
  for (size_t b = 0; b < links.size();) {
    size_t e = b;
    while (e < links.size() && links[e].vertex == links[b].vertex) ++e;
    bool ok = true;
    for (size_t i = b + 1; i < e; ++i) ok = ok && links[i].from != links[i - 1].from;
    size_t steps = 0;
    uint32_t at = links[b].to;
    while (ok && at != links[b].from && steps < e - b) {
      const auto it = std::lower_bound(links.begin() + long(b), links.begin() + long(e), at,
                                       [](const LinkEdge& l, uint32_t x) { return l.from < x; });
      if (it == links.begin() + long(e) || it->from != at)
        ok = false;
      else
        at = it->to, ++steps;
    }
    if (!ok || steps + 1 != e - b) ++m.nonmanifold_vertices;
    b = e;
  }
  uint64_t vertices = 0;
  for (uint8_t u : used) vertices += u;
  m.unused_vertices = vertex_count - vertices;
  uint64_t undirected = 0;
  for (const auto& [key, count] : directed)
    if ((key >> 32) < (key & 0xffffffffu) || !directed.count((key << 32) | (key >> 32))) ++undirected;
  m.euler = int64_t(vertices) - int64_t(undirected) + int64_t(indices.size() / 3);
  return m;
}

inline double mesh_area(std::span<const Vec3f> p, std::span<const uint32_t> idx) {
  double area = 0;
  for (size_t t = 0; t + 2 < idx.size(); t += 3)
    area += 0.5 * double(length(cross(p[idx[t + 1]] - p[idx[t]], p[idx[t + 2]] - p[idx[t]])));
  return area;
}

/// Signed volume enclosed by a closed mesh, positive when its triangles are counter-clockwise
/// seen from outside: the sum of a . (b x c) / 6.
inline double mesh_volume(std::span<const Vec3f> p, std::span<const uint32_t> idx) {
  double volume = 0;
  for (size_t t = 0; t + 2 < idx.size(); t += 3)
    volume += double(dot(p[idx[t]], cross(p[idx[t + 1]], p[idx[t + 2]]))) / 6;
  return volume;
}

}  // namespace penumbra::test
