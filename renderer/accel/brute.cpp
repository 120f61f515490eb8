// Brute-force back end (linear scan over every triangle and shape).
#include "renderer/accel/brute.h"

#include <vector>

#include "renderer/accel/triangle.h"

namespace penumbra {
namespace {

// The elements of a curve set view that have radii (none without).
size_t curve_elements(const GeometryView& m) {
  return m.radii.size() < m.positions.size() ? 0 : m.curve_count();
}

class BruteAccelerator final : public Accelerator {
 public:
  explicit BruteAccelerator(std::span<const GeometryView> meshes) : m_meshes(meshes.begin(), meshes.end()) {
    for (const auto& m : m_meshes) {
      if (m.shape) {
        const Bounds3f b = shape_bounds(*m.shape);
        if (!b.empty() && is_finite(b.lo) && is_finite(b.hi)) m_bounds = merge(m_bounds, b);
        ++m_shapes;
        continue;
      }
      if (m.curves != CurveKind::None) {
        m_shapes += m.curve_count();
        for (size_t i = 0; i < curve_elements(m); ++i) {
          const Bounds3f b = shape_bounds(curve_element(m, i));
          if (!b.empty() && is_finite(b.lo) && is_finite(b.hi)) m_bounds = merge(m_bounds, b);
        }
        continue;
      }
      for (Vec3f p : m.positions) m_bounds = merge(m_bounds, p);
      m_triangles += m.indices.size() / 3;
    }
  }

  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const override {
    return scan(ray, hit, &cost, nullptr, false);
  }
  bool counts_traversal() const override { return true; }

  bool intersect(const Ray& ray, Hit& hit) const override { return scan(ray, hit, nullptr, nullptr, false); }
  bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const override {
    return scan(ray, hit, nullptr, &filter, false);
  }

  bool occluded(const Ray& ray) const override {
    Hit hit;
    return scan(ray, hit, nullptr, nullptr, true);
  }
  bool occluded(const Ray& ray, const HitFilter& filter) const override {
    Hit hit;
    return scan(ray, hit, nullptr, &filter, true);
  }

  /// Every primitive whose bounds meet the region (read again before each, as the visitor may
  /// shrink a ball), in view and triangle order; the scan counts as one node.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (cost) ++cost->nodes;
    for (uint32_t g = 0; g < m_meshes.size(); ++g) {
      const auto& m = m_meshes[g];
      if (m.shape) {
        if (region_meets(region, shape_bounds(*m.shape))) visitor.visit(g, 0, region);
        continue;
      }
      if (m.curves != CurveKind::None) {
        for (size_t i = 0; i < curve_elements(m); ++i) {
          const Bounds3f b = shape_bounds(curve_element(m, i));
          if (is_finite(b.lo) && is_finite(b.hi) && region_meets(region, b))
            visitor.visit(g, uint32_t(i), region);
        }
        continue;
      }
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        const Bounds3f b = merge(merge(Bounds3f{m.positions[m.indices[i]], m.positions[m.indices[i]]},
                                       m.positions[m.indices[i + 1]]),
                                 m.positions[m.indices[i + 2]]);
        if (region_meets(region, b)) visitor.visit(g, uint32_t(i / 3), region);
      }
    }
  }

  Bounds3f bounds() const override { return m_bounds; }
  AccelStats stats() const override {
    AccelStats s;
    s.name = "brute";
    s.triangles = m_triangles;
    s.shapes = m_shapes;
    s.leaves = 1;
    s.nodes = 1;
    s.references = m_triangles + m_shapes;
    s.max_leaf_prims = s.references;
    s.avg_leaf_prims = double(s.references);
    s.empty_leaves = s.references == 0;
    return s;
  }

 private:
  /// Every triangle and shape in turn: the closest hit `filter` (null: every hit) accepts, or
  /// with `any_hit` the first one found.
  bool scan(const Ray& ray, Hit& hit, TraversalCost* cost, const HitFilter* filter, bool any_hit) const {
    hit = Hit{};
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    float tfar = ray.tfar;
    for (uint32_t g = 0; g < m_meshes.size(); ++g) {
      const auto& m = m_meshes[g];
      if (m.shape) {
        Ray r = ray;
        r.tfar = tfar;
        ShapeHit sh;
        const auto accept = [&](float t) { return !filter || (*filter)(ray, Hit{t, 0, 0, g, 0}); };
        if (intersect_shape_accepted(*m.shape, r, accept, sh, cost)) {
          tfar = sh.t;
          hit = {sh.t, 0, 0, g, 0};
          if (any_hit) return true;
        }
        continue;
      }
      if (m.curves != CurveKind::None) {
        for (size_t i = 0; i < curve_elements(m); ++i) {
          const Shape s = curve_element(m, i);
          const Bounds3f b = shape_bounds(s);
          if (b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) continue;
          Ray r = ray;
          r.tfar = tfar;
          ShapeHit sh;
          const auto accept = [&](float t) { return !filter || (*filter)(ray, Hit{t, 0, 0, g, s.element}); };
          if (intersect_shape_accepted(s, r, accept, sh, cost)) {
            tfar = sh.t;
            hit = {sh.t, 0, 0, g, s.element};
            if (any_hit) return true;
          }
        }
        continue;
      }
      if (cost) cost->triangles += m.indices.size() / 3;
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        float t, u, v;
        if (!intersect_triangle_watertight(ray, w, m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                                           m.positions[m.indices[i + 2]], tfar, t, u, v))
          continue;
        const Hit candidate{t, u, v, g, uint32_t(i / 3)};
        if (filter && !(*filter)(ray, candidate)) continue;
        tfar = t;
        hit = candidate;
        if (any_hit) return true;
      }
    }
    return hit.valid();
  }

  std::vector<GeometryView> m_meshes;
  Bounds3f m_bounds;
  uint64_t m_triangles = 0;
  uint64_t m_shapes = 0;
};

}  // namespace

std::unique_ptr<Accelerator> make_brute_accelerator(std::span<const GeometryView> meshes) {
  return std::make_unique<BruteAccelerator>(meshes);
}

}  // namespace penumbra
