// Shapes that are not triangle meshes: analytic primitives with exact ray tests (sphere, plane,
// disk, box, capsule) and implicit surfaces (CSG trees of SDFs, sphere traced), each in its own
// object space. The one ray test per kind that every acceleration structure calls, and the
// surface data (normal, UV) at a hit point. Pure geometry: no materials, no placement.
#pragma once

#include <array>
#include <cstdint>

#include "renderer/core/geometry.h"
#include "renderer/shapes/sdf.h"

namespace penumbra {

/// What a Shape is. Canonical frames: centred at the origin, axis of symmetry +Y, flat shapes in
/// the XZ plane facing +Y.
enum class ShapeKind : uint8_t {
  Sphere,    ///< radius
  Plane,     ///< rectangle |x| <= half_size.x, |z| <= half_size.z at y = 0, front +Y
  Disk,      ///< x^2 + z^2 <= radius^2 at y = 0, front +Y
  Box,       ///< |x|, |y|, |z| <= half_size
  Capsule,   ///< points within radius of the segment (0, -half_height, 0)-(0, half_height, 0)
  Implicit,  ///< the zero set of sdf (f < 0 inside), sphere traced
  Segment,   ///< points within radius of the segment p0-p1 (a sphere about p0 when p1 == p0): one
             ///< line segment or point of a curve set (GeometryView::curves), in its view's space
  Splat,     ///< a 3D Gaussian about p0 (make_splat_shape), hit at its response's maximum along
             ///< the ray where that is inside kSplatSigmas and at least kSplatMinAlpha
};

/// Number of ShapeKind values.
inline constexpr int kShapeKindCount = 8;

/// "sphere", "plane", "disk", "box", "capsule", "implicit", "segment", "splat".
const char* shape_kind_name(ShapeKind kind);

/// One shape in its object space. Make implicit shapes with make_implicit_shape() so that
/// `lipschitz` and `sdf_bounds` agree with the tree.
struct Shape {
  ShapeKind kind = ShapeKind::Sphere;
  float radius = 1;          ///< Sphere, Disk, Capsule; > 0
  float half_height = 0.5f;  ///< Capsule: half length of the axis segment; >= 0
  Vec3f half_size{1, 1, 1};  ///< Box: half extents (> 0); Plane: x and z half sizes (> 0);
                             ///< Splat: the half extents of its box at kSplatSigmas
  SdfTree sdf;               ///< Implicit: the CSG tree, in object space
  float lipschitz = 1;       ///< Implicit: sdf_lipschitz(sdf)
  Bounds3f sdf_bounds;       ///< Implicit: a box holding every point with f <= 0
  SphereTraceConfig trace;   ///< Implicit: step budget and tolerances
  Vec3f p0, p1;              ///< Segment: the axis' end points; Splat: p0 is the centre
  /// Splat: the rows of S^-1 R^T, which map p - p0 into the Gaussian's whitened frame (where its
  /// density is exp(-|x|^2 / 2)).
  std::array<Vec3f, 3> whiten{};
  float opacity = 0;     ///< Splat: the peak opacity, in [0, 1]
  uint32_t element = 0;  ///< the prim_id a hit on it reports: a Segment's index in its curve
                         ///< set; 0 for a shape of its own
};

/// A Segment shape: the capsule of `radius` about p0-p1 (a sphere when they are equal) that
/// reports prim_id `element`.
Shape make_segment_shape(Vec3f p0, Vec3f p1, float radius, uint32_t element);

/// Mahalanobis distance at which a splat's kernel ends (the extension's ellipse kernel: 3 sigma).
inline constexpr float kSplatSigmas = 3;
/// Responses below this are not hits (as 3D Gaussian Splatting's rasteriser skips alpha < 1/255).
inline constexpr float kSplatMinAlpha = 1.0f / 255;

/// A Splat shape: the Gaussian about `centre` with unit rotation quaternion q = (x, y, z, w)
/// (local to view space) and standard deviations `scale` along its local axes (Sigma =
/// R S S^T R^T), of peak `opacity`, reporting prim_id `element`. Scales below 1e-3 of the
/// largest are raised to it (a flat splat is a thin disc); a splat without a positive finite
/// scale or opacity gets empty bounds (never hit).
Shape make_splat_shape(Vec3f centre, Vec4f q, Vec3f scale, float opacity, uint32_t element);

/// The response of a Splat shape along `ray` at its maximum (Moenne-Loccoz et al., "3D Gaussian
/// Ray Tracing", 2024): t* = -(o'.d') / (d'.d') in the whitened frame (o' = W (o - p0),
/// d' = W d), `m2` = |o' + t* d'|^2 the squared Mahalanobis distance there and
/// alpha = opacity exp(-m2 / 2). False for a zero direction or a non-finite answer.
bool splat_response(const Shape& splat, const Ray& ray, double& t, double& m2, double& alpha);

/// An implicit shape over `tree` with its Lipschitz bound and bounds computed. The bounds are
/// empty when the tree's inside is not bounded (a complement or half-space not intersected
/// with something finite): such a shape cannot be placed in an accelerator.
Shape make_implicit_shape(SdfTree tree, const SphereTraceConfig& trace = {});

/// A box holding every point where the tree is <= 0, in the tree's frame, from each primitive's
/// extents mapped through the node transforms (union: merge; intersection: overlap; subtraction:
/// the first operand; smooth operators: widened by the blend radius over the smallest singular
/// value of the transforms below; Displace: its child's, widened likewise by |amplitude|). Empty
/// if unbounded or if the tree has no root.
Bounds3f sdf_tree_bounds(const SdfTree& tree);

/// Object-space bounds of the shape's surface (empty for an implicit shape without bounds).
Bounds3f shape_bounds(const Shape& shape);

/// The result of one ray-shape test.
struct ShapeHit {
  float t = kInfinity;
  uint32_t evaluations = 0;  ///< SDF evaluations (sphere-tracing steps); 0 for analytic shapes
};

/// The closest surface point of `shape` along `ray` (object space; any finite non-zero
/// direction) with t in [max(ray.tnear, 0), ray.tfar]: the nearest root of the exact equation
/// for analytic shapes (rays starting inside a closed shape hit its far side), the sphere-traced
/// crossing for implicit ones. Returns true on a hit and sets hit.t. Never allocates or throws.
bool intersect_shape(const Shape& shape, const Ray& ray, ShapeHit& hit);

/// Surface data at an object-space point on the shape.
struct ShapeSurface {
  Vec3f n;              ///< unit outward normal (front side for flat shapes)
  Vec2f uv;             ///< texture coordinates; (0, 0) where the shape has none
  bool has_uv = false;  ///< sphere: (phi / 2 pi, theta / pi) with phi around +Y from +X and
                        ///< theta from +Y, v increasing downwards as glTF images do; plane and disk:
                        ///< (x, z) mapped from [-size, size] to [0, 1]; box: the hit face's two
                        ///< other axes; capsule: (phi / 2 pi, height); segment: (the nearest
                        ///< axis point's place from p0 (0) to p1 (1), 0); implicit: none
};

/// The shape's surface data at `p` (a point returned by intersect_shape). Implicit shapes take
/// the normal from the tree's analytic gradient, or where that vanishes from central
/// differences of step `h` (> 0, in object units).
ShapeSurface shape_surface(const Shape& shape, Vec3f p, float h);

/// The difference b - a of two of the shape's texture coordinates, u taken the short way round
/// on shapes whose u wraps (sphere, capsule).
Vec2f shape_uv_delta(const Shape& shape, Vec2f a, Vec2f b);

/// Moves a point found by intersect_shape onto the surface where that is exact (sphere:
/// radial projection; flat shapes: y = 0; box: its face), and returns it unchanged otherwise.
Vec3f snap_to_shape(const Shape& shape, Vec3f p);

/// The distance within which intersect_shape may place a surface point found at ray distance
/// `t` along a direction of length `dir_length` (0 for analytic shapes: their hit points carry
/// only rounding error); spawned rays start at least this far off the surface.
float shape_hit_tolerance(const Shape& shape, float t, float dir_length);

}  // namespace penumbra
