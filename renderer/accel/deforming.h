// Deformation motion blur in Penumbra's own structures: deforming triangle meshes (GeometryViews
// with motion steps) under a BVH whose nodes hold linear bounds per time segment.
#pragma once

// The tree's topology is built over each triangle's box averaged over the steps (the binned SAH
// builder of accel/bvh_build.h, which sees only boxes). Each node then keeps, per time segment
// between two consecutive steps, the union of its triangles' boxes at each of the two steps: a
// vertex moves linearly within a segment, so the two boxes interpolated at a time in it bound the
// triangles at that time (linear bounds, as Embree's motion-blur BVH keeps them). A ray tests
// the boxes at its own time, and each triangle interpolated at its time with the watertight
// test every own structure shares (accel/triangle.h). Woop et al., "STBVH: A Spatial-Temporal
// BVH for Efficient Multi-Segment Motion Blur", HPG 2017, also splits in time, which this tree
// does not.

#include <cstdint>
#include <memory>
#include <span>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// Build parameters of the deforming-mesh structure.
struct DeformingConfig {
  int max_leaf_size = 4;    ///< [1, 255]: triangles per leaf at most
  bool exhaustive = false;  ///< true: no tree, every triangle tested (the brute-force reference)
};

/// The structure over `meshes` (each mesh.deforms(), all with the same motion_steps: copies of
/// their positions), their arrays copied. Hits: geom_id the view's index, prim_id the triangle
/// index, t, u and v those of the triangle interpolated at the ray's time (interpolate_vertex),
/// exactly as the watertight test gives them for a static mesh at that pose. A triangle with a
/// non-finite vertex at any step is never hit. Throws std::invalid_argument if a mesh does not
/// deform or has another step count, or its arrays disagree (an index out of range,
/// motion_positions not motion_steps x positions.size()).
std::unique_ptr<Accelerator> make_deforming_accelerator(std::span<const GeometryView> meshes,
                                                        const DeformingConfig& config = {});

}  // namespace penumbra
