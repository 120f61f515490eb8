// Binned-SAH BVH build: I. Wald, "On fast Construction of SAH-based Bounding Volume
// Hierarchies", IEEE Symposium on Interactive Ray Tracing 2007. One pass over a node's
// references bins their centroids along all three axes at once; the chosen split partitions
// them in place while accumulating both children's boxes and centroid bounds, so each level
// reads every reference twice. Subtrees above a size threshold build in parallel TBB tasks.
// The flattening into binary nodes follows pbrt-v4's LinearBVHNode (Pharr, Jakob & Humphreys,
// 4th ed., sec. 7.3).
#include "renderer/accel/bvh_build.h"

#include <emmintrin.h>
#include <tbb/concurrent_vector.h>
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

/// The best binned object split of a node (Wald 2007): its unnormalised SAH cost (areas times
/// blocks; infinite if the centroids cannot be separated), the plane as a bin of the centroid
/// binning, and the children's boxes.
struct ObjectSplit {
  float cost = kInfinity;
  int axis = -1, bin = -1, nb = 0;
  float cmin = 0, scale = 0;  ///< bin of centroid c along axis: bin_index(c, cmin, scale, nb)
  Bounds3f left, right;
};

int bin_index(float c, float cmin, float scale, int nb) {
  const int b = int((c - cmin) * scale);
  return std::clamp(b, 0, nb - 1);
}

/// Leaf blocks of n primitives: the unit of the intersection cost.
float blocks(uint32_t n, int block) {
  return float((n + uint32_t(block) - 1) / uint32_t(block));
}

/// Bins the centroids of refs[r.begin, r.end) along all three axes in one pass and sweeps the
/// planes between bins for the cheapest split.
ObjectSplit best_object_split(const BvhBuildRef* refs, const Range& r, int bin_count, int block) {
  const uint32_t n = r.end - r.begin;
  // No more bins than references: small nodes, the most numerous, stay cheap to bin.
  const int nb = int(std::min<uint32_t>(uint32_t(bin_count), std::max(n, 2u)));
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
      bin_ref(0, refs[i]);
      bin_ref(1, refs[i + 1]);
    }
    for (int k = 0; k < 3; ++k)
      for (int b = 0; b < nb; ++b) {
        bins.box[0][k][b].merge_with(bins.box[1][k][b]);
        bins.count[0][k][b] += bins.count[1][k][b];
      }
  }
  for (; i < r.end; ++i) bin_ref(0, refs[i]);
  // Phase 2: per axis, sweep from the right, then from the left, over the nb - 1 planes.
  ObjectSplit best;
  best.nb = nb;
  std::array<float, 256> right_cost;
  std::array<SseBox, 256> right_box;
  for (int k = 0; k < 3; ++k) {
    if (!(ext[k] > 0)) continue;
    SseBox acc;
    uint32_t cnt = 0;
    for (int b = nb - 1; b > 0; --b) {
      acc.merge_with(bins.box[0][k][b]);
      cnt += bins.count[0][k][b];
      right_cost[b] = cnt ? acc.area() * blocks(cnt, block) : -1.0f;
      right_box[b] = acc;
    }
    acc = SseBox{};
    cnt = 0;
    for (int b = 0; b < nb - 1; ++b) {
      acc.merge_with(bins.box[0][k][b]);
      cnt += bins.count[0][k][b];
      if (cnt == 0 || right_cost[b + 1] < 0) continue;
      const float cost = acc.area() * blocks(cnt, block) + right_cost[b + 1];
      if (cost < best.cost) {
        best.cost = cost;
        best.bin = b;
        best.axis = k;
        best.left = acc.bounds();
        best.right = right_box[b + 1].bounds();
      }
    }
  }
  if (best.axis >= 0) {
    best.cmin = r.centroids.lo[best.axis];
    best.scale = scale[best.axis];
  }
  return best;
}

/// SAH of a split of unnormalised cost `cost` of a node of box area `area` and n references,
/// C = Ct + Ci (A_L B_L + A_R B_R) / A in blocks B, and of a leaf, C = Ci B.
float split_cost(const BvhConfig& c, float cost, float area, uint32_t n, int block) {
  return c.traversal_cost + c.intersection_cost * (area > 0 ? cost / area : blocks(n, block));
}
float leaf_cost(const BvhConfig& c, uint32_t n, int block) {
  return c.intersection_cost * blocks(n, block);
}

/// Hoare partition of refs[r.begin, r.end) by `goes_left`, accumulating each side's box and
/// centroid bounds.
template <typename Pred>
void partition(BvhBuildRef* refs, const Range& r, Pred goes_left, Range& left, Range& right) {
  SseBox box[2], cen[2];
  const auto add_to = [&](int side, const BvhBuildRef& ref) {
    const __m128 lo = ref_lo(ref), hi = ref_hi(ref);
    const __m128 c = _mm_mul_ps(_mm_add_ps(lo, hi), _mm_set1_ps(0.5f));
    box[side].grow(lo, hi);
    cen[side].grow(c, c);
  };
  uint32_t i = r.begin, j = r.end;
  for (;;) {
    while (i < j && goes_left(refs[i])) add_to(0, refs[i++]);
    while (i < j && !goes_left(refs[j - 1])) add_to(1, refs[--j]);
    if (i >= j) break;
    std::swap(refs[i], refs[j - 1]);
  }
  left = {r.begin, i, box[0].bounds(), cen[0].bounds()};
  right = {i, r.end, box[1].bounds(), cen[1].bounds()};
}

/// Partitions `r` by the object split `s`; true iff both sides are non-empty.
bool apply_object_split(BvhBuildRef* refs, const Range& r, const ObjectSplit& s, Range& left, Range& right) {
  const int k = s.axis;
  partition(
      refs, r,
      [&](const BvhBuildRef& ref) { return bin_index(ref.centroid()[k], s.cmin, s.scale, s.nb) <= s.bin; },
      left, right);
  return left.end > r.begin && left.end < r.end;
}

/// Object median along the widest centroid axis: the fallback when SAH cannot separate the
/// centroids (all equal) or the SAH depth limit is reached.
void median_split(BvhBuildRef* refs, const Range& r, int& axis, Range& left, Range& right) {
  const Vec3f ext = r.centroids.extent();
  axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
  const uint32_t mid = r.begin + (r.end - r.begin) / 2;
  const int k = axis;
  const auto less = [k](const BvhBuildRef& a, const BvhBuildRef& b) {
    const float ca = a.centroid()[k], cb = b.centroid()[k];
    return ca < cb || (ca == cb && a.index < b.index);
  };
  std::nth_element(refs + r.begin, refs + mid, refs + r.end, less);
  left = {r.begin, mid, {}, {}};
  right = {mid, r.end, {}, {}};
  for (Range* side : {&left, &right})
    for (uint32_t i = side->begin; i < side->end; ++i) add(*side, refs[i]);
}

std::unique_ptr<BvhBuildNode> make_leaf(std::unique_ptr<BvhBuildNode> node, uint32_t begin, uint32_t n) {
  node->first = begin;
  node->count = n;
  return node;
}

/// The object-split builder: every node is a range of the one reference array, partitioned in
/// place.
class Builder {
 public:
  Builder(const BvhConfig& c, std::vector<BvhBuildRef>& refs, int block)
      : m_config(c), m_refs(refs.data()), m_block(block) {}

  std::unique_ptr<BvhBuildNode> build(const Range& r, int depth) {
    auto node = std::make_unique<BvhBuildNode>();
    node->box = r.box;
    const uint32_t n = r.end - r.begin;
    if (n <= 1) return make_leaf(std::move(node), r.begin, n);
    Range left, right;
    int axis = 0;
    if (!(depth < kMaxSahDepth && find_sah_split(r, axis, left, right))) {
      if (n <= uint32_t(m_config.max_leaf_size)) return make_leaf(std::move(node), r.begin, n);
      median_split(m_refs, r, axis, left, right);
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
  /// Returns true and partitions `r` into `left` and `right` if the best binned split is
  /// cheaper than a leaf (or the node is too big to be one).
  bool find_sah_split(const Range& r, int& axis, Range& left, Range& right) {
    const uint32_t n = r.end - r.begin;
    const ObjectSplit s = best_object_split(m_refs, r, m_config.bin_count, m_block);
    if (s.axis < 0) return false;
    if (n <= uint32_t(m_config.max_leaf_size) &&
        leaf_cost(m_config, n, m_block) <= split_cost(m_config, s.cost, surface_area(r.box), n, m_block))
      return false;
    axis = s.axis;
    return apply_object_split(m_refs, r, s, left, right);
  }

  const BvhConfig& m_config;
  BvhBuildRef* m_refs;
  int m_block;
};

/// A spatial split (Stich et al. 2009): the plane at `pos` along `axis`, and the references
/// each side gets (those crossing it go to both).
struct SpatialSplit {
  float cost = kInfinity;  ///< unnormalised SAH: areas times blocks
  int axis = -1;
  int bin = -1;  ///< the plane lies between spatial bins `bin` and `bin + 1`
};

/// Spatial bins of a node's box along one axis: nb equal slabs.
struct Slabs {
  float lo = 0, width = 0, inv = 0;
  int nb = 0;
  int bin(float x) const { return std::clamp(int((x - lo) * inv), 0, nb - 1); }
  float plane(int b) const { return lo + width * float(b + 1); }  ///< between bins b and b + 1
};

Slabs make_slabs(const Bounds3f& box, int axis, int nb) {
  const float ext = box.hi[axis] - box.lo[axis];
  return {box.lo[axis], ext / float(nb), float(nb) / ext, nb};
}

/// Builds with object and spatial splits (Stich, Friedrich & Dietrich, "Spatial Splits in
/// Bounding Volume Hierarchies", HPG 2009). A node whose best object split leaves children
/// overlapping by more than alpha of the root's area also bins its references spatially: each
/// is cut at the slab planes it crosses (by the clipper, so boxes follow the triangle, not its
/// box), and the cheapest plane may put a reference's two parts in both children. Each node
/// owns its references and may duplicate up to its share of the budget, which the children
/// split by their counts, so the tree never depends on scheduling. A subtree that cannot
/// duplicate any more is built in place by the object builder. Until gather(), a leaf's
/// references are refs [first, first + count) of chunk `axis`.
class SpatialBuilder {
 public:
  SpatialBuilder(const BvhConfig& c, int block, const ReferenceClipper& clip, float root_area)
      : m_config(c), m_block(block), m_clip(clip), m_min_overlap(c.spatial_alpha * root_area) {}

  std::unique_ptr<BvhBuildNode> build(std::vector<BvhBuildRef> refs, const Range& r, int depth,
                                      double budget) {
    const uint32_t n = uint32_t(refs.size());
    if (budget < 1 || n <= 1) return build_in_place(std::move(refs), r, depth);
    auto node = std::make_unique<BvhBuildNode>();
    node->box = r.box;
    const ObjectSplit os =
        depth < kMaxSahDepth ? best_object_split(refs.data(), r, m_config.bin_count, m_block) : ObjectSplit{};
    SpatialSplit ss;
    if (depth < kMaxSahDepth && (os.axis < 0 || surface_area(intersect(os.left, os.right)) > m_min_overlap))
      ss = best_spatial_split(refs, r.box, uint32_t(std::min<double>(budget, UINT32_MAX)));
    const float cost = std::min(os.cost, ss.cost);
    const float area = surface_area(r.box);
    const bool fits = n <= uint32_t(m_config.max_leaf_size);
    if (fits && (cost == kInfinity ||
                 leaf_cost(m_config, n, m_block) <= split_cost(m_config, cost, area, n, m_block)))
      return leaf(std::move(node), std::move(refs));
    std::vector<BvhBuildRef> lv, rv;
    Range left, right;
    if (!(ss.cost < os.cost && apply_spatial_split(refs, r.box, ss, lv, rv, left, right))) {
      if (os.axis >= 0 && apply_object_split(refs.data(), r, os, left, right)) {
        node->axis = os.axis;
      } else if (fits) {
        return leaf(std::move(node), std::move(refs));
      } else {
        median_split(refs.data(), r, node->axis, left, right);
      }
      lv.assign(refs.begin() + left.begin, refs.begin() + left.end);
      rv.assign(refs.begin() + right.begin, refs.begin() + right.end);
      right = {0, right.end - right.begin, right.box, right.centroids};
    } else {
      node->axis = ss.axis;
    }
    refs = {};  // the children own their references now
    const double nl = double(lv.size()), nr = double(rv.size());
    const double spare = std::max(0.0, budget - (nl + nr - n));
    const double bl = spare * nl / (nl + nr), br = spare - bl;
    if (n >= m_config.parallel_threshold) {
      tbb::parallel_invoke([&] { node->child[0] = build(std::move(lv), left, depth + 1, bl); },
                           [&] { node->child[1] = build(std::move(rv), right, depth + 1, br); });
    } else {
      node->child[0] = build(std::move(lv), left, depth + 1, bl);
      node->child[1] = build(std::move(rv), right, depth + 1, br);
    }
    return node;
  }

  /// Concatenates the leaves' references into `out` depth first and points each leaf there.
  void gather(BvhBuildNode& b, std::vector<BvhBuildRef>& out) const {
    if (b.child[0]) {
      gather(*b.child[0], out);
      gather(*b.child[1], out);
      return;
    }
    const std::vector<BvhBuildRef>& chunk = m_chunks[size_t(b.axis)];
    const uint32_t first = uint32_t(out.size());
    out.insert(out.end(), chunk.begin() + b.first, chunk.begin() + b.first + b.count);
    b.first = first;
    b.axis = 0;
  }

 private:
  std::unique_ptr<BvhBuildNode> leaf(std::unique_ptr<BvhBuildNode> node, std::vector<BvhBuildRef> refs) {
    node->count = uint32_t(refs.size());
    node->axis = store(std::move(refs));
    return node;
  }

  int store(std::vector<BvhBuildRef> refs) {
    return int(m_chunks.push_back(std::move(refs)) - m_chunks.begin());
  }

  /// The object builder over a node's own references; its leaves are tagged with their chunk.
  std::unique_ptr<BvhBuildNode> build_in_place(std::vector<BvhBuildRef> refs, const Range& r, int depth) {
    Builder builder(m_config, refs, m_block);
    auto root = builder.build(r, depth);
    tag(*root, store(std::move(refs)));
    return root;
  }

  static void tag(BvhBuildNode& b, int chunk) {
    if (!b.child[0]) {
      b.axis = chunk;
      return;
    }
    tag(*b.child[0], chunk);
    tag(*b.child[1], chunk);
  }

  /// Slabs per axis of the spatial binning: the configured bins, at most 64.
  int spatial_bins() const { return std::min(m_config.bin_count, 64); }

  /// Bins the references spatially along each axis, cutting each at the slab planes it
  /// crosses, and sweeps for the cheapest plane that duplicates at most `budget` references.
  SpatialSplit best_spatial_split(const std::vector<BvhBuildRef>& refs, const Bounds3f& box,
                                  uint32_t budget) const {
    const int nb = spatial_bins();
    const uint32_t n = uint32_t(refs.size());
    SpatialSplit best;
    std::array<Bounds3f, 64> bin_box, right_box;
    std::array<uint32_t, 64> enter, exit, right_count;
    for (int k = 0; k < 3; ++k) {
      if (!(box.hi[k] > box.lo[k])) continue;
      const Slabs slabs = make_slabs(box, k, nb);
      bin_box.fill({});
      enter.fill(0);
      exit.fill(0);
      for (const BvhBuildRef& ref : refs) {
        const int b0 = slabs.bin(ref.lo[k]), b1 = slabs.bin(ref.hi[k]);
        BvhBuildRef cur = ref;
        for (int b = b0; b < b1; ++b) {
          Bounds3f l, rr;
          m_clip(cur, k, slabs.plane(b), l, rr);
          bin_box[size_t(b)] = merge(bin_box[size_t(b)], l);
          cur.lo = rr.lo, cur.hi = rr.hi;
        }
        bin_box[size_t(b1)] = merge(bin_box[size_t(b1)], cur.box());
        ++enter[size_t(b0)];
        ++exit[size_t(b1)];
      }
      Bounds3f acc;
      uint32_t cnt = 0;
      for (int b = nb - 1; b > 0; --b) {
        acc = merge(acc, bin_box[size_t(b)]);
        cnt += exit[size_t(b)];
        right_box[size_t(b)] = acc;
        right_count[size_t(b)] = cnt;
      }
      acc = {};
      cnt = 0;
      for (int b = 0; b < nb - 1; ++b) {
        acc = merge(acc, bin_box[size_t(b)]);
        cnt += enter[size_t(b)];
        const uint32_t rc = right_count[size_t(b + 1)];
        if (cnt == 0 || rc == 0 || cnt + rc - n > budget) continue;
        const float cost = surface_area(acc) * blocks(cnt, m_block) +
                           surface_area(right_box[size_t(b + 1)]) * blocks(rc, m_block);
        if (cost < best.cost) best = {cost, k, b};
      }
    }
    return best;
  }

  /// Distributes the references by the spatial split `s`, cutting those that cross its plane;
  /// false (outputs unspecified) if a side would be empty.
  bool apply_spatial_split(const std::vector<BvhBuildRef>& refs, const Bounds3f& box, const SpatialSplit& s,
                           std::vector<BvhBuildRef>& lv, std::vector<BvhBuildRef>& rv, Range& left,
                           Range& right) const {
    const int k = s.axis;
    const Slabs slabs = make_slabs(box, k, spatial_bins());
    const float pos = slabs.plane(s.bin);
    for (const BvhBuildRef& ref : refs) {
      if (slabs.bin(ref.hi[k]) <= s.bin) {
        lv.push_back(ref);
      } else if (slabs.bin(ref.lo[k]) > s.bin) {
        rv.push_back(ref);
      } else {
        Bounds3f l, r;
        m_clip(ref, k, pos, l, r);
        if (!l.empty()) lv.push_back(BvhBuildRef(l, ref.index));
        if (!r.empty()) rv.push_back(BvhBuildRef(r, ref.index));
      }
    }
    if (lv.empty() || rv.empty()) return false;
    left = {0, uint32_t(lv.size()), {}, {}};
    right = {0, uint32_t(rv.size()), {}, {}};
    for (const BvhBuildRef& ref : lv) add(left, ref);
    for (const BvhBuildRef& ref : rv) add(right, ref);
    return true;
  }

  const BvhConfig& m_config;
  int m_block;
  const ReferenceClipper& m_clip;
  float m_min_overlap;
  tbb::concurrent_vector<std::vector<BvhBuildRef>> m_chunks;
};

}  // namespace

std::unique_ptr<BvhBuildNode> build_bvh_tree(std::vector<BvhBuildRef>& refs, const BvhConfig& config,
                                             int block, const ReferenceClipper* clip) {
  Range root{0, uint32_t(refs.size()), {}, {}};
  for (const BvhBuildRef& ref : refs) add(root, ref);
  if (clip && config.spatial_alpha > 0) {
    SpatialBuilder builder(config, block, *clip, surface_area(root.box));
    const double budget = double(config.spatial_budget) * double(refs.size());
    auto tree = builder.build(std::move(refs), root, 0, budget);
    refs.clear();
    builder.gather(*tree, refs);
    return tree;
  }
  Builder builder(config, refs, block);
  return builder.build(root, 0);
}

namespace {
void release_subtree(std::unique_ptr<BvhBuildNode> node, int depth) {
  if (node && node->child[0] && depth < 10)
    tbb::parallel_invoke([&] { release_subtree(std::move(node->child[0]), depth + 1); },
                         [&] { release_subtree(std::move(node->child[1]), depth + 1); });
}
}  // namespace

void release_bvh_tree(std::unique_ptr<BvhBuildNode> root) {
  release_subtree(std::move(root), 0);
}

void split_triangle_bounds(const Vec3f v[3], const Bounds3f& box, int axis, float pos, Bounds3f& left,
                           Bounds3f& right) {
  left = right = Bounds3f{};
  for (int i = 0; i < 3; ++i) {
    const Vec3f a = v[i], b = v[(i + 1) % 3];
    if (a[axis] <= pos) left = merge(left, a);
    if (a[axis] >= pos) right = merge(right, a);
    if ((a[axis] < pos && b[axis] > pos) || (a[axis] > pos && b[axis] < pos)) {
      // The crossing, padded on the other axes by a bound on its rounding error (a few ulps of
      // the vertices' magnitude): the boxes must contain the exact crossing, and a big
      // triangle's error can exceed the margin traversal adds to a small node's box.
      Vec3f p = a + (b - a) * ((pos - a[axis]) / (b[axis] - a[axis]));
      p[axis] = pos;
      Vec3f e = (abs(a) + abs(b)) * 0x1p-20f;
      e[axis] = 0;
      for (const Vec3f q : {p - e, p + e}) {
        left = merge(left, q);
        right = merge(right, q);
      }
    }
  }
  left = intersect(left, box);
  right = intersect(right, box);
  left.hi[axis] = std::min(left.hi[axis], pos);
  right.lo[axis] = std::max(right.lo[axis], pos);
}

void split_box_bounds(const Bounds3f& box, int axis, float pos, Bounds3f& left, Bounds3f& right) {
  left = right = box;
  left.hi[axis] = std::min(left.hi[axis], pos);
  right.lo[axis] = std::max(right.lo[axis], pos);
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
