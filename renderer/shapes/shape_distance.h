// Distances to shapes for spatial queries: the point of a shape's surface nearest to a point,
// in the shape's object space.
#pragma once

#include "renderer/shapes/shape.h"

namespace penumbra {

/// The point of the shape's surface nearest to `p` (object space, p finite). Exact for the
/// analytic shapes (sphere, rectangle, disk, box surface — from inside too —, capsule); for an
/// implicit shape, the surface point that Newton projection along the tree's gradient reaches
/// from `p` (at most 64 steps, |f| / L below the tree's trace tolerance), which is the nearest
/// one where the tree is a Euclidean distance. Where the nearest point is not unique (the
/// centre of a sphere) one of them. Never allocates or throws.
Vec3f closest_point_on_shape(const Shape& shape, Vec3f p);

}  // namespace penumbra
