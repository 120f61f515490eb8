// Brute-force back end (linear scan over every triangle and shape).
#include "renderer/accel/brute.h"

#include <vector>

#include "renderer/accel/triangle.h"

namespace penumbra {
namespace {

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
      for (Vec3f p : m.positions) m_bounds = merge(m_bounds, p);
      m_triangles += m.indices.size() / 3;
    }
  }

  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const override {
    return closest(ray, hit, &cost);
  }
  bool counts_traversal() const override { return true; }

  bool intersect(const Ray& ray, Hit& hit) const override { return closest(ray, hit, nullptr); }

  bool occluded(const Ray& ray) const override {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    for (const auto& m : m_meshes) {
      if (m.shape) {
        ShapeHit sh;
        if (intersect_shape(*m.shape, ray, sh)) return true;
        continue;
      }
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        float t, u, v;
        if (intersect_triangle_watertight(ray, w, m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                                          m.positions[m.indices[i + 2]], ray.tfar, t, u, v))
          return true;
      }
    }
    return false;
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
  bool closest(const Ray& ray, Hit& hit, TraversalCost* cost) const {
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
        const bool found = intersect_shape(*m.shape, r, sh);
        if (cost) ++cost->shapes, cost->evaluations += sh.evaluations;
        if (found) {
          tfar = sh.t;
          hit = {sh.t, 0, 0, g, 0};
        }
        continue;
      }
      if (cost) cost->triangles += m.indices.size() / 3;
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        float t, u, v;
        if (intersect_triangle_watertight(ray, w, m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                                          m.positions[m.indices[i + 2]], tfar, t, u, v)) {
          tfar = t;
          hit = {t, u, v, g, uint32_t(i / 3)};
        }
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
