// Binned-SAH BVH. Build: I. Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", IEEE Symposium on Interactive Ray Tracing 2007. Layout and traversal follow
// pbrt-v4's LinearBVHNode (Pharr, Jakob & Humphreys, 4th ed., sec. 7.3).
#include "renderer/accel/bvh.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/common.h"

namespace penumbra {
namespace {

/// Flattened node, 32 bytes. Children of an interior node: the first is the next node in the
/// array (depth-first order), the second is at `offset`.
struct alignas(32) BvhNode {
  Vec3f lo;         // 12 bytes: box minimum
  Vec3f hi;         // 12 bytes: box maximum
  uint32_t offset;  //  4 bytes: leaf: first triangle; interior: index of the second child
  uint16_t count;   //  2 bytes: triangles in a leaf; 0 marks an interior node
  uint8_t axis;     //  1 byte : split axis of an interior node (visit order)
  uint8_t pad;      //  1 byte : unused
};
static_assert(sizeof(BvhNode) == 32, "BvhNode must stay 32 bytes");

// Build-time types stay in this file.
struct BuildRef {  // one triangle's bounds and centroid: all the builder ever sees
  Bounds3f box;
  Vec3f centroid;
  uint32_t index;  // into the triangle array
};

struct BuildNode {
  Bounds3f box;
  std::unique_ptr<BuildNode> child[2];
  uint32_t first = 0, count = 0;  // leaf range in the reordered reference array
  int axis = 0;
};

/// SAH depth limit: below it, splits fall back to the object median, which bounds the
/// remaining depth by log2(n) and keeps every path within kStackSize.
constexpr int kMaxSahDepth = 64;
constexpr int kStackSize = 128;

class Builder {
 public:
  Builder(const BvhConfig& c, std::vector<BuildRef>& refs) : m_config(c), m_refs(refs) {}

  std::unique_ptr<BuildNode> build(uint32_t begin, uint32_t end, int depth) {
    auto node = std::make_unique<BuildNode>();
    Bounds3f box, centroids;
    for (uint32_t i = begin; i < end; ++i) {
      box = merge(box, m_refs[i].box);
      centroids = merge(centroids, m_refs[i].centroid);
    }
    node->box = box;
    const uint32_t n = end - begin;
    if (n <= 1) return make_leaf(std::move(node), begin, n);

    // Choose the split: binned SAH over all three axes, or the object median.
    uint32_t mid = begin;
    int axis = 0;
    const bool sah = depth < kMaxSahDepth;
    if (sah && find_sah_split(begin, end, box, centroids, axis, mid)) {
      // partitioned by find_sah_split
    } else if (n <= uint32_t(m_config.max_leaf_size)) {
      return make_leaf(std::move(node), begin, n);
    } else {
      // Object median along the widest centroid axis: the fallback when SAH cannot separate
      // the centroids (all equal) or the SAH depth limit is reached.
      const Vec3f ext = centroids.extent();
      axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
      mid = begin + n / 2;
      std::nth_element(m_refs.begin() + begin, m_refs.begin() + mid, m_refs.begin() + end,
                       [axis](const BuildRef& a, const BuildRef& b) {
                         return a.centroid[axis] < b.centroid[axis] ||
                                (a.centroid[axis] == b.centroid[axis] && a.index < b.index);
                       });
    }
    node->axis = axis;
    // Recurse; large subtrees in parallel. The tree's shape never depends on scheduling.
    if (n >= m_config.parallel_threshold) {
      tbb::parallel_invoke([&] { node->child[0] = build(begin, mid, depth + 1); },
                           [&] { node->child[1] = build(mid, end, depth + 1); });
    } else {
      node->child[0] = build(begin, mid, depth + 1);
      node->child[1] = build(mid, end, depth + 1);
    }
    return node;
  }

 private:
  static std::unique_ptr<BuildNode> make_leaf(std::unique_ptr<BuildNode> node, uint32_t begin,
                                              uint32_t n) {
    node->first = begin;
    node->count = n;
    return node;
  }

  /// Returns true and partitions [begin, end) at `mid` if the best binned split is cheaper
  /// than a leaf (or the node is too big to be one).
  bool find_sah_split(uint32_t begin, uint32_t end, const Bounds3f& box, const Bounds3f& centroids,
                      int& best_axis, uint32_t& mid) {
    const uint32_t n = end - begin;
    const int nb = m_config.bin_count;
    struct Bin {
      Bounds3f box;
      uint32_t count = 0;
    };
    std::array<Bin, 256> bins;
    std::array<float, 256> right_area;
    std::array<uint32_t, 256> right_count;
    float best_cost = kInfinity;
    int best_bin = -1;
    best_axis = -1;
    const Vec3f ext = centroids.extent();
    for (int axis = 0; axis < 3; ++axis) {
      if (!(ext[axis] > 0)) continue;
      // Phase 1: bin centroids (Wald 2007, eq. 1: k = nb (1 - eps) (c - cmin) / (cmax - cmin)).
      const float scale = nb * (1 - 1e-6f) / ext[axis];
      for (int b = 0; b < nb; ++b) bins[b] = Bin{};
      for (uint32_t i = begin; i < end; ++i) {
        const int b = bin_index(m_refs[i].centroid[axis], centroids.lo[axis], scale, nb);
        bins[b].box = merge(bins[b].box, m_refs[i].box);
        ++bins[b].count;
      }
      // Phase 2: sweep from the right, then from the left, evaluating the nb - 1 planes.
      Bounds3f acc;
      uint32_t cnt = 0;
      for (int b = nb - 1; b > 0; --b) {
        acc = merge(acc, bins[b].box);
        cnt += bins[b].count;
        right_area[b] = surface_area(acc);
        right_count[b] = cnt;
      }
      acc = Bounds3f{};
      cnt = 0;
      for (int b = 0; b < nb - 1; ++b) {
        acc = merge(acc, bins[b].box);
        cnt += bins[b].count;
        if (cnt == 0 || right_count[b + 1] == 0) continue;
        const float cost = surface_area(acc) * float(cnt) + right_area[b + 1] * float(right_count[b + 1]);
        if (cost < best_cost) {
          best_cost = cost;
          best_bin = b;
          best_axis = axis;
        }
      }
    }
    if (best_axis < 0) return false;
    // Phase 3: compare with a leaf, C = Ct + Ci (A_L N_L + A_R N_R) / A.
    const float area = surface_area(box);
    const float split_cost = m_config.traversal_cost +
                             m_config.intersection_cost * (area > 0 ? best_cost / area : float(n));
    const float leaf_cost = m_config.intersection_cost * float(n);
    if (n <= uint32_t(m_config.max_leaf_size) && leaf_cost <= split_cost) return false;
    // Phase 4: partition the references by bin.
    const float scale = nb * (1 - 1e-6f) / ext[best_axis];
    const float cmin = centroids.lo[best_axis];
    const int axis = best_axis;
    auto it = std::stable_partition(m_refs.begin() + begin, m_refs.begin() + end, [&](const BuildRef& r) {
      return bin_index(r.centroid[axis], cmin, scale, nb) <= best_bin;
    });
    mid = uint32_t(it - m_refs.begin());
    return mid > begin && mid < end;
  }

  static int bin_index(float c, float cmin, float scale, int nb) {
    const int b = int((c - cmin) * scale);
    return std::clamp(b, 0, nb - 1);
  }

  const BvhConfig& m_config;
  std::vector<BuildRef>& m_refs;
};

class BvhAccelerator final : public TraversalAccelerator<BvhAccelerator> {
  friend class TraversalAccelerator<BvhAccelerator>;

 public:
  BvhAccelerator(std::span<const TriangleMeshView> meshes, const BvhConfig& config) : m_config(config) {
    validate(config);
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<TriangleRecord> tris = gather_triangles(meshes);
    m_input_triangles = count_input_triangles(meshes);
    if (!tris.empty()) {
      std::vector<BuildRef> refs(tris.size());
      for (uint32_t i = 0; i < tris.size(); ++i) {
        const Bounds3f b = triangle_bounds(tris[i]);
        refs[i] = {b, b.center(), i};
      }
      Builder builder(m_config, refs);
      auto root = builder.build(0, uint32_t(refs.size()), 0);
      // Reorder the triangles so each leaf is a contiguous range.
      m_tris.resize(tris.size());
      for (size_t i = 0; i < refs.size(); ++i) m_tris[i] = tris[refs[i].index];
      flatten(*root);
      m_bounds = root->box;
      m_sah_root_area = surface_area(root->box);
      compute_stats(*root, 0);
      m_tally.fill(m_stats);
    }
    m_build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  Bounds3f bounds() const override { return m_bounds; }

  AccelStats stats() const override {
    AccelStats s = m_stats;
    s.name = "bvh";
    s.config = "max_leaf_size " + std::to_string(m_config.max_leaf_size) + ", bin_count " +
               std::to_string(m_config.bin_count) + ", traversal_cost " +
               format_number(m_config.traversal_cost) + ", intersection_cost " +
               format_number(m_config.intersection_cost);
    s.triangles = m_input_triangles;
    s.nodes = m_nodes.size();
    s.bytes = m_nodes.size() * sizeof(BvhNode) + m_tris.size() * sizeof(TriangleRecord);
    s.build_seconds = m_build_seconds;
    return s;
  }

 private:
  /// Depth-first traversal, nearer child first (by the sign of the ray direction along the
  /// node's split axis), culling boxes beyond `best`. `visit(w, tri)` returns true to stop
  /// (any-hit); closest-hit visitors narrow `best`. Returns true iff a visitor stopped it.
  template <typename Visit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit) const {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid || m_nodes.empty()) return false;
    const RayBoxQuery q = prepare_box_query(ray);
    uint32_t stack[kStackSize];
    int sp = 0;
    uint32_t idx = 0;
    for (;;) {
      const BvhNode& node = m_nodes[idx];
      float t0 = w.tnear, t1 = best;
      if (intersect_box(node.lo, node.hi, q, t0, t1)) {
        if (node.count == 0) {
          const bool far_first = q.dir_neg[node.axis];
          stack[sp++] = far_first ? idx + 1 : node.offset;
          idx = far_first ? node.offset : idx + 1;
          continue;
        }
        for (uint32_t i = node.offset, e = node.offset + node.count; i < e; ++i)
          if (visit(w, m_tris[i])) return true;
      }
      if (sp == 0) return false;
      idx = stack[--sp];
    }
  }

  uint32_t flatten(const BuildNode& b) {
    const uint32_t idx = uint32_t(m_nodes.size());
    const Bounds3f box = widen_for_rounding(b.box);
    m_nodes.push_back({box.lo, box.hi, 0, 0, uint8_t(b.axis), 0});
    if (!b.child[0]) {
      m_nodes[idx].offset = b.first;
      m_nodes[idx].count = uint16_t(b.count);
      return idx;
    }
    flatten(*b.child[0]);
    m_nodes[idx].offset = flatten(*b.child[1]);
    return idx;
  }

  void compute_stats(const BuildNode& b, uint64_t depth) {
    m_stats.max_depth = std::max(m_stats.max_depth, depth);
    const double rel = m_sah_root_area > 0 ? surface_area(b.box) / m_sah_root_area : 1.0;
    if (!b.child[0]) {
      m_tally.add(b.count);
      m_stats.sah_cost += rel * m_config.intersection_cost * b.count;
      return;
    }
    m_stats.sah_cost += rel * m_config.traversal_cost;
    compute_stats(*b.child[0], depth + 1);
    compute_stats(*b.child[1], depth + 1);
  }

  BvhConfig m_config;
  std::vector<BvhNode> m_nodes;        // depth-first; node 0 is the root; boxes widened
  Bounds3f m_bounds;                   // exact bounds of the triangles
  std::vector<TriangleRecord> m_tris;  // reordered so leaves are contiguous
  uint64_t m_input_triangles = 0;
  double m_sah_root_area = 0;
  LeafTally m_tally;
  AccelStats m_stats;
  double m_build_seconds = 0;
};

}  // namespace

void validate(const BvhConfig& c) {
  if (c.max_leaf_size < 1 || c.max_leaf_size > 255)
    throw std::invalid_argument("bvh: max_leaf_size must be in [1, 255], got " + std::to_string(c.max_leaf_size));
  if (c.bin_count < 2 || c.bin_count > 256)
    throw std::invalid_argument("bvh: bin_count must be in [2, 256], got " + std::to_string(c.bin_count));
  if (!(c.traversal_cost > 0) || !(c.intersection_cost > 0))
    throw std::invalid_argument("bvh: traversal_cost and intersection_cost must be > 0");
}

std::unique_ptr<Accelerator> make_bvh_accelerator(std::span<const TriangleMeshView> meshes,
                                                  const BvhConfig& config) {
  return std::make_unique<BvhAccelerator>(meshes, config);
}

}  // namespace penumbra
