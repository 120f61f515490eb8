// Closed boxes as outward-wound triangles in double precision, for the collision tests.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/accel/polytope.h"

namespace penumbra::test {

/// Appends the box [lo, hi] as 8 corners and 12 triangles facing outwards.
inline void add_box_triangles(DVec3 lo, DVec3 hi, std::vector<DVec3>& pts, std::vector<uint32_t>& tris) {
  const uint32_t base = uint32_t(pts.size());
  for (int i = 0; i < 8; ++i) pts.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces)
    for (int k : {0, 1, 2, 0, 2, 3}) tris.push_back(base + uint32_t(f[k]));
}

}  // namespace penumbra::test
