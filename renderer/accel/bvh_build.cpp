// Binned-SAH BVH build: I. Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", IEEE Symposium on Interactive Ray Tracing 2007. One pass over a node's
// references bins their centroids along all three axes at once; the chosen split partitions
// them in place while accumulating both children's boxes and centroid bounds, so each level
// reads every reference twice. Subtrees above a size threshold build in parallel TBB tasks.
// The flattening into binary nodes follows pbrt-v4's LinearBVHNode (Pharr, Jakob & Humphreys,
// 4th ed., sec. 7.3).
#include "renderer/accel/bvh_build.h"

#include <emmintrin.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <cstddef>

namespace penumbra {
namespace {

/// SAH depth limit: below it, splits fall back to the object median, which bounds the
/// remaining depth by log2(n) and keeps every path within kBvhStackSize.
constexpr int kMaxSahDepth = 64;
static_assert(kMaxSahDepth + 32 <= kBvhStackSize, "median splits of up to 2^32 references fit the stacks");

/// The references of one node: their range, box and centroid bounds.
struct Range {
  uint32_t begin, end;
  Bounds3f box, centroids;
};

/// Widens a range's box and centroid bounds by one reference.
void add(Range& side, const BvhBuildRef& ref) {
  side.box = merge(side.box, ref.box());
  side.centroids = merge(side.centroids, ref.centroid());
}

/// A reference's box corners in SSE registers, lane 3 (the index or padding) cleared so that
/// no arithmetic runs on its bits (a subnormal as a float).
inline __m128 xyz_only(__m128 v) {
  return _mm_and_ps(v, _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0)));
}
inline __m128 ref_lo(const BvhBuildRef& r) {
  return xyz_only(_mm_load_ps(&r.lo.x));
}
inline __m128 ref_hi(const BvhBuildRef& r) {
  return xyz_only(_mm_load_ps(&r.hi.x));
}

/// A box in SSE registers (lane 3 unused): the build's inner loops merge with one min and one
/// max per box.
struct SseBox {
  __m128 lo = _mm_set1_ps(kInfinity), hi = _mm_set1_ps(-kInfinity);
  void grow(__m128 a, __m128 b) {
    lo = _mm_min_ps(lo, a);
    hi = _mm_max_ps(hi, b);
  }
  Bounds3f bounds() const {
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo);
    _mm_store_ps(h, hi);
    return {{l[0], l[1], l[2]}, {h[0], h[1], h[2]}};
  }
  /// Surface area; only called on non-empty boxes.
  float area() const {
    alignas(16) float d[4];
    _mm_store_ps(d, _mm_sub_ps(hi, lo));
    return 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
  }
  void merge_with(const SseBox& o) {
    lo = _mm_min_ps(lo, o.lo);
    hi = _mm_max_ps(hi, o.hi);
  }
};
static_assert(offsetof(BvhBuildRef, lo) == 0 && offsetof(BvhBuildRef, hi) == 16, "aligned SSE loads");

class Builder {
 public:
  Builder(const BvhConfig& c, std::vector<BvhBuildRef>& refs, int block)
      : m_config(c), m_refs(refs), m_block(block) {}

  std::unique_ptr<BvhBuildNode> build(const Range& r, int depth) {
    auto node = std::make_unique<BvhBuildNode>();
    node->box = r.box;
    const uint32_t n = r.end - r.begin;
    if (n <= 1) return make_leaf(std::move(node), r.begin, n);
    Range left, right;
    int axis = 0;
    if (!(depth < kMaxSahDepth && find_sah_split(r, axis, left, right))) {
      if (n <= uint32_t(m_config.max_leaf_size)) return make_leaf(std::move(node), r.begin, n);
      median_split(r, axis, left, right);
    }
    node->axis = axis;
    // Recurse; large subtrees in parallel. The tree's shape never depends on scheduling.
    if (n >= m_config.parallel_threshold) {
      tbb::parallel_invoke([&] { node->child[0] = build(left, depth + 1); },
                           [&] { node->child[1] = build(right, depth + 1); });
    } else {
      node->child[0] = build(left, depth + 1);
      node->child[1] = build(right, depth + 1);
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

  /// Leaf blocks of n primitives: the unit of the intersection cost.
  float blocks(uint32_t n) const { return float((n + uint32_t(m_block) - 1) / uint32_t(m_block)); }

  /// Returns true and partitions `r` into `left` and `right` if the best binned split is
  /// cheaper than a leaf (or the node is too big to be one).
  bool find_sah_split(const Range& r, int& best_axis, Range& left, Range& right) {
    const uint32_t n = r.end - r.begin;
    // No more bins than references: small nodes, the most numerous, stay cheap to bin.
    const int nb = int(std::min<uint32_t>(uint32_t(m_config.bin_count), std::max(n, 2u)));
    const int sets = n >= 64 ? 2 : 1;
    // Two sets of bins, for even and odd references: neighbours often share a bin, and one set
    // would chain every merge through the previous one's store.
    struct Bins {
      SseBox box[2][3][256];
      uint32_t count[2][3][256];
    };
    thread_local Bins bins;  // 54 KiB: off the stack of deep recursions; only nb bins are reset
    const Vec3f ext = r.centroids.extent();
    alignas(16) float scale[4] = {0, 0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      // Wald 2007, eq. 1: k = nb (1 - eps) (c - cmin) / (cmax - cmin).
      scale[k] = ext[k] > 0 ? nb * (1 - 1e-6f) / ext[k] : 0.0f;
      for (int set = 0; set < sets; ++set)
        for (int b = 0; b < nb; ++b) bins.box[set][k][b] = SseBox{}, bins.count[set][k][b] = 0;
    }
    // Phase 1: bin the centroids along the three axes in one pass; the bin index is
    // bin_index()'s (the same float operations, clamped before truncation).
    const __m128 cmin4 = _mm_setr_ps(r.centroids.lo.x, r.centroids.lo.y, r.centroids.lo.z, 0);
    const __m128 scale4 = _mm_load_ps(scale), top = _mm_set1_ps(float(nb - 1));
    const auto bin_ref = [&](int set, const BvhBuildRef& ref) {
      const __m128 lo = ref_lo(ref), hi = ref_hi(ref);
      const __m128 c = _mm_mul_ps(_mm_add_ps(lo, hi), _mm_set1_ps(0.5f));  // Bounds3f::center()
      const __m128 f = _mm_mul_ps(_mm_sub_ps(c, cmin4), scale4);
      alignas(16) int32_t b[4];
      _mm_store_si128(reinterpret_cast<__m128i*>(b),
                      _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(f, _mm_setzero_ps()), top)));
      for (int k = 0; k < 3; ++k) {
        bins.box[set][k][b[k]].grow(lo, hi);
        ++bins.count[set][k][b[k]];
      }
    };
    uint32_t i = r.begin;
    if (sets == 2) {
      for (; i + 1 < r.end; i += 2) {
        bin_ref(0, m_refs[i]);
        bin_ref(1, m_refs[i + 1]);
      }
      for (int k = 0; k < 3; ++k)
        for (int b = 0; b < nb; ++b) {
          bins.box[0][k][b].merge_with(bins.box[1][k][b]);
          bins.count[0][k][b] += bins.count[1][k][b];
        }
    }
    for (; i < r.end; ++i) bin_ref(0, m_refs[i]);
    // Phase 2: per axis, sweep from the right, then from the left, over the nb - 1 planes.
    float best_cost = kInfinity;
    int best_bin = -1;
    best_axis = -1;
    std::array<float, 256> right_cost;
    for (int k = 0; k < 3; ++k) {
      if (!(ext[k] > 0)) continue;
      SseBox acc;
      uint32_t cnt = 0;
      for (int b = nb - 1; b > 0; --b) {
        acc.merge_with(bins.box[0][k][b]);
        cnt += bins.count[0][k][b];
        right_cost[b] = cnt ? acc.area() * blocks(cnt) : -1.0f;
      }
      acc = SseBox{};
      cnt = 0;
      for (int b = 0; b < nb - 1; ++b) {
        acc.merge_with(bins.box[0][k][b]);
        cnt += bins.count[0][k][b];
        if (cnt == 0 || right_cost[b + 1] < 0) continue;
        const float cost = acc.area() * blocks(cnt) + right_cost[b + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_bin = b;
          best_axis = k;
        }
      }
    }
    if (best_axis < 0) return false;
    // Phase 3: compare with a leaf, C = Ct + Ci (A_L B_L + A_R B_R) / A in blocks B.
    const float area = surface_area(r.box);
    const float split_cost =
        m_config.traversal_cost + m_config.intersection_cost * (area > 0 ? best_cost / area : blocks(n));
    const float leaf_cost = m_config.intersection_cost * blocks(n);
    if (n <= uint32_t(m_config.max_leaf_size) && leaf_cost <= split_cost) return false;
    // Phase 4: partition in place by bin.
    const int k = best_axis;
    const float cmin = r.centroids.lo[k], s = scale[k];  // the axis's scale from phase 1
    partition(
        r, [&](const BvhBuildRef& ref) { return bin_index(ref.centroid()[k], cmin, s, nb) <= best_bin; },
        left, right);
    return left.end > r.begin && left.end < r.end;
  }

  /// Object median along the widest centroid axis: the fallback when SAH cannot separate the
  /// centroids (all equal) or the SAH depth limit is reached.
  void median_split(const Range& r, int& axis, Range& left, Range& right) {
    const Vec3f ext = r.centroids.extent();
    axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
    const uint32_t mid = r.begin + (r.end - r.begin) / 2;
    const int k = axis;
    const auto less = [k](const BvhBuildRef& a, const BvhBuildRef& b) {
      const float ca = a.centroid()[k], cb = b.centroid()[k];
      return ca < cb || (ca == cb && a.index < b.index);
    };
    std::nth_element(m_refs.begin() + r.begin, m_refs.begin() + mid, m_refs.begin() + r.end, less);
    left = {r.begin, mid, {}, {}};
    right = {mid, r.end, {}, {}};
    for (Range* side : {&left, &right})
      for (uint32_t i = side->begin; i < side->end; ++i) add(*side, m_refs[i]);
  }

  /// Hoare partition of `r` by `goes_left`, accumulating each side's box and centroid bounds.
  template <typename Pred>
  void partition(const Range& r, Pred goes_left, Range& left, Range& right) {
    SseBox box[2], cen[2];
    const auto add_to = [&](int side, const BvhBuildRef& ref) {
      const __m128 lo = ref_lo(ref), hi = ref_hi(ref);
      const __m128 c = _mm_mul_ps(_mm_add_ps(lo, hi), _mm_set1_ps(0.5f));
      box[side].grow(lo, hi);
      cen[side].grow(c, c);
    };
    uint32_t i = r.begin, j = r.end;
    for (;;) {
      while (i < j && goes_left(m_refs[i])) add_to(0, m_refs[i++]);
      while (i < j && !goes_left(m_refs[j - 1])) add_to(1, m_refs[--j]);
      if (i >= j) break;
      std::swap(m_refs[i], m_refs[j - 1]);
    }
    left = {r.begin, i, box[0].bounds(), cen[0].bounds()};
    right = {i, r.end, box[1].bounds(), cen[1].bounds()};
  }

  static int bin_index(float c, float cmin, float scale, int nb) {
    const int b = int((c - cmin) * scale);
    return std::clamp(b, 0, nb - 1);
  }

  const BvhConfig& m_config;
  std::vector<BvhBuildRef>& m_refs;
  int m_block;
};

}  // namespace

std::unique_ptr<BvhBuildNode> build_bvh_tree(std::vector<BvhBuildRef>& refs, const BvhConfig& config,
                                             int block) {
  Range root{0, uint32_t(refs.size()), {}, {}};
  for (const BvhBuildRef& ref : refs) add(root, ref);
  Builder builder(config, refs, block);
  return builder.build(root, 0);
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

}  // namespace penumbra
