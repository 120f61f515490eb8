// Points on analytic shapes for light sampling: uniform by surface area in the shape's object
// space, the area element of an affine placement (so the density in world space is exact under
// any scale or shear), and the cone a sphere subtends from a point (pbrt-v4 6.2.4,
// Sphere::Sample with a reference point). Pure geometry: no materials, no scene.
#pragma once

#include "renderer/core/geometry.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

/// Surface area of the shape in its object space: sphere 4 pi r^2, plane 4 x z half sizes, disk
/// pi r^2, box 8 (xy + yz + zx), capsule 4 pi r (h + r). 0 for implicit shapes, which have no
/// closed-form area and are not sampled.
float shape_area(const Shape& shape);

/// A point on a shape's surface with its unit outward normal (front side for flat shapes).
struct ShapePoint {
  Vec3f p;
  Vec3f n;
};

/// A point distributed uniformly by object-space area (density 1 / shape_area) from u in
/// [0,1)^2: spheres by Archimedes' projection, disks by Shirley and Chiu's concentric map,
/// boxes and capsules by choosing a face or part in proportion to its area with u.x (then
/// reused). Requires shape_area(shape) > 0. Never allocates.
ShapePoint sample_shape_area(const Shape& shape, Vec2f u);

/// How much a placement with linear part L (row-major 3x3 of an Affine3f) stretches areas at a
/// surface point with object normal n: |det L| |L^-T n| (world area = this x object area).
/// `inverse` is the placement's inverse map. 0 for a singular map.
float area_scale(const Affine3f& to_world, const Affine3f& inverse, Vec3f n);

/// The uniform scale s when L = s R with R a rotation or reflection (columns orthogonal and of
/// equal length within a relative 1e-4), else 0. A sphere so placed stays a sphere of radius s r.
float similarity_scale(const Affine3f& to_world);

/// Solid angle subtended by a sphere of radius `radius` whose centre is `distance` away, as the
/// cone's 1 - cos(theta_max); 0 when the point is on or inside the sphere. Small cones use the
/// series 1 - cos = sin^2 / 2 (pbrt-v4), so that distant spheres keep their precision.
float sphere_cone_one_minus_cos(float radius, float distance);

/// A point on the part of the sphere (centre c, radius r) visible from `ref` (outside it),
/// uniform over the subtended cone of directions from u (density 1 / (2 pi (1 - cos theta_max))
/// per unit solid angle), with its outward normal. False when ref is on or inside the sphere.
bool sample_sphere_cone(Vec3f c, float r, Vec3f ref, Vec2f u, ShapePoint& out);

}  // namespace penumbra
