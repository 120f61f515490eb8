// Interpenetration volumes: how much of two solids overlaps.
//  - Convex polyhedra (boxes, hulls, k-DOPs, a composite's parts): exact, by clipping a box
//    with every face plane of both (Polytope, in double precision).
//  - Two balls: the lens in closed form.
//  - Any other pair (spheres or capsules against polyhedra, closed meshes as solids): adaptive
//    cell quadrature with a guaranteed bound. A cell whose centre lies farther than its half
//    diagonal from a solid's surface is wholly inside or wholly outside it, so each level of an
//    octree over the two solids' common box settles such cells, in or out, and splits the rest;
//    the cells still unsettled when the bound is met (or the cell budget runs out) count half,
//    and half their volume is the error bound: the true volume lies in
//    [volume - error, volume + error]. Closed meshes measure distances on their SolidMesh (exact
//    point-triangle distances, inside by the solid BSP).
#pragma once

#include <cstdint>

#include "renderer/collision/proxy.h"
#include "renderer/shapes/solid_bsp.h"

namespace penumbra {

/// A volume with its bound.
struct VolumeEstimate {
  double volume = 0;   ///< the estimate
  double error = 0;    ///< the true volume lies within +-error of it (0 when exact)
  bool exact = false;  ///< closed form or clipping (error 0)
  uint64_t cells = 0;  ///< cells evaluated by the quadrature (0 when exact)
};

/// How the cell quadrature refines.
///
/// | field          | default | meaning                                                        |
/// |----------------|---------|----------------------------------------------------------------|
/// | relative_error | 1e-2    | stop when error <= relative_error x the smaller solid's volume |
/// | max_cells      | 2^21    | cells evaluated at most (the error bound says what remains);   |
/// |                |         | a level's cells take 25 bytes each, two levels at a time       |
struct SharedVolumeConfig {
  double relative_error = 1e-2;
  uint64_t max_cells = uint64_t(1) << 21;
};

/// The volume of the intersection of two convex polyhedra given by their planes (inside
/// n . p <= d), clipped from `start`, a box that holds their intersection. Exact to rounding.
double convex_intersection_volume(std::span<const DPlane> a, std::span<const DPlane> b,
                                  const Bounds3f& start);

/// The volume two balls share (the lens; the smaller ball when one holds the other).
double ball_intersection_volume(const BoundingSphere& a, const BoundingSphere& b);

/// The volume two proxies share: exact for polyhedral kinds (aabb, obb, hull, kdop; composites
/// part by part, summed, when no two parts of a composite overlap) and for two spheres; the
/// cell quadrature for the rest (a capsule, one sphere, a composite whose parts overlap).
VolumeEstimate proxy_intersection_volume(const Proxy& a, const Proxy& b,
                                         const SharedVolumeConfig& config = {});

/// The volume two solids share, each the union of closed meshes (a node placing several meshes,
/// or copies of one: each its own solid, so that overlapping or mirrored parts stay sound), by
/// the cell quadrature. An empty span is an empty solid (volume 0). The union's distance skips
/// the meshes whose boxes lie farther than the nearest answer so far.
VolumeEstimate mesh_intersection_volume(std::span<const SolidMesh> a, std::span<const SolidMesh> b,
                                        const SharedVolumeConfig& config = {});

}  // namespace penumbra
