// Binned-SAH BVH. Build: I. Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", IEEE Symposium on Interactive Ray Tracing 2007. Binary layout and traversal
// follow pbrt-v4's LinearBVHNode (Pharr, Jakob & Humphreys, 4th ed., sec. 7.3). The 4-wide
// layout collapses the binary tree (opening the child of largest surface area first) and tests
// four boxes per SSE instruction: Wald, Benthin & Boulos, "Getting Rid of Packets", IEEE RT 2008;
// Dammertz, Hanika & Keller, "Shallow Bounding Volume Hierarchies for Fast SIMD Ray Tracing of
// Incoherent Rays", EGSR 2008.
#include "renderer/accel/bvh.h"

#include <tbb/parallel_invoke.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/bvh_build.h"
#include "renderer/accel/common.h"
#include "renderer/accel/stats.h"

namespace penumbra {
namespace {

/// 4-wide node, 128 bytes (two cache lines), boxes in structure-of-arrays form so one SSE
/// register holds the same bound of all four children. Unused slots have an empty box
/// (lo = +inf, hi = -inf), which no ray meets.
struct alignas(64) Bvh4Node {
  float lo[3][4];     // 48 bytes: lo[axis][child]
  float hi[3][4];     // 48 bytes: hi[axis][child]
  uint32_t child[4];  // 16 bytes: interior child: node index; leaf: first triangle
  uint8_t count[4];   //  4 bytes: 0 = interior child (or unused slot), else triangles in the leaf
  uint32_t pad[3];    // 12 bytes: unused
};
static_assert(sizeof(Bvh4Node) == 128, "Bvh4Node must stay 128 bytes");

/// Bound on the 4-wide traversal stack: each level pushes at most 3 entries beyond the one it
/// pops, and the collapsed tree is no deeper than the binary one (< kStackSize levels).
constexpr int kStack4Size = 3 * 128 + 4;

/// SAH depth limit: below it, splits fall back to the object median, which bounds the
/// remaining depth by log2(n) and keeps every path within kStackSize.
constexpr int kMaxSahDepth = 64;
constexpr int kStackSize = kBvhStackSize;

class Builder {
 public:
  Builder(const BvhConfig& c, std::vector<BvhBuildRef>& refs) : m_config(c), m_refs(refs) {}

  std::unique_ptr<BvhBuildNode> build(uint32_t begin, uint32_t end, int depth) {
    auto node = std::make_unique<BvhBuildNode>();
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
                       [axis](const BvhBuildRef& a, const BvhBuildRef& b) {
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
  static std::unique_ptr<BvhBuildNode> make_leaf(std::unique_ptr<BvhBuildNode> node, uint32_t begin,
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
    const float split_cost =
        m_config.traversal_cost + m_config.intersection_cost * (area > 0 ? best_cost / area : float(n));
    const float leaf_cost = m_config.intersection_cost * float(n);
    if (n <= uint32_t(m_config.max_leaf_size) && leaf_cost <= split_cost) return false;
    // Phase 4: partition the references by bin.
    const float scale = nb * (1 - 1e-6f) / ext[best_axis];
    const float cmin = centroids.lo[best_axis];
    const int axis = best_axis;
    auto it = std::stable_partition(m_refs.begin() + begin, m_refs.begin() + end, [&](const BvhBuildRef& r) {
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
  std::vector<BvhBuildRef>& m_refs;
};

}  // namespace

std::unique_ptr<BvhBuildNode> build_bvh_tree(std::vector<BvhBuildRef>& refs, const BvhConfig& config) {
  Builder builder(config, refs);
  return builder.build(0, uint32_t(refs.size()), 0);
}

uint32_t flatten_bvh(const BvhBuildNode& b, std::vector<BvhNode>& nodes) {
  const uint32_t idx = uint32_t(nodes.size());
  const Bounds3f box = widen_for_rounding(b.box);
  nodes.push_back({box.lo, box.hi, 0, 0, uint8_t(b.axis), 0});
  if (!b.child[0]) {
    nodes[idx].offset = b.first;
    nodes[idx].count = uint16_t(b.count);
    return idx;
  }
  flatten_bvh(*b.child[0], nodes);
  nodes[idx].offset = flatten_bvh(*b.child[1], nodes);
  return idx;
}

namespace {

class BvhAccelerator final : public TraversalAccelerator<BvhAccelerator> {
  friend class TraversalAccelerator<BvhAccelerator>;

 public:
  BvhAccelerator(std::span<const GeometryView> meshes, const BvhConfig& config) : m_config(config) {
    validate(config);
    const BuildTimer timer;
    std::vector<PrimitiveRecord> tris = gather_primitives(meshes, m_shapes);
    m_input_triangles = count_input_triangles(meshes);
    if (!tris.empty()) {
      std::vector<BvhBuildRef> refs(tris.size());
      for (uint32_t i = 0; i < tris.size(); ++i) {
        const Bounds3f b = primitive_bounds(tris[i]);
        refs[i] = {b, b.center(), i};
      }
      auto root = build_bvh_tree(refs, m_config);
      // Reorder the triangles so each leaf is a contiguous range.
      m_tris.resize(tris.size());
      for (size_t i = 0; i < refs.size(); ++i) m_tris[i] = tris[refs[i].index];
      m_bounds = root->box;
      m_sah_root_area = surface_area(root->box);
      if (m_config.width == 2) {
        flatten_bvh(*root, m_nodes);
        compute_stats(*root, 0);
      } else {
        collapse(*root, 0);
      }
      m_tally.fill(m_stats);
    }
    m_build_seconds = timer.seconds();
  }

  Bounds3f bounds() const override { return m_bounds; }

  AccelStats stats() const override {
    AccelStats s = make_stats(m_stats, "bvh",
                              "width " + std::to_string(m_config.width) + ", max_leaf_size " +
                                  std::to_string(m_config.max_leaf_size) + ", bin_count " +
                                  std::to_string(m_config.bin_count) + ", traversal_cost " +
                                  format_number(m_config.traversal_cost) + ", intersection_cost " +
                                  format_number(m_config.intersection_cost),
                              m_input_triangles,
                              m_nodes.size() * sizeof(BvhNode) + m_nodes4.size() * sizeof(Bvh4Node) +
                                  m_tris.size() * sizeof(PrimitiveRecord),
                              m_build_seconds);
    s.nodes = m_config.width == 2 ? m_nodes.size() : m_nodes4.size() + m_tally.leaves;
    s.shapes = m_shapes.size();
    return s;
  }

 private:
  /// The traversal of the configured layout. `visit(w, tri)` returns true to stop (any-hit);
  /// closest-hit visitors narrow `best`. Returns true iff a visitor stopped it.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    return m_config.width == 2 ? traverse2(ray, best, visit, counter)
                               : traverse4<AnyHit>(ray, best, visit, counter);
  }

  /// 4-wide traversal: the four child boxes are slab-tested at once; the children met are
  /// pushed far to near with their entry distance, and entries beyond `best` are skipped when
  /// popped. Leaves sit on the stack like nodes, so triangles are tested front to back.
  /// The box test is the scalar one's (common.h) in SSE, distances padded outward by kSlabPad.
  /// On an axis the ray is parallel to (1/d infinite) the distances are +-inf, or NaN
  /// (0 * inf) when the origin lies exactly on a face: such a lane is inside the slab, faces
  /// included, so NaN lanes become the unrestricted interval [-inf, inf].
  /// For occlusion (AnyHit) the leaves met are tested at once, before any node is pushed, and
  /// nothing is sorted: the first hit ends the query, wherever it is.
  template <bool AnyHit, typename Visit, typename Counter>
  bool traverse4(const Ray& ray, const float& best, Visit& visit, const Counter& counter) const {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid || m_nodes4.empty()) return false;
    const RayBoxQuery q = prepare_box_query(ray);
    const __m128 org[3] = {_mm_set1_ps(q.org.x), _mm_set1_ps(q.org.y), _mm_set1_ps(q.org.z)};
    const __m128 inv[3] = {_mm_set1_ps(q.inv_dir.x), _mm_set1_ps(q.inv_dir.y), _mm_set1_ps(q.inv_dir.z)};
    const __m128 pad = _mm_set1_ps(kSlabPad - 1.0f);
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 tnear = _mm_set1_ps(w.tnear);
    const __m128 neg_inf = _mm_set1_ps(-kInfinity), pos_inf = _mm_set1_ps(kInfinity);
    const __m128 max_float = _mm_set1_ps(std::numeric_limits<float>::max());
    const bool parallel[3] = {std::isinf(q.inv_dir.x), std::isinf(q.inv_dir.y), std::isinf(q.inv_dir.z)};
    struct Entry {
      uint32_t child, count;
      float t;
    };
    Entry stack[kStack4Size];
    int sp = 0;
    stack[sp++] = {0, 0, w.tnear};
    while (sp > 0) {
      const Entry e = stack[--sp];
      if (e.t > best) continue;
      counter.node();
      if (e.count > 0) {
        for (uint32_t i = e.child, end = e.child + e.count; i < end; ++i)
          if (visit(w, m_tris[i])) return true;
        continue;
      }
      const Bvh4Node& n = m_nodes4[e.child];
      __m128 t0 = tnear, t1 = _mm_set1_ps(best);
      for (int k = 0; k < 3; ++k) {
        // Near and far planes by the direction's sign (not min/max), so an unused slot's
        // inverted box (lo = +inf, hi = -inf) gives an empty interval.
        const float* near_plane = q.dir_neg[k] ? n.hi[k] : n.lo[k];
        const float* far_plane = q.dir_neg[k] ? n.lo[k] : n.hi[k];
        const __m128 a = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(near_plane), org[k]), inv[k]);
        const __m128 b = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(far_plane), org[k]), inv[k]);
        __m128 tn = a, tf = b;
        if (parallel[k]) {
          const __m128 on_face = _mm_cmpunord_ps(a, b);
          tn = _mm_or_ps(_mm_andnot_ps(on_face, tn), _mm_and_ps(on_face, neg_inf));
          tf = _mm_or_ps(_mm_andnot_ps(on_face, tf), _mm_and_ps(on_face, pos_inf));
        } else {
          // The pad is capped at FLT_MAX so an infinite distance stays infinite (inf - inf
          // would be NaN, and an unused slot's box would then count as met).
          tn = _mm_sub_ps(tn, _mm_min_ps(_mm_mul_ps(_mm_and_ps(tn, abs_mask), pad), max_float));
          tf = _mm_add_ps(tf, _mm_min_ps(_mm_mul_ps(_mm_and_ps(tf, abs_mask), pad), max_float));
        }
        t0 = _mm_max_ps(tn, t0);
        t1 = _mm_min_ps(tf, t1);
      }
      int mask = _mm_movemask_ps(_mm_cmple_ps(t0, t1));
      if (mask == 0) continue;
      if constexpr (AnyHit) {
        for (int m = mask; m; m &= m - 1) {
          const int c = __builtin_ctz(unsigned(m));
          if (n.count[c] == 0) {
            stack[sp++] = {n.child[c], 0, w.tnear};
            const char* p = reinterpret_cast<const char*>(&m_nodes4[n.child[c]]);
            _mm_prefetch(p, _MM_HINT_T0);
            _mm_prefetch(p + 64, _MM_HINT_T0);
            continue;
          }
          counter.node();
          for (uint32_t i = n.child[c], end = n.child[c] + n.count[c]; i < end; ++i)
            if (visit(w, m_tris[i])) return true;
        }
        continue;
      }
      alignas(16) float tn[4];
      _mm_store_ps(tn, t0);
      // Children met, sorted far to near (at most 4: insertion sort), then pushed.
      int order[4], m = 0;
      for (; mask; mask &= mask - 1) {
        const int c = __builtin_ctz(unsigned(mask));
        int j = m++;
        while (j > 0 && tn[order[j - 1]] < tn[c]) {
          order[j] = order[j - 1];
          --j;
        }
        order[j] = c;
      }
      for (int j = 0; j < m; ++j) {
        const int c = order[j];
        stack[sp++] = {n.child[c], n.count[c], tn[c]};
        // Traversal is bound by memory latency (node and triangle loads miss the cache on big
        // scenes): start fetching what the next pops will read.
        if (n.count[c] == 0) {
          const char* p = reinterpret_cast<const char*>(&m_nodes4[n.child[c]]);
          _mm_prefetch(p, _MM_HINT_T0);
          _mm_prefetch(p + 64, _MM_HINT_T0);
        } else {
          const char* p = reinterpret_cast<const char*>(&m_tris[n.child[c]]);
          const char* end = p + n.count[c] * sizeof(PrimitiveRecord);
          for (; p < end; p += 64) _mm_prefetch(p, _MM_HINT_T0);
        }
      }
    }
    return false;
  }

  /// Binary traversal: depth first, nearer child first (by the sign of the ray direction along
  /// the node's split axis), culling boxes beyond `best`.
  template <typename Visit, typename Counter>
  bool traverse2(const Ray& ray, const float& best, Visit& visit, const Counter& counter) const {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid) return false;
    return walk_bvh(
        m_nodes, prepare_box_query(ray), w.tnear, best, [&] { counter.node(); },
        [&](uint32_t first, uint32_t count) {
          for (uint32_t i = first, e = first + count; i < e; ++i)
            if (visit(w, m_tris[i])) return true;
          return false;
        });
  }

  /// Emits the 4-wide node for interior binary node `b`: its children, with the interior child
  /// of largest surface area replaced by its two children until there are four (or only
  /// leaves). Fills the statistics as it goes (leaves, depth, SAH cost of the 4-wide tree).
  /// A node's interior children are stored next to each other (one block per parent), so
  /// siblings share pages and the hardware prefetcher's adjacent lines. Writes node `idx`
  /// (the root: 0, allocated here).
  void collapse(const BvhBuildNode& b, uint64_t depth, uint32_t idx = 0) {
    if (m_nodes4.empty()) m_nodes4.emplace_back();
    m_stats.max_depth = std::max(m_stats.max_depth, depth);
    const double rel = m_sah_root_area > 0 ? surface_area(b.box) / m_sah_root_area : 1.0;
    m_stats.sah_cost += rel * m_config.traversal_cost;
    const BvhBuildNode* kids[4];
    int n = 0;
    if (!b.child[0]) {
      kids[n++] = &b;  // the root is a leaf: one slot
    } else {
      kids[n++] = b.child[0].get();
      kids[n++] = b.child[1].get();
    }
    while (n < 4) {
      int open = -1;
      float area = -1;
      for (int i = 0; i < n; ++i)
        if (kids[i]->child[0] && surface_area(kids[i]->box) > area) {
          area = surface_area(kids[i]->box);
          open = i;
        }
      if (open < 0) break;
      const BvhBuildNode* o = kids[open];
      kids[open] = o->child[0].get();
      kids[n++] = o->child[1].get();
    }
    uint32_t child[4] = {0, 0, 0, 0};
    uint8_t count[4] = {0, 0, 0, 0};
    uint32_t next = uint32_t(m_nodes4.size());  // the block of this node's interior children
    for (int i = 0; i < n; ++i)
      if (kids[i]->child[0]) child[i] = next++;
    m_nodes4.resize(next);
    for (int i = 0; i < n; ++i) {
      if (kids[i]->child[0]) {
        collapse(*kids[i], depth + 1, child[i]);
      } else {
        child[i] = kids[i]->first;
        count[i] = uint8_t(kids[i]->count);
        m_tally.add(kids[i]->count);
        m_stats.max_depth = std::max(m_stats.max_depth, depth + 1);
        const double lrel = m_sah_root_area > 0 ? surface_area(kids[i]->box) / m_sah_root_area : 1.0;
        m_stats.sah_cost += lrel * m_config.intersection_cost * kids[i]->count;
      }
    }
    Bvh4Node& node = m_nodes4[idx];  // after the recursion: resize may have moved it
    for (int i = 0; i < 4; ++i) {
      const Bounds3f box = i < n ? widen_for_rounding(kids[i]->box) : Bounds3f{};
      for (int k = 0; k < 3; ++k) {
        node.lo[k][i] = i < n ? box.lo[k] : kInfinity;
        node.hi[k][i] = i < n ? box.hi[k] : -kInfinity;
      }
      node.child[i] = i < n ? child[i] : UINT32_MAX;  // never followed: the box is empty
      node.count[i] = count[i];
    }
  }

  void compute_stats(const BvhBuildNode& b, uint64_t depth) {
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
  std::vector<BvhNode> m_nodes;         // width 2: depth-first; node 0 is the root; boxes widened
  std::vector<Bvh4Node> m_nodes4;       // width 4: node 0 is the root; boxes widened
  Bounds3f m_bounds;                    // exact bounds of the triangles
  std::vector<PrimitiveRecord> m_tris;  // reordered so leaves are contiguous
  uint64_t m_input_triangles = 0;
  double m_sah_root_area = 0;
  LeafTally m_tally;
  AccelStats m_stats;
  double m_build_seconds = 0;
};

}  // namespace

void validate(const BvhConfig& c) {
  if (c.max_leaf_size < 1 || c.max_leaf_size > 255)
    throw std::invalid_argument("bvh: max_leaf_size must be in [1, 255], got " +
                                std::to_string(c.max_leaf_size));
  if (c.bin_count < 2 || c.bin_count > 256)
    throw std::invalid_argument("bvh: bin_count must be in [2, 256], got " + std::to_string(c.bin_count));
  if (c.width != 2 && c.width != 4)
    throw std::invalid_argument("bvh: width must be 2 or 4, got " + std::to_string(c.width));
  if (!(c.traversal_cost > 0) || !(c.intersection_cost > 0))
    throw std::invalid_argument("bvh: traversal_cost and intersection_cost must be > 0");
}

std::unique_ptr<Accelerator> make_bvh_accelerator(std::span<const GeometryView> meshes,
                                                  const BvhConfig& config) {
  return std::make_unique<BvhAccelerator>(meshes, config);
}

}  // namespace penumbra
