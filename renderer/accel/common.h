// Pieces shared by Penumbra's own acceleration structures (BVH, kD-tree, grid): the packed
// triangle array they all build over, the robust ray-box slab test, and the leaf loop that
// calls the one watertight triangle test (with or without a hit filter). Not used by Embree;
// nothing here knows materials.
#pragma once

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/accel/triangle.h"

namespace penumbra {

/// One primitive copied out of the geometry views, with the ids a Hit reports: a world-space
/// triangle (a, b, c), or, when prim_id has kShapeBit set, a shape whose bounds are [a, b] and
/// whose index in the structure's shape table is prim_id & ~kShapeBit (c unused).
/// 44 bytes: a, b, c (3 x 12) + geom_id (4) + prim_id (4).
struct PrimitiveRecord {
  Vec3f a, b, c;
  uint32_t geom_id = 0;  ///< index of the view in the span given to the builder
  uint32_t prim_id = 0;  ///< triangle index within that mesh, or kShapeBit | shape table index
};
static_assert(sizeof(PrimitiveRecord) == 44);

inline constexpr uint32_t kShapeBit = 0x80000000u;

inline bool is_shape(const PrimitiveRecord& r) {
  return (r.prim_id & kShapeBit) != 0;
}

/// The primitives of every view, in view order (triangles in index order; a shape is one record
/// pointing at its copy in `shapes`, which this appends to). Triangles with a non-finite vertex
/// and shapes without finite bounds are dropped (no test can hit them); degenerate triangles are
/// kept so every structure sees exactly what the brute-force oracle sees.
std::vector<PrimitiveRecord> gather_primitives(std::span<const GeometryView> views,
                                               std::vector<Shape>& shapes);

/// Triangles in `views` as given (before dropping non-finite ones): what stats() reports.
inline uint64_t count_input_triangles(std::span<const GeometryView> views) {
  uint64_t n = 0;
  for (const auto& m : views)
    if (!m.shape && m.curves == CurveKind::None) n += m.indices.size() / 3;
  return n;
}

/// Shapes in `views`, each element of a curve set counted.
inline uint64_t count_input_shapes(std::span<const GeometryView> views) {
  uint64_t n = 0;
  for (const auto& m : views) n += m.shape != nullptr ? 1 : m.curve_count();
  return n;
}

/// The prim_id a Hit reports for a record: the triangle's, or the shape's element (0 for a
/// shape of its own, the index of a curve set's point or segment).
inline uint32_t record_prim_id(const PrimitiveRecord& r, const Shape* shapes) {
  return is_shape(r) ? shapes[r.prim_id & ~kShapeBit].element : r.prim_id;
}

/// The box a builder sees for a primitive: the triangle's vertices, or the shape's bounds.
inline Bounds3f primitive_bounds(const PrimitiveRecord& t) {
  if (is_shape(t)) return {t.a, t.b};
  return merge(merge(Bounds3f{t.a, t.a}, t.b), t.c);
}

/// Surface area of a box; 0 for an empty box.
inline float surface_area(const Bounds3f& b) {
  if (b.empty()) return 0;
  const Vec3f d = b.extent();
  return 2 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

/// Width of the band around a surface within which the watertight test's rounding can still
/// report a hit near t = 0 for a ray starting there: 2^-20 of the box's largest coordinate plus
/// its size. Boxes are widened by it, and a kD-tree treats origins that close to a split plane
/// as lying on it, so no structure culls what the brute-force scan would report.
inline float rounding_band(const Bounds3f& b) {
  if (b.empty()) return 0;
  const float m = std::max(max_component(abs(b.lo)), max_component(abs(b.hi)));
  return (m + max_component(b.extent())) * 0x1p-20f;
}

inline Bounds3f widen_for_rounding(const Bounds3f& b) {
  const float band = rounding_band(b);
  const Vec3f w{band, band, band};
  return b.empty() ? b : Bounds3f{b.lo - w, b.hi + w};
}

/// Per-ray constants of the slab test.
struct RayBoxQuery {
  Vec3f org, inv_dir;
  int dir_neg[3] = {0, 0, 0};  ///< 1 where the direction component is negative
};

[[gnu::always_inline]] inline RayBoxQuery prepare_box_query(const Ray& ray) {
  RayBoxQuery q;
  q.org = ray.org;
  q.inv_dir = {1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z};  // +-inf for 0
  for (int k = 0; k < 3; ++k) q.dir_neg[k] = ray.dir[k] < 0 || (ray.dir[k] == 0 && std::signbit(ray.dir[k]));
  return q;
}

/// Relative widening of slab distances so that rounding never culls a box the ray touches:
/// 1 + 2 gamma(3) as in pbrt-v4 (Pharr, Jakob & Humphreys, 4th ed., sec. 6.8), with margin.
inline constexpr float kSlabPad = 1.0f + 4 * 3 * 0.5f * 1.1920929e-7f;

/// Slab test (Kay & Kajiya 1986) of the box [lo, hi] against the ray over [t0, t1]. On overlap
/// narrows t0/t1 to the entry and exit distances and returns true. A ray parallel to a slab
/// (direction component 0, so 1/d is infinite) overlaps it iff its origin lies within it, faces
/// included: the IEEE arithmetic alone would give NaN there (0 * inf).
inline bool intersect_box(const Vec3f& lo, const Vec3f& hi, const RayBoxQuery& q, float& t0, float& t1) {
  for (int k = 0; k < 3; ++k) {
    if (std::isinf(q.inv_dir[k])) {
      if (q.org[k] < lo[k] || q.org[k] > hi[k]) return false;
      continue;
    }
    float tn = (lo[k] - q.org[k]) * q.inv_dir[k];
    float tf = (hi[k] - q.org[k]) * q.inv_dir[k];
    if (tn > tf) std::swap(tn, tf);
    tf = tf > 0 ? tf * kSlabPad : tf * (2.0f - kSlabPad);
    tn = tn > 0 ? tn * (2.0f - kSlabPad) : tn * kSlabPad;
    t0 = tn > t0 ? tn : t0;
    t1 = tf < t1 ? tf : t1;
    if (t0 > t1) return false;
  }
  return true;
}

/// Pads a positive distance upward by the slab margin (used when a traversal compares a hit
/// distance with a cell or node exit distance).
inline float pad_up(float t) {
  return t * kSlabPad;
}

/// The filter of unfiltered queries: accepts every hit, and compiles away.
struct AcceptAll {
  bool operator()(const Ray&, const Hit&) const { return true; }
};

/// Closest-hit leaf test, dispatching on the primitive's kind to the one shared test per kind;
/// narrows `tfar` and fills `hit` on a hit that `filter` (AcceptAll or a HitFilter, offered the
/// query's ray) accepts; a rejected one leaves both alone, and a shape is tested again past it
/// (intersect_shape_accepted). `cost` (may be null) counts the tests.
template <typename Filter = AcceptAll>
inline bool intersect_leaf(const Ray& ray, const WatertightRay& w, const PrimitiveRecord& rec,
                           const Shape* shapes, float& tfar, Hit& hit, TraversalCost* cost,
                           const Filter& filter = {}) {
  if (is_shape(rec)) {
    Ray r = ray;
    r.tfar = tfar;
    ShapeHit sh;
    const Shape& shape = shapes[rec.prim_id & ~kShapeBit];
    const auto accept = [&](float t) { return filter(ray, Hit{t, 0, 0, rec.geom_id, shape.element}); };
    if (!intersect_shape_accepted(shape, r, accept, sh, cost)) return false;
    tfar = sh.t;
    hit = {sh.t, 0, 0, rec.geom_id, shape.element};
    return true;
  }
  if (cost) ++cost->triangles;
  float t, u, v;
  if (!intersect_triangle_watertight(ray, w, rec.a, rec.b, rec.c, tfar, t, u, v)) return false;
  const Hit candidate{t, u, v, rec.geom_id, rec.prim_id};
  if (!filter(ray, candidate)) return false;
  tfar = t;
  hit = candidate;
  return true;
}

/// Any-hit leaf test: whether `rec` has a hit in the ray's range that `filter` accepts.
template <typename Filter = AcceptAll>
inline bool occluded_leaf(const Ray& ray, const WatertightRay& w, const PrimitiveRecord& rec,
                          const Shape* shapes, const Filter& filter = {}) {
  float tfar = ray.tfar;
  Hit candidate;
  return intersect_leaf(ray, w, rec, shapes, tfar, candidate, nullptr, filter);
}

/// Node counters for traversals: NoCount compiles away; CountNodes adds to a TraversalCost.
/// triangles(n) counts triangle tests a traversal settles itself (the wide BVH's SIMD filter);
/// the visitors count the ones they make.
struct NoCount {
  void node() const {}
  void triangles(uint32_t) const {}
};
struct CountNodes {
  TraversalCost& cost;
  void node() const { ++cost.nodes; }
  void triangles(uint32_t n) const { cost.triangles += n; }
};

/// The leaf visitors of TraversalAccelerator: visit(w, record) tests one primitive (true ends
/// the query). kUnfiltered visitors (no HitFilter) also let a structure settle triangle tests
/// itself, as the wide BVH's block test does: counted() counts such a test, and take(hit) makes
/// a hit in the ray's range, nearer than `best` (closest) or anywhere (any), the answer.
template <typename Filter>
struct ClosestVisitor {
  static constexpr bool kUnfiltered = std::is_same_v<Filter, AcceptAll>;
  const Ray& ray;
  const Shape* shapes;
  float& best;
  Hit& hit;
  TraversalCost* cost;
  const Filter& filter;
  bool operator()(const WatertightRay& w, const PrimitiveRecord& rec) const {
    intersect_leaf(ray, w, rec, shapes, best, hit, cost, filter);
    return false;
  }
  void counted() const {
    if (cost) ++cost->triangles;
  }
  void take(const Hit& h) const {
    best = h.t;
    hit = h;
  }
};

template <typename Filter>
struct AnyVisitor {
  static constexpr bool kUnfiltered = std::is_same_v<Filter, AcceptAll>;
  const Ray& ray;
  const Shape* shapes;
  const Filter& filter;
  bool operator()(const WatertightRay& w, const PrimitiveRecord& rec) const {
    return occluded_leaf(ray, w, rec, shapes, filter);
  }
  void counted() const {}
  void take(const Hit&) const {}
};

/// intersect(), intersect_counted() and occluded() of the reference structures, written once
/// over the structure's primitive records and its table of shapes (m_shapes, filled by
/// gather_primitives):
/// each structure provides
///   template <class Visit, class Counter, bool AnyHit>
///   bool traverse(const Ray&, const float& best, Visit&&, const Counter&,
///                 std::bool_constant<AnyHit>) const,
/// which walks the cells or leaves the ray may meet (skipping those beyond `best`), calls
/// counter.node() per node or cell visited, and calls visit(w, record) on their primitives until it
/// returns true (CRTP, so the visitors inline). AnyHit is true for occlusion queries, where any
/// hit ends the query and visiting order does not matter. The filtered queries apply the
/// HitFilter in the same visitors, so a rejected candidate never narrows `best`.
template <typename Derived>
class TraversalAccelerator : public Accelerator {
 public:
  bool intersect(const Ray& ray, Hit& hit) const final {
    return closest(ray, hit, NoCount{}, nullptr, AcceptAll{});
  }

  bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const final {
    return closest(ray, hit, NoCount{}, nullptr, filter);
  }

  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const final {
    return closest(ray, hit, CountNodes{cost}, &cost, AcceptAll{});
  }
  bool counts_traversal() const final { return true; }

  bool occluded(const Ray& ray) const final { return any(ray, AcceptAll{}); }
  bool occluded(const Ray& ray, const HitFilter& filter) const final { return any(ray, filter); }

 protected:
  std::vector<Shape> m_shapes;  ///< the shapes the records point at (gather_primitives fills it)

 private:
  template <typename Filter>
  bool any(const Ray& ray, const Filter& filter) const {
    return static_cast<const Derived*>(this)->traverse(
        ray, ray.tfar, AnyVisitor<Filter>{ray, m_shapes.data(), filter}, NoCount{}, std::true_type{});
  }

  template <typename Counter, typename Filter>
  bool closest(const Ray& ray, Hit& hit, const Counter& counter, TraversalCost* cost,
               const Filter& filter) const {
    hit = Hit{};
    float best = ray.tfar;
    static_cast<const Derived*>(this)->traverse(
        ray, best, ClosestVisitor<Filter>{ray, m_shapes.data(), best, hit, cost, filter}, counter,
        std::false_type{});
    return hit.valid();
  }
};

}  // namespace penumbra
