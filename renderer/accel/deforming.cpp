// The deforming-mesh structure: a binary BVH with a box per node and time segment.
#include "renderer/accel/deforming.h"

#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/bvh_build.h"
#include "renderer/accel/bvh_wide.h"
#include "renderer/accel/stats.h"
#include "renderer/accel/triangle.h"

namespace penumbra {
namespace {

class DeformingAccelerator final : public Accelerator {
 public:
  DeformingAccelerator(std::span<const GeometryView> meshes, const DeformingConfig& config)
      : m_steps(meshes.empty() ? 2 : meshes[0].motion_steps), m_exhaustive(config.exhaustive) {
    if (config.max_leaf_size < 1 || config.max_leaf_size > 255)
      throw std::invalid_argument("deforming structure: max_leaf_size must be in [1, 255]");
    for (size_t g = 0; g < meshes.size(); ++g) {
      const GeometryView& mesh = meshes[g];
      const std::string which = "deforming structure: mesh " + std::to_string(g);
      if (!mesh.deforms()) throw std::invalid_argument(which + " has no motion steps");
      if (mesh.motion_steps != m_steps)
        throw std::invalid_argument(which + " has " + std::to_string(mesh.motion_steps) +
                                    " motion steps, not " + std::to_string(m_steps));
      if (mesh.motion_positions.size() != mesh.positions.size() * m_steps)
        throw std::invalid_argument(which + ": " + std::to_string(mesh.motion_positions.size()) +
                                    " motion positions for " + std::to_string(m_steps) + " steps of " +
                                    std::to_string(mesh.positions.size()) + " vertices");
      for (const uint32_t i : mesh.indices)
        if (i >= mesh.positions.size())
          throw std::invalid_argument(which + ": index " + std::to_string(i) + " out of range");
      m_count += mesh.positions.size();
    }
    // Every mesh's vertices at step k, one after the other: step k of the whole set.
    m_keys.reserve(m_count * m_steps);
    for (uint32_t k = 0; k < m_steps; ++k)
      for (const GeometryView& mesh : meshes) {
        const auto step = mesh.motion_positions.subspan(k * mesh.positions.size(), mesh.positions.size());
        m_keys.insert(m_keys.end(), step.begin(), step.end());
      }
    size_t base = 0;
    for (uint32_t g = 0; g < meshes.size(); ++g) {
      const GeometryView& mesh = meshes[g];
      for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        for (size_t j = 0; j < 3; ++j) m_indices.push_back(uint32_t(base + mesh.indices[t + j]));
        m_ids.push_back({g, uint32_t(t / 3)});
      }
      base += mesh.positions.size();
    }
    const BuildTimer timer;
    build(config);
    m_build_seconds = timer.seconds();
  }

  bool intersect(const Ray& ray, Hit& hit) const override { return closest(ray, hit, nullptr, nullptr); }
  bool intersect(const Ray& ray, Hit& hit, const HitFilter& filter) const override {
    return closest(ray, hit, nullptr, &filter);
  }
  bool intersect_counted(const Ray& ray, Hit& hit, TraversalCost& cost) const override {
    return closest(ray, hit, &cost, nullptr);
  }
  bool counts_traversal() const override { return true; }
  bool occluded(const Ray& ray) const override {
    Hit hit;
    return query(ray, hit, nullptr, nullptr, true);
  }
  bool occluded(const Ray& ray, const HitFilter& filter) const override {
    Hit hit;
    return query(ray, hit, nullptr, &filter, true);
  }
  /// Region queries test each node's box over all time (its linear bounds merged), so a
  /// triangle is reached wherever it is during the shutter.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    const auto leaf = [&](uint32_t first, uint32_t count) {
      for (uint32_t k = first; k < first + count; ++k) {
        const TriangleId& id = m_ids[m_prims[k]];
        visitor.visit(id.geom, id.prim, region);
      }
    };
    if (!m_exhaustive) return walk_region_binary(m_nodes, region, cost, leaf);
    if (cost) ++cost->nodes;
    if (region_meets(region, widen_for_rounding(m_bounds))) leaf(0, uint32_t(m_prims.size()));
  }
  Bounds3f bounds() const override { return m_bounds; }

  AccelStats stats() const override {
    AccelStats s;
    s.name = m_exhaustive ? "brute" : "bvh";
    s.config = "deforming, " + std::to_string(m_steps) + " steps";
    s.triangles = m_indices.size() / 3;
    s.references = m_prims.size();
    s.nodes = m_exhaustive ? 1 : m_nodes.size();
    s.leaves = m_exhaustive ? 1 : 0;
    for (const BvhNode& n : m_nodes)
      if (n.count > 0) ++s.leaves, s.max_leaf_prims = std::max<uint64_t>(s.max_leaf_prims, n.count);
    if (m_exhaustive) s.max_leaf_prims = m_prims.size();
    s.avg_leaf_prims = s.leaves ? double(s.references) / double(s.leaves) : 0;
    s.max_depth = m_depth;
    s.bytes = m_indices.size() * sizeof(uint32_t) + m_ids.size() * sizeof(TriangleId) +
              m_keys.size() * sizeof(Vec3f) + m_prims.size() * sizeof(uint32_t) +
              m_nodes.size() * sizeof(BvhNode) + m_lbounds.size() * sizeof(Bounds3f);
    s.build_seconds = m_build_seconds;
    return s;
  }

 private:
  /// Triangle `tri`'s vertices at step `k`.
  void vertices_at_step(uint32_t tri, uint32_t k, Vec3f p[3]) const {
    for (int j = 0; j < 3; ++j) p[j] = m_keys[size_t(k) * m_count + m_indices[3 * size_t(tri) + size_t(j)]];
  }

  /// The triangle's box over steps [k0, k1]; empty if a vertex is not finite at any of them.
  Bounds3f steps_box(uint32_t tri, uint32_t k0, uint32_t k1) const {
    Bounds3f b;
    for (uint32_t k = k0; k <= k1; ++k) {
      Vec3f p[3];
      vertices_at_step(tri, k, p);
      for (const Vec3f& q : p) {
        if (!is_finite(q)) return {};
        b = merge(b, q);
      }
    }
    return b;
  }

  /// The triangle's box at step k; empty if a vertex is not finite there.
  Bounds3f step_box(uint32_t tri, uint32_t k) const { return steps_box(tri, k, k); }

  void build(const DeformingConfig& config) {
    // The builder groups triangles by their box averaged over the steps (where they are over
    // the shutter on average, as Embree's motion-blur builder weighs its linear bounds); the
    // boxes a ray tests are the linear bounds computed after.
    std::vector<BvhBuildRef> refs;
    const uint32_t tris = uint32_t(m_indices.size() / 3);
    for (uint32_t t = 0; t < tris; ++t) {
      const Bounds3f all = steps_box(t, 0, m_steps - 1);
      if (all.empty()) continue;
      m_bounds = merge(m_bounds, all);
      Vec3f lo, hi;
      for (uint32_t k = 0; k < m_steps; ++k) {
        const Bounds3f b = step_box(t, k);
        lo += b.lo;
        hi += b.hi;
      }
      const float w = 1.0f / float(m_steps);
      refs.emplace_back(Bounds3f{lo * w, hi * w}, t);
    }
    if (refs.empty() || m_exhaustive) {
      for (const BvhBuildRef& r : refs) m_prims.push_back(r.index);
      return;
    }
    BvhConfig bvh;
    bvh.max_leaf_size = config.max_leaf_size;
    const auto root = build_bvh_tree(refs, bvh);
    for (const BvhBuildRef& r : refs) m_prims.push_back(r.index);
    flatten_bvh(*root, m_nodes);
    m_depth = depth(*root);
    // Linear bounds per node and segment, bottom-up (a node's children come after it in
    // depth-first order): the boxes at the segment's two steps. Vertices move linearly within
    // a segment, so the box interpolated the same way at any time in it holds them; rounding
    // is monotonic, so the float interpolation of the box holds the float interpolation of
    // the vertices too.
    const uint32_t segments = m_steps - 1;
    m_lbounds.assign(m_nodes.size() * segments * 2, Bounds3f{});
    for (size_t i = m_nodes.size(); i-- > 0;) {
      const BvhNode& n = m_nodes[i];
      for (uint32_t s = 0; s < segments; ++s)
        for (uint32_t e = 0; e < 2; ++e) {
          Bounds3f b;
          if (n.count == 0) {
            b = merge(lbound(i + 1, s, e), lbound(n.offset, s, e));
          } else {
            for (uint32_t k = n.offset; k < n.offset + n.count; ++k)
              b = merge(b, step_box(m_prims[k], s + e));
          }
          m_lbounds[(i * segments + s) * 2 + e] = b;
        }
    }
    for (Bounds3f& b : m_lbounds) b = widen_for_rounding(b);
    // Each node's box over all time, which region queries test: its widened linear bounds at
    // every step merged (a vertex between two steps lies within their boxes' hull).
    for (size_t i = 0; i < m_nodes.size(); ++i) {
      Bounds3f all;
      for (uint32_t s = 0; s < segments; ++s) all = merge(merge(all, lbound(i, s, 0)), lbound(i, s, 1));
      m_nodes[i].lo = all.lo;
      m_nodes[i].hi = all.hi;
    }
  }

  const Bounds3f& lbound(size_t node, uint32_t segment, uint32_t end) const {
    return m_lbounds[(node * (m_steps - 1) + segment) * 2 + end];
  }

  static uint64_t depth(const BvhBuildNode& n) {
    return n.child[0] ? 1 + std::max(depth(*n.child[0]), depth(*n.child[1])) : 0;
  }

  /// Tests triangle `tri` at the ray's time against [tnear, tfar].
  bool test(const Ray& ray, const WatertightRay& w, uint32_t tri, float tfar, Hit& out) const {
    Vec3f p[3];
    for (int j = 0; j < 3; ++j)
      p[j] = interpolate_vertex(m_keys.data(), m_count, m_steps, m_indices[3 * size_t(tri) + size_t(j)],
                                ray.time);
    float t, u, v;
    if (!intersect_triangle_watertight(ray, w, p[0], p[1], p[2], tfar, t, u, v)) return false;
    out = {t, u, v, m_ids[tri].geom, m_ids[tri].prim};
    return true;
  }

  bool closest(const Ray& ray, Hit& hit, TraversalCost* cost, const HitFilter* filter) const {
    return query(ray, hit, cost, filter, false);
  }

  /// The closest accepted hit (or, with `any_hit`, the first one found) over the leaves the ray's
  /// time-segment boxes let it reach.
  bool query(const Ray& ray, Hit& hit, TraversalCost* cost, const HitFilter* filter, bool any_hit) const {
    hit = Hit{};
    if (!is_valid_query(ray)) return false;
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    float best = ray.tfar;
    // Offers triangles [first, first + count) of m_prims; true ends the query (any hit found).
    const auto leaf = [&](uint32_t first, uint32_t count) {
      if (cost) cost->triangles += count;
      for (uint32_t k = first; k < first + count; ++k) {
        Hit h;
        if (!test(ray, w, m_prims[k], best, h)) continue;
        if (filter && !(*filter)(ray, h)) continue;
        best = h.t;
        hit = h;
        if (any_hit) return true;
      }
      return false;
    };
    if (m_exhaustive) {
      if (cost) ++cost->nodes;
      leaf(0, uint32_t(m_prims.size()));
      return hit.valid();
    }
    if (m_nodes.empty()) return false;
    const MotionSegment seg = motion_segment(ray.time, m_steps);
    const float a = seg.a, b = 1.0f - seg.a;
    const RayBoxQuery q = prepare_box_query(ray);
    const float tnear = std::max(ray.tnear, 0.0f);
    uint32_t stack[kBvhStackSize];
    int sp = 0;
    uint32_t idx = 0;
    for (;;) {
      const BvhNode& node = m_nodes[idx];
      const Bounds3f &b0 = lbound(idx, seg.k, 0), &b1 = lbound(idx, seg.k, 1);
      if (cost) ++cost->nodes;
      float t0 = tnear, t1 = best;
      // The box at the ray's time, interpolated as interpolate_vertex interpolates vertices.
      const Vec3f lo = b0.lo * b + b1.lo * a, hi = b0.hi * b + b1.hi * a;
      if (!b0.empty() && intersect_box(lo, hi, q, t0, t1)) {
        if (node.count == 0) {
          const bool far_first = q.dir_neg[node.axis];
          stack[sp++] = far_first ? idx + 1 : node.offset;
          idx = far_first ? node.offset : idx + 1;
          continue;
        }
        if (leaf(node.offset, node.count)) return true;
      }
      if (sp == 0) break;
      idx = stack[--sp];
    }
    return hit.valid();
  }

  struct TriangleId {
    uint32_t geom, prim;  // the view and its triangle
  };
  std::vector<uint32_t> m_indices;  // 3 per triangle, into a step of m_keys
  std::vector<TriangleId> m_ids;    // per triangle
  std::vector<Vec3f> m_keys;        // m_steps x m_count positions
  size_t m_count = 0;
  uint32_t m_steps = 0;
  bool m_exhaustive = false;
  std::vector<uint32_t> m_prims;    // triangle indices in leaf order
  std::vector<BvhNode> m_nodes;     // topology (split by step-averaged boxes); lo, hi: the box over
                                    // all time (region queries); ray traversal reads m_lbounds
  std::vector<Bounds3f> m_lbounds;  // node x segment x {start, end}: linear bounds
  Bounds3f m_bounds;
  uint64_t m_depth = 0;
  double m_build_seconds = 0;
};

}  // namespace

std::unique_ptr<Accelerator> make_deforming_accelerator(std::span<const GeometryView> meshes,
                                                        const DeformingConfig& config) {
  return std::make_unique<DeformingAccelerator>(meshes, config);
}

}  // namespace penumbra
