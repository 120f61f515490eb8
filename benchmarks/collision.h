// penumbra-bench --collision: the collision queries measured on a model (all its placed meshes as
// one body):
//  - the proxy trade-off: per kind, fit time, bytes, distance tests per second between two
//    copies in random placements, and tightness (volume over the convex hull's, Hausdorff
//    distance over the model's diagonal);
//  - proxy-proxy distance tests per second for every pair of kinds;
//  - mesh against mesh: the model against a turned copy at increasing overlap, by the own box
//    trees (build and query), Embree's rtcCollide with the same exact triangle test, and FCL's
//    OBBRSS trees when the build found it; every method must find the same meeting triangle
//    pairs, or the run fails.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "renderer/scene/scene.h"

namespace penumbra::bench {

/// What --collision measures.
struct CollisionBenchConfig {
  int builds = 3;                                      ///< fits and tree builds per method (median)
  int repeats = 3;                                     ///< timed passes (median)
  int tests = 2000;                                    ///< proxy distance tests per pair of kinds
  int samples = 20000;                                 ///< surface samples for the Hausdorff distance
  std::vector<double> overlaps{0.0, 0.05, 0.25, 0.5};  ///< fractions of the model's x extent
  uint64_t seed = 1;
  std::string csv;  ///< also write every row as CSV (atomically)
};

/// Measures each named scene and prints its tables. Returns 0, or 1 when the mesh methods
/// disagreed on a pair count. Throws std::invalid_argument for a scene without triangles.
int run_collision(const std::vector<std::pair<std::string, Scene>>& scenes,
                  const CollisionBenchConfig& config);

}  // namespace penumbra::bench
