// Seeded generators of the benchmark's stress scenes. Each scene stresses acceleration
// structures differently; the same (name, seed, triangles) always gives bit-identical geometry
// on every platform (own integer RNG, no std distributions). Scenes are plain renderer Scenes
// with a camera and lights, so they can be benchmarked in memory or written as glTF and rendered.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "renderer/scene/scene.h"

namespace penumbra::bench {

/// One generator: its name, what it stresses, and its default triangle count.
struct GeneratorInfo {
  std::string name;
  std::string description;
  uint64_t default_triangles;
};

/// The generators, in the order the benchmark runs them:
///   atrium   - architectural interior (Sponza-like): hall, two storeys of columns and arches,
///              gallery floors, drapes, seeded clutter. Large occluders, mixed triangle sizes.
///   soup     - uniformly random small triangles in a cube: no structure to exploit.
///   stadium  - "teapot in a stadium": a dense teapot-like object (almost every triangle) in a
///              huge, sparse bowl of large triangles. Uniform grids collapse on it.
///   slivers  - long thin triangles along one axis: overlapping boxes, bad for SAH and grids.
///   terrain  - fBm heightfield for the scaling series (default 5.2M triangles).
///   spheres  - analytic spheres (one per 10,000 requested triangles) on a ground quad.
///   spheres-mesh - the same spheres, each tessellated to 10,080 triangles: analytic shapes
///              against the triangles they replace.
std::vector<GeneratorInfo> generators();

/// Generates scene `name` with about `triangles` triangles (0: the generator's default;
/// the result is within a few percent above or below, except for the fixed parts). Throws
/// std::invalid_argument for an unknown name or a count outside [1000, 100M].
Scene generate_scene(const std::string& name, uint64_t seed = 1, uint64_t triangles = 0);

}  // namespace penumbra::bench
