// Implicit shapes as triangle meshes: every implicit shape a scene places (or one node's) is
// extracted by marching cubes in its object space, moved into the world by its instance and given
// its material, as a scene of world-space meshes that io/gltf_writer can write.
#pragma once

#include <cstdint>

#include "renderer/scene/scene.h"
#include "renderer/shapes/marching_cubes.h"

namespace penumbra {

/// Settings of mesh_implicit_shapes().
struct ShapeMeshConfig {
  int resolution = 128;  ///< cells along the longest axis of each shape's sdf_bounds, in [1, 4096]
  int node = -1;         ///< only the instances of this glTF node; -1 = every instance
  /// Bytes the grids and meshes may take in all: each shape's working memory and mesh estimate
  /// (marching_cubes_bytes), and the mesh estimates of all placements with the largest working
  /// memory, are checked before anything is meshed, each exact mesh before it is allocated.
  uint64_t max_bytes = UINT64_MAX;
  MarchingCubesConfig marching_cubes;  ///< max_output_bytes is set from max_bytes
};

/// What mesh_implicit_shapes() made.
struct ShapeMeshes {
  Scene scene;               ///< the meshes (world space, identity instances) and the materials
  int skipped_analytic = 0;  ///< selected instances of analytic shapes (not meshed)
};

/// One world-space mesh per selected instance of an implicit shape, in instance order: positions
/// by to_world, normals by its inverse transpose, triangles reversed under a mirroring map so
/// they stay counter-clockwise seen from outside; the mesh takes the shape's material and name
/// and the instance's node. The scene's materials are copied unchanged. Throws
/// std::invalid_argument for a bad resolution, an implicit shape without bounds, a shape whose
/// grid or mesh does not fit max_bytes, or placements whose meshes do not fit it together (naming
/// the shape, for those the one with the most mesh bytes, and the bytes needed).
ShapeMeshes mesh_implicit_shapes(const Scene& scene, const ShapeMeshConfig& config);

}  // namespace penumbra
