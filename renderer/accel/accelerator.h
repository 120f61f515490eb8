// The one ray-query interface of Penumbra. Every back end (Embree, BVH, kD-tree, grid, brute
// force) builds from geometry views (triangle meshes and shapes: analytic primitives and implicit
// surfaces) and answers closest-hit and occlusion queries with the same Hit record, optionally
// through an any-hit filter evaluated inside traversal. Accelerators know nothing of materials or
// film (a filter's context is the caller's). Back ends are chosen by name through accel/factory.h.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "renderer/core/geometry.h"
#include "renderer/core/motion.h"
#include "renderer/shapes/shape.h"

namespace penumbra {

/// What the triangles of a curve set view stand for (GeometryView::curves).
enum class CurveKind : uint8_t {
  None,      ///< triangles
  Points,    ///< each triangle (i, i, i) is a sphere of radius radii[i] about positions[i]
  Segments,  ///< each triangle (a, b, b) is a capsule of radius (radii[a] + radii[b]) / 2 about
             ///< the segment positions[a]-positions[b] (round linear curve with constant radius)
  Shapes,    ///< no triangles: element i is the shape elements[i] (a splat cloud's splats)
};

/// A read-only view of one geometry: a triangle mesh, a curve set (`curves` not None: its
/// degenerate triangles are points or line segments with radii), or (when `shape` is set) one
/// shape, which is a single primitive. geom_id in a Hit is the index of the view in the span
/// given to the builder; prim_id is the triangle index within a mesh or a curve set and 0 for a
/// shape (Hit u, v are 0 for both curve elements and shapes). Builders copy the shape and the
/// curve elements (as Segment shapes); the mesh arrays are copied by every back end but brute
/// force.
struct GeometryView {
  std::span<const Vec3f> positions;
  std::span<const uint32_t> indices;   ///< 3 per triangle, each < positions.size()
  const Shape* shape = nullptr;        ///< a shape instead of triangles (positions, indices unused)
  CurveKind curves = CurveKind::None;  ///< the triangles stand for points or segments
  std::span<const float> radii;        ///< curves: one radius (>= 0) per position
  std::span<const Shape> elements;     ///< CurveKind::Shapes: the elements (prim_id = index)
  /// Deformation motion blur: `motion_steps` >= 2 copies of the positions (step after step,
  /// motion_steps x positions.size() entries) spread evenly over Ray::time 0 to 1, each vertex
  /// linearly interpolated between the two steps around a ray's time (interpolate_vertex). 0 (and
  /// no motion_positions): the mesh stays as `positions` has it, which is then only its frame-time
  /// pose for the data that has no ray time.
  std::span<const Vec3f> motion_positions;
  uint32_t motion_steps = 0;

  bool deforms() const { return motion_steps >= 2 && !shape && curves == CurveKind::None; }
  /// Curve elements (points or segments) of a curve set view; 0 otherwise.
  size_t curve_count() const {
    if (curves == CurveKind::None || shape) return 0;
    return curves == CurveKind::Shapes ? elements.size() : indices.size() / 3;
  }
};

/// One placement of a geometry: the mesh's triangles (or the shape) mapped by `to_world` (object
/// to world space).
/// Builders given instances report the instance's index as a Hit's geom_id. Instances with the
/// identity map are built in world space directly; the others share one object-space structure
/// per mesh under a top level over their world bounds (two-level instancing). An instance whose
/// map is singular or not finite is never hit.
struct InstanceView {
  uint32_t mesh = 0;  ///< index into the geometry span given to the builder
  Affine3f to_world;
  /// Motion blur: the map's keys over the shutter (interpolate_motion at Ray::time), used
  /// instead of to_world; empty for an instance that does not move. A moving instance is always
  /// placed under the top level, its box bounding every time (motion_bounds).
  std::span<const MotionKey> motion;
};

/// How a build over instances treats one: in world space (the identity map), never hit (a
/// singular or non-finite map), or placed under the top level (Accelerator::update_instances
/// keeps each instance's kind).
enum class InstanceKind : uint8_t { Identity, Singular, Placed };

inline InstanceKind instance_kind(const InstanceView& inst) {
  Affine3f to_object;
  if (!inst.motion.empty()) {
    for (const MotionKey& k : inst.motion)
      if (!inverse(compose_motion(k), to_object)) return InstanceKind::Singular;
    return InstanceKind::Placed;
  }
  if (is_identity(inst.to_world)) return InstanceKind::Identity;
  return inverse(inst.to_world, to_object) ? InstanceKind::Placed : InstanceKind::Singular;
}

/// The mesh and kind of every instance of a build, which Accelerator::update_instances keeps.
struct InstanceLayout {
  std::vector<uint32_t> meshes;
  std::vector<InstanceKind> kinds;

  void add(const InstanceView& inst) {
    meshes.push_back(inst.mesh);
    kinds.push_back(instance_kind(inst));
  }
  /// True if `instances` has this layout's count, and each instance its mesh and kind.
  bool matches(std::span<const InstanceView> instances) const {
    if (instances.size() != kinds.size()) return false;
    for (size_t i = 0; i < instances.size(); ++i)
      if (instances[i].mesh != meshes[i] || instance_kind(instances[i]) != kinds[i]) return false;
    return true;
  }
};

/// Build and size statistics of an accelerator. Fields a back end cannot report are 0 (Embree
/// does not expose its node counts). For the grid, "nodes" and "leaves" are cells.
struct AccelStats {
  std::string name;
  std::string config;           ///< the build parameters, human readable
  uint64_t triangles = 0;       ///< triangles given to the builder (each stored mesh once)
  uint64_t shapes = 0;          ///< shapes given to the builder (each stored shape once)
  uint64_t instances = 0;       ///< placements under a top level (0: single level)
  uint64_t nodes = 0;           ///< all nodes (interior + leaves), or grid cells
  uint64_t leaves = 0;          ///< leaves, or grid cells
  uint64_t empty_leaves = 0;    ///< leaves or cells with no triangle
  uint64_t references = 0;      ///< triangle references summed over leaves/cells
  uint64_t max_leaf_prims = 0;  ///< largest leaf or cell
  double avg_leaf_prims = 0;    ///< references / non-empty leaves
  uint64_t max_depth = 0;       ///< deepest leaf (root = depth 0)
  double sah_cost = 0;          ///< SAH cost of the tree with the builder's constants (0: n/a);
                                ///< two levels: top nodes at 1 plus each instance's bottom cost
                                ///< weighted by the area of its world box
  double sah_node_area = 0;     ///< the SAH without constants (BVH, kD-tree; 0 with sah_leaf_area:
                                ///< n/a): sum over interior nodes of area / root area
  double sah_leaf_area = 0;     ///< sum over leaves of area / root area x references (not blocks)
  uint64_t bytes = 0;           ///< memory held by the structure
  double build_seconds = 0;
};

/// Work done by queries: nodes (or grid cells) visited, triangles and shapes tested, and SDF
/// evaluations of sphere tracing. Summed by intersect_counted(); the cost heat map (penumbra
/// render --aov cost) shows it per pixel.
struct TraversalCost {
  uint64_t nodes = 0;        ///< interior and leaf nodes (BVH, kD-tree) or cells (grid) visited
  uint64_t triangles = 0;    ///< ray-triangle tests
  uint64_t shapes = 0;       ///< ray-shape tests (analytic or implicit)
  uint64_t evaluations = 0;  ///< SDF evaluations made by the implicit shapes' tests
};

/// The rays every back end answers: finite origin and direction, a non-zero direction and a
/// non-empty [tnear, tfar] without NaN. Others miss (the interface's contract below).
inline bool is_valid_query(const Ray& r) {
  return is_finite(r.org) && is_finite(r.dir) && !std::isnan(r.tnear) && !std::isnan(r.tfar) &&
         r.tnear <= r.tfar && dot(r.dir, r.dir) > 0;
}

/// An any-hit filter evaluated inside traversal. accept(context, ray, hit) is called with each
/// candidate hit whose t lies in the query's range, the hit as intersect() would report it
/// (geom_id the view's or, over instances, the instance's index) and `ray` the query's ray. A
/// rejected candidate does not narrow the search. The same hit may be offered more than once
/// (structures with duplicated references: kD-tree, grid, spatial splits in the BVH and Embree), so the
/// answer must depend on (ray, hit) alone. `accept` is non-null, thread-safe, and never
/// allocates, throws or logs; `context` is passed through untouched (it stays the caller's).
struct HitFilter {
  bool (*accept)(const void* context, const Ray& ray, const Hit& hit) = nullptr;
  const void* context = nullptr;

  bool operator()(const Ray& ray, const Hit& hit) const { return accept(context, ray, hit); }
};

/// The region of a spatial query other than a ray: a closed ball (centre, squared radius) or a
/// closed axis-aligned box. A ball's radius may shrink while the query runs (a nearest-neighbour
/// search narrows it to the k-th distance found so far).
struct QueryRegion {
  bool is_box = false;
  Vec3f centre;               ///< ball
  float radius2 = kInfinity;  ///< ball: squared radius, >= 0 (may be +inf)
  Bounds3f box;               ///< box: non-empty, finite
};

/// Squared distance from `p` to the closed box `b` (0 inside; +inf for an empty box).
inline float distance2(Vec3f p, const Bounds3f& b) {
  if (b.empty()) return kInfinity;
  float d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const float d = p[k] < b.lo[k] ? b.lo[k] - p[k] : (p[k] > b.hi[k] ? p[k] - b.hi[k] : 0.0f);
    d2 += d * d;
  }
  return d2;
}

/// Rounding allowance of node pruning: a node is skipped only when its squared distance exceeds
/// the ball's by more than this relative margin, so that rounding in distance2 never skips a
/// primitive the exact test (which rounds too) would place inside.
inline constexpr float kRegionPad = 1.0f + 1e-5f;

/// True if the closed box `b` may hold a point of the region (a ball: distance2 within the
/// padded squared radius; a box: the boxes overlap, faces included).
inline bool region_meets(const QueryRegion& r, const Bounds3f& b) {
  if (b.empty()) return false;
  if (!r.is_box) return distance2(r.centre, b) <= r.radius2 * kRegionPad;
  return r.box.lo.x <= b.hi.x && b.lo.x <= r.box.hi.x && r.box.lo.y <= b.hi.y && b.lo.y <= r.box.hi.y &&
         r.box.lo.z <= b.hi.z && b.lo.z <= r.box.hi.z;
}

/// Receives the primitives a region query reaches (Accelerator::visit_region).
class RegionVisitor {
 public:
  virtual ~RegionVisitor() = default;
  /// Called with a primitive (its ids as a Hit reports them: geom_id the view's or, over
  /// instances, the instance's index; prim_id the triangle, 0 for a shape) stored in a leaf or
  /// cell that meets `region`. May shrink region.radius2 (never grow it). May be called more
  /// than once for one primitive. Never throws.
  virtual void visit(uint32_t geom_id, uint32_t prim_id, QueryRegion& region) = 0;
};

/// Element `i` of a curve set view as the shape every back end tests: a Segment (a sphere for a
/// point; its radius is not finite or negative, and it is never hit, when the radii say so), or
/// the view's own element for CurveKind::Shapes.
inline Shape curve_element(const GeometryView& v, size_t i) {
  if (v.curves == CurveKind::Shapes) {
    Shape s = v.elements[i];
    s.element = uint32_t(i);
    return s;
  }
  const uint32_t a = v.indices[3 * i], b = v.indices[3 * i + 1];
  const float r = v.curves == CurveKind::Points ? v.radii[a] : 0.5f * (v.radii[a] + v.radii[b]);
  return make_segment_shape(v.positions[a], v.curves == CurveKind::Points ? v.positions[a] : v.positions[b],
                            r, uint32_t(i));
}

/// Most hits of one shape a filtered query tests along a ray before giving up on it.
inline constexpr int kMaxShapeCrossings = 1024;

/// The nearest hit of `shape` along `ray` (the shape's space, t in the ray's range) for which
/// accept(t) is true: a shape, unlike a triangle, may meet a ray more than once, so the test is
/// repeated just past each rejected hit (at most kMaxShapeCrossings times, then no hit). Each
/// test adds to `cost` when non-null. What every back end's filtered queries do for a shape.
template <typename Accept>
bool intersect_shape_accepted(const Shape& shape, const Ray& ray, Accept&& accept, ShapeHit& hit,
                              TraversalCost* cost) {
  Ray r = ray;
  for (int i = 0; i < kMaxShapeCrossings; ++i) {
    ShapeHit sh;
    const bool found = intersect_shape(shape, r, sh);
    if (cost) ++cost->shapes, cost->evaluations += sh.evaluations;
    if (!found) return false;
    if (accept(sh.t)) {
      hit = sh;
      return true;
    }
    r.tnear = std::nextafter(std::max(sh.t, r.tnear), kInfinity);
  }
  return false;
}

class Accelerator {
 public:
  virtual ~Accelerator() = default;
  /// Closest hit with t in [max(ray.tnear, 0), ray.tfar]. Returns hit.valid(). Rays with a
  /// NaN/Inf origin or direction, a zero direction or tnear > tfar miss.
  /// Thread-safe; never allocates, throws or logs.
  virtual bool intersect(const Ray& ray, Hit& hit) const = 0;
  /// True iff some triangle or shape is hit with t in [max(ray.tnear, 0), ray.tfar]. Thread-safe.
  virtual bool occluded(const Ray& ray) const = 0;
  /// The closest hit in intersect()'s range that `filter` accepts (rejected ones are skipped):
  /// what re-shooting intersect() just past each rejected hit until one is accepted gives.
  /// Returns hit.valid(); hit is reset on a miss. Thread-safe; never allocates, throws or logs.
  virtual bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const = 0;
  /// True iff some hit in occluded()'s range is accepted by `filter`. Thread-safe.
  virtual bool occluded(const Ray& ray, const HitFilter& filter) const = 0;
  /// intersect(), also adding the work it did to `cost`. Back ends that cannot count (Embree
  /// keeps no statistics in release builds) answer without counting: see counts_traversal().
  virtual bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const {
    (void)cost;
    return intersect(ray, hit);
  }
  /// True iff intersect_counted() fills in TraversalCost.
  virtual bool counts_traversal() const { return false; }
  /// Spatial queries other than rays: offers `visitor` every primitive of every leaf or cell
  /// whose bounds meet `region` (region_meets), skipping subtrees and cells that do not. For a
  /// ball, nearer nodes are visited first where the structure orders them, and radius2 is read
  /// again before each node, so a visitor that shrinks it prunes what follows. Every primitive
  /// with a point in the region is offered at least once; others may be. Deforming
  /// meshes and moving instances are reached through their bounds over the shutter. Adds nodes
  /// (cells) visited to `cost` when non-null. Thread-safe; never allocates, throws or logs.
  virtual void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const = 0;
  virtual Bounds3f bounds() const = 0;
  virtual AccelStats stats() const = 0;
  /// Moves the instances of a build over instances to new maps and rebuilds only the top level
  /// (the per-mesh structures are kept): `instances` has the build's count and meshes in the
  /// same order, and every instance keeps its kind (the identity, singular, or placed by an
  /// invertible map), so the answers equal a fresh build over `instances`. Returns false, with
  /// the accelerator unchanged, when it cannot: another count, mesh or kind, or a back end
  /// built in one level (the default); the caller then builds anew. The geometry views given
  /// to the build must still be valid. Not thread-safe: no query may run during the call.
  /// Throws std::runtime_error if the back end's rebuild fails.
  virtual bool update_instances(std::span<const InstanceView> instances) {
    (void)instances;
    return false;
  }
  /// Refitting for animation: moves a single-level build to `views`, the same views with new
  /// vertex positions (and shapes with new parameters), keeping the tree and recomputing its
  /// boxes bottom-up (stats() then reports the refitted tree's SAH cost). `views` must have
  /// the build's count, and each view its kind and triangle count; no triangle may have a
  /// non-finite vertex then or at the build. Answers equal those of any correct structure
  /// over `views` (a refitted tree only traverses more). Returns false, with the accelerator
  /// unchanged, when it cannot (another layout, or a back end that does not refit: the
  /// default); the caller then builds anew. Not thread-safe: no query may run during the call.
  virtual bool refit(std::span<const GeometryView> views) {
    (void)views;
    return false;
  }
  /// refit() for a build over instances: every mesh's structure refitted to `meshes` and the
  /// instances moved to `instances` (as update_instances() does). Returns false under the
  /// conditions of both; the structure may then be partly refitted and must be discarded (built
  /// anew).
  virtual bool refit_instances(std::span<const GeometryView> meshes,
                               std::span<const InstanceView> instances) {
    (void)meshes;
    (void)instances;
    return false;
  }
};

}  // namespace penumbra
