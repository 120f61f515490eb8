// Brute-force back end (linear scan).
#include "renderer/accel/brute.h"

#include <vector>

#include "renderer/accel/triangle.h"

namespace penumbra {
namespace {

class BruteAccelerator final : public Accelerator {
 public:
  explicit BruteAccelerator(std::span<const TriangleMeshView> meshes)
      : m_meshes(meshes.begin(), meshes.end()) {
    for (const auto& m : m_meshes) {
      for (Vec3f p : m.positions) m_bounds = merge(m_bounds, p);
      m_triangles += m.indices.size() / 3;
    }
  }

  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const override {
    if (prepare_watertight(ray).valid) cost.triangles += m_triangles;
    return intersect(ray, hit);
  }
  bool counts_traversal() const override { return true; }

  bool intersect(const Ray& ray, Hit& hit) const override {
    hit = Hit{};
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    float tfar = ray.tfar;
    for (uint32_t g = 0; g < m_meshes.size(); ++g) {
      const auto& m = m_meshes[g];
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

  bool occluded(const Ray& ray) const override {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    for (const auto& m : m_meshes)
      for (size_t i = 0; i + 2 < m.indices.size(); i += 3) {
        float t, u, v;
        if (intersect_triangle_watertight(ray, w, m.positions[m.indices[i]], m.positions[m.indices[i + 1]],
                                          m.positions[m.indices[i + 2]], ray.tfar, t, u, v))
          return true;
      }
    return false;
  }

  Bounds3f bounds() const override { return m_bounds; }
  AccelStats stats() const override {
    AccelStats s;
    s.name = "brute";
    s.triangles = m_triangles;
    s.leaves = 1;
    s.nodes = 1;
    s.references = m_triangles;
    s.max_leaf_prims = m_triangles;
    s.avg_leaf_prims = double(m_triangles);
    s.empty_leaves = m_triangles == 0;
    return s;
  }

 private:
  std::vector<TriangleMeshView> m_meshes;
  Bounds3f m_bounds;
  uint64_t m_triangles = 0;
};

}  // namespace

std::unique_ptr<Accelerator> make_brute_accelerator(std::span<const TriangleMeshView> meshes) {
  return std::make_unique<BruteAccelerator>(meshes);
}

}  // namespace penumbra
