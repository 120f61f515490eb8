// Spatial queries other than rays, answered by every acceleration structure through
// Accelerator::visit_region and measured exactly on the geometry the structure was built over:
// the k primitives nearest to a point, every primitive within a distance of a point, every
// primitive meeting a box. Results are ordered by (distance, geom_id, prim_id), so every
// structure gives the same answer, bit for bit.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "renderer/accel/accelerator.h"

namespace penumbra {

/// The geometry a structure was built over: the views given to the builder and, for a build over
/// instances, the instances (empty for a single-level build). Ids in results are a Hit's.
struct QueryScene {
  std::span<const GeometryView> meshes;
  std::span<const InstanceView> instances;
};

/// One primitive a query found, measured from the query point (overlap: from the box's centre).
struct PrimitiveMatch {
  float distance = kInfinity;  ///< world distance from the query point to `point`
  Vec3f point;                 ///< the primitive's surface point nearest to the query point (world)
  float u = 0, v = 0;          ///< triangles: point = (1 - u - v) a + u b + v c; shapes: 0
  uint32_t geom_id = 0, prim_id = 0;
};

/// Most neighbours a nearest() query may ask for.
inline constexpr int kMaxNearest = 1 << 16;

/// The nearest point of triangle abc to p and its barycentrics (u, v) of b and c (Ericson,
/// "Real-Time Collision Detection", 2005, sec. 5.1.5, in double); a degenerate triangle's
/// nearest point on its edges. Never allocates or throws.
Vec3f closest_point_on_triangle(Vec3f p, Vec3f a, Vec3f b, Vec3f c, float& u, float& v);

/// The nearest point of primitive (geom_id, prim_id) of `scene` to the world point p, in world
/// space. Triangles are placed by their instance's map and measured exactly; a placed shape's
/// nearest point is found in its object space and mapped (exact when the map is a similarity:
/// rotation, uniform scale, translation; otherwise a surface point near the nearest). Returns
/// false for a primitive that does not exist or has a non-finite vertex.
bool measure_primitive(const QueryScene& scene, uint32_t geom_id, uint32_t prim_id, Vec3f p,
                       PrimitiveMatch& m);

/// True if primitive (geom_id, prim_id) meets the closed world box (triangles: the separating-
/// axis test in double; shapes: the part of the box inside the shape's world bounds, subdivided
/// down to 1/64 of its size, where a piece whose nearest surface point lies in it meets it, and
/// the last level counts a piece within its half-diagonal of the surface as meeting).
bool primitive_meets_box(const QueryScene& scene, uint32_t geom_id, uint32_t prim_id, const Bounds3f& box);

/// The at most k primitives nearest to p within max_distance (inclusive), nearest first, ties
/// by ids, written to out[0, n) (out.size() >= k); returns n. p finite, 1 <= k <= kMaxNearest,
/// max_distance >= 0 (may be +inf). Never allocates, throws or logs: callable in parallel.
size_t nearest(const Accelerator& accel, const QueryScene& scene, Vec3f p, int k, float max_distance,
               std::span<PrimitiveMatch> out, TraversalCost* cost = nullptr);

/// Every primitive at distance <= radius from p, nearest first, ties by ids, into `out`
/// (replaced). radius >= 0 and finite.
void within(const Accelerator& accel, const QueryScene& scene, Vec3f p, float radius,
            std::vector<PrimitiveMatch>& out, TraversalCost* cost = nullptr);

/// Every primitive meeting the closed box (finite, non-empty), ordered by ids, measured from
/// the box's centre, into `out` (replaced).
void overlap(const Accelerator& accel, const QueryScene& scene, const Bounds3f& box,
             std::vector<PrimitiveMatch>& out, TraversalCost* cost = nullptr);

/// nearest() for every point of `points` on `threads` workers (0: all cores): out gets k
/// entries per point (point i's at [i k, i k + counts[i])), counts one per point. The same
/// output for any thread count.
void nearest_batch(const Accelerator& accel, const QueryScene& scene, std::span<const Vec3f> points, int k,
                   float max_distance, int threads, std::vector<PrimitiveMatch>& out,
                   std::vector<uint32_t>& counts);

/// within() for every point of `points` on `threads` workers (0: all cores): point i's matches
/// are out[offsets[i], offsets[i + 1]) (offsets has points.size() + 1 entries). Returns false,
/// with out and offsets empty, when the points meet more than `max_matches` primitives in all.
/// The same output for any thread count.
bool within_batch(const Accelerator& accel, const QueryScene& scene, std::span<const Vec3f> points,
                  float radius, int threads, size_t max_matches, std::vector<PrimitiveMatch>& out,
                  std::vector<size_t>& offsets);

/// The closest hit of every ray (hits[i], geom_id == Hit::kInvalidId on a miss; hits.size() >=
/// rays.size()) on `threads` workers (0: all cores). The same output for any thread count.
void intersect_batch(const Accelerator& accel, std::span<const Ray> rays, std::span<Hit> hits, int threads);

}  // namespace penumbra
