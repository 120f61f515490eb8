// Octree. Regular 8-way subdivision of the scene box at each node's centre, each primitive
// referenced by the children its part inside the node meets (Sutherland-Hodgman clipping, as the
// kD-tree's perfect splits). Traversal: J. Revelles, C. Urena and M. Lastra, "An Efficient
// Parametric Algorithm for Octree Traversal", WSCG 2000: a child's t-interval is its parent's
// intersected, per axis, with the half-line before or after the mid-plane parameter
// tm_k = (mid_k - o_k) * (1 / d_k); children are visited in order of entry. Node layout after
// the kD-tree's (renderer/accel/kdtree.cpp).
#include "renderer/accel/octree.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/clip.h"
#include "renderer/accel/common.h"
#include "renderer/accel/stats.h"
#include "renderer/accel/tree_common.h"

namespace penumbra {
namespace {

constexpr int kMaxLeafPrimsLimit = 1024;
constexpr int kMaxDepthLimit = 20;
constexpr uint32_t kInterior = ~0u;  // OctNode::count of an interior node
// Each interior node on the path pushes at most 7 children; interior nodes lie above max_depth.
constexpr int kStackSize = 7 * kMaxDepthLimit + 1;
// An axis narrower than this many rounding bands is not split (see splits()).
constexpr float kMinSplitBands = 4;
// The SAH constants of the statistics: the kD-tree's defaults (K_T, K_I of Wald & Havran 2006).
constexpr double kTraversalCost = 15;
constexpr double kIntersectionCost = 20;

/// Flattened node, 8 bytes. The eight children of an interior node are adjacent (64 bytes), in
/// child order c = x + 2 y + 4 z, where a set bit means the upper half along that axis.
struct OctNode {
  uint32_t index;  // 4 bytes: interior: index of child 0; leaf: first of its records
  uint32_t count;  // 4 bytes: leaf: number of records (0: an empty leaf); interior: kInterior
  bool leaf() const { return count != kInterior; }
};
static_assert(sizeof(OctNode) == 8, "OctNode must stay 8 bytes");

// A leaf's count cannot be kInterior, so counts and indices stop one below it.
constexpr TreeFormat kFormat{"octree", kInterior - 1, "2^32 - 2"};

/// An interior node stores no split: its children halve its box at the centre.
struct NoSplit {};

/// The leaf and interior nodes flatten_tree() writes.
OctNode leaf_node(uint32_t first_record, uint32_t count) {
  return {first_record, count};
}

OctNode interior_node(uint32_t first_child, NoSplit) {
  return {first_child, kInterior};
}

// ---- Subdivision, shared by build and traversal ------------------------------------------------

/// The centre of [lo, hi] along one axis, as build and traversal both compute it: the halves
/// summed (no overflow at huge coordinates), clamped into [lo, hi].
inline float centre(float lo, float hi) {
  return std::clamp(0.5f * lo + 0.5f * hi, lo, hi);
}

/// An axis is split only if its centre lies strictly inside it and it is wider than
/// kMinSplitBands rounding bands (children are widened by one band on each side: a narrower
/// axis would give children as wide as their parent). Along an axis that is not split (a flat
/// box, one a float wide, or one within rounding of a point) the lower children span the whole
/// axis and the upper children are empty leaves.
inline bool splits(float lo, float mid, float hi, float band) {
  return lo < mid && mid < hi && hi - lo > kMinSplitBands * band;
}

/// Whether some axis of `box` is split (else its one child would be the box itself).
inline bool splits_any(const Bounds3f& box, float band) {
  for (int k = 0; k < 3; ++k)
    if (splits(box.lo[k], centre(box.lo[k], box.hi[k]), box.hi[k], band)) return true;
  return false;
}

/// Child c's range along one axis of a node spanning [lo, hi] with centre `mid`, where `upper`
/// is bit k of c; empty (lo > hi) for an upper child along an axis that is not split.
inline void child_range(float lo, float mid, float hi, float band, bool upper, float& child_lo,
                        float& child_hi) {
  if (!splits(lo, mid, hi, band)) {
    child_lo = upper ? kInfinity : lo;
    child_hi = upper ? -kInfinity : hi;
  } else {
    child_lo = upper ? mid : lo;
    child_hi = upper ? hi : mid;
  }
}

/// The box of child c of `box` (bit k of c: the upper half along axis k); empty for an upper
/// child along an axis that is not split.
Bounds3f child_box(const Bounds3f& box, float band, int c) {
  Bounds3f b;
  for (int k = 0; k < 3; ++k) {
    child_range(box.lo[k], centre(box.lo[k], box.hi[k]), box.hi[k], band, (c >> k) & 1, b.lo[k], b.hi[k]);
    if (b.lo[k] > b.hi[k]) return Bounds3f{};
  }
  return b;
}

// ---- Build ------------------------------------------------------------------------------------

/// child[c] is child c of the node (bit k of c: the upper half along axis k); a leaf's
/// primitives ascending.
using BuildNode = TreeBuildNode<8, NoSplit>;

class Builder {
 public:
  Builder(const OctreeConfig& c, const std::vector<PrimitiveRecord>& prims, float band)
      : m_config(c), m_prims(prims), m_band(band) {
    m_bounds.reserve(prims.size());
    for (const PrimitiveRecord& p : prims) m_bounds.push_back(primitive_bounds(p));
  }

  /// The subtree over primitives `ids` (ascending) in `box` at `depth`. Its shape depends on
  /// the input alone, never on scheduling.
  std::unique_ptr<BuildNode> build(std::vector<uint32_t> ids, const Bounds3f& box, int depth,
                                   double budget) const {
    auto node = std::make_unique<BuildNode>();
    node->area = surface_area(box);
    const size_t n = ids.size();
    if (n <= size_t(m_config.max_leaf_prims) || depth >= m_config.max_depth || !splits_any(box, m_band)) {
      node->prims = std::move(ids);
      return node;
    }
    // Phase 1: each child references the primitives whose part inside its box, widened by the
    // rounding band, is not empty.
    const Vec3f band{m_band, m_band, m_band};
    std::array<Bounds3f, 8> boxes, wide;
    for (int c = 0; c < 8; ++c) {
      boxes[c] = child_box(box, m_band, c);
      if (!boxes[c].empty()) wide[c] = {boxes[c].lo - band, boxes[c].hi + band};
    }
    std::array<std::vector<uint32_t>, 8> kids;
    for (const uint32_t id : ids)
      for (int c = 0; c < 8; ++c)
        if (!boxes[c].empty() && references(id, wide[c])) kids[c].push_back(id);
    // Phase 2: no progress (every child holds all of the primitives or none, and more than one
    // holds them all): a leaf. One full child is kept: it cuts off empty space.
    int full = 0;
    bool separated = false;
    for (int c = 0; c < 8; ++c) {
      full += kids[c].size() == n;
      separated = separated || (!kids[c].empty() && kids[c].size() < n);
    }
    if (!separated && full != 1) {
      node->prims = std::move(ids);
      return node;
    }
    // The reference budget: the references this split adds beyond the node's own must fit in
    // what the node was given; what is left passes to the children in proportion to their
    // counts (so the tree never depends on scheduling).
    size_t total = 0;
    for (const auto& k : kids) total += k.size();
    const double extra = double(total) - double(n);
    if (extra > budget) {
      node->prims = std::move(ids);
      return node;
    }
    const double left = budget - std::max(extra, 0.0);
    // Phase 3: recurse; large nodes build their children in parallel.
    std::vector<uint32_t>().swap(ids);
    node->leaf = false;
    const auto make_child = [&](int c) {
      const double share = total > 0 ? left * double(kids[c].size()) / double(total) : 0.0;
      node->child[size_t(c)] = build(std::move(kids[c]), boxes[c], depth + 1, share);
    };
    if (n >= m_config.parallel_threshold) {
      tbb::parallel_for(0, 8, make_child);
    } else {
      for (int c = 0; c < 8; ++c) make_child(c);
    }
    return node;
  }

 private:
  /// Whether clip_primitive_bounds(primitive id, box) is not empty. The bounding-box tests
  /// settle the cases clipping would (disjoint: nothing kept; contained: nothing clipped).
  bool references(uint32_t id, const Bounds3f& box) const {
    const Bounds3f& b = m_bounds[id];
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      if (b.hi[k] < box.lo[k] || b.lo[k] > box.hi[k]) return false;
      inside = inside && b.lo[k] >= box.lo[k] && b.hi[k] <= box.hi[k];
    }
    return inside || !clip_primitive_bounds(m_prims[id], box).empty();
  }

  const OctreeConfig& m_config;
  const std::vector<PrimitiveRecord>& m_prims;
  std::vector<Bounds3f> m_bounds;  // primitive_bounds of each primitive
  float m_band;                    // child boxes are widened by this before clipping
};

// ---- The accelerator ----------------------------------------------------------------------------

class OctreeAccelerator final : public TraversalAccelerator<OctreeAccelerator> {
  friend class TraversalAccelerator<OctreeAccelerator>;

 public:
  OctreeAccelerator(std::span<const GeometryView> views, const OctreeConfig& config) : m_config(config) {
    validate(config);
    build_tree(
        views, kFormat, {kTraversalCost, kIntersectionCost}, m_shapes, m_tree,
        [this](const std::vector<PrimitiveRecord>& prims) { return build_root(prims); }, leaf_node,
        interior_node);
  }

  Bounds3f bounds() const override { return m_tree.bounds; }

  TreeWalk walk() const {
    return walk_flat_tree<8>(m_tree, [](const OctNode& n) {
      return n.leaf() ? TreeNodeView{true, n.index, n.count} : TreeNodeView{false, n.index, 0};
    });
  }

  AccelStats stats() const override {
    return tree_stats(m_tree, kFormat,
                      "max_leaf_prims " + std::to_string(m_config.max_leaf_prims) + ", max_depth " +
                          std::to_string(m_config.max_depth) + ", reference_budget " +
                          format_number(m_config.reference_budget),
                      m_shapes.size());
  }

  /// Depth first from the root, whose box is m_tree.bounds; empty leaves are left out. A ball
  /// takes an interior node's children nearest first (distance2 to their boxes); each node is
  /// tested against the region when it is reached, so a radius shrunk meanwhile prunes the
  /// pushed ones.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (m_tree.nodes.empty()) return;
    RegionTodo todo[kStackSize];
    int sp = 0;
    RegionTodo cur{0,
                   {m_tree.bounds.lo.x, m_tree.bounds.lo.y, m_tree.bounds.lo.z},
                   {m_tree.bounds.hi.x, m_tree.bounds.hi.y, m_tree.bounds.hi.z}};
    for (;;) {
      if (region_meets(region, cur.box())) {
        const OctNode& node = m_tree.nodes[cur.node];
        if (cost) ++cost->nodes;
        if (node.leaf()) {
          const PrimitiveRecord* recs = m_tree.leaf_prims.data() + node.index;
          for (uint32_t i = 0; i < node.count; ++i)
            visitor.visit(recs[i].geom_id, record_prim_id(recs[i], m_shapes.data()), region);
        } else {
          RegionTodo kids[8];
          const int n = region_children(node, cur, region, kids);
          if (n > 0) {
            for (int i = n - 1; i >= 1; --i) todo[sp++] = kids[i];
            cur = kids[0];
            continue;
          }
        }
      }
      if (sp == 0) return;
      cur = todo[--sp];
    }
  }

 private:
  /// A node to visit: its index, the part [t0, t1] of the ray that may lie in it, and its box
  /// (plain arrays: the traversal stack is never initialised as a whole).
  struct Todo {
    uint32_t node;
    float t0, t1;
    float lo[3], hi[3];
  };

  /// A node of a region query and its box (plain arrays, as in Todo).
  struct RegionTodo {
    uint32_t node;
    float lo[3], hi[3];
    Bounds3f box() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
  };

  /// The build tree over `prims` (null if there are none).
  std::unique_ptr<BuildNode> build_root(const std::vector<PrimitiveRecord>& prims) const {
    if (prims.empty()) return nullptr;
    std::vector<uint32_t> all(prims.size());
    std::iota(all.begin(), all.end(), 0u);
    const Builder builder(m_config, prims, m_tree.band);
    const double budget = double(m_config.reference_budget) * double(prims.size());
    return builder.build(std::move(all), m_tree.bounds, 0, budget);
  }

  /// Front-to-back traversal with early exit: a node whose interval starts beyond `best`
  /// (narrowed by closest-hit visitors) is skipped. `visit(w, rec)` returns true to stop
  /// (any-hit). Returns true iff a visitor stopped it. Occlusion queries (AnyHit) take the same
  /// order.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    TreeRay r;
    if (!enter_tree(m_tree, ray, r)) return false;
    Todo todo[kStackSize];
    int sp = 0;
    Todo cur{0,
             r.t0,
             r.t1,
             {m_tree.bounds.lo.x, m_tree.bounds.lo.y, m_tree.bounds.lo.z},
             {m_tree.bounds.hi.x, m_tree.bounds.hi.y, m_tree.bounds.hi.z}};
    Mailbox mailbox;
    for (;;) {
      if (!(best < cur.t0)) {
        const OctNode& node = m_tree.nodes[cur.node];
        counter.node();
        if (node.leaf()) {
          if (visit_leaf(m_tree, node.index, node.count, r.w, mailbox, visit)) return true;
        } else {
          Todo kids[8];
          const int n = children(node, cur, r.q, best, kids);
          if (n > 0) {
            for (int i = n - 1; i >= 1; --i) todo[sp++] = kids[i];
            cur = kids[0];
            continue;
          }
        }
      }
      if (sp == 0) return false;
      cur = todo[--sp];
    }
  }

  /// The children of interior node `node` (interval and box in `cur`) that may hold part of the
  /// ray before `best`, written to `out` in order of entry distance (ties in child order);
  /// returns their number. Empty leaves are left out.
  ///
  /// Per axis k, the near side of the mid plane (below it for d_k > 0, above for d_k < 0) gets
  /// (-inf, tm_k] and the far side [tm_k, +inf), tm_k padded outward by kSlabPad as
  /// intersect_box pads; a child's interval is the node's intersected with its sides' along all
  /// three axes (Revelles et al. 2000). Conservative rules keep every hit brute force reports:
  /// an origin within the rounding band of the plane gives both sides (-inf, inf); a ray
  /// parallel to the plane (1/d_k infinite, as in intersect_box) gives the origin's side
  /// (-inf, inf) and the other nothing.
  int children(const OctNode& node, const Todo& cur, const RayBoxQuery& q, float best, Todo* out) const {
    float start[3][2], end[3][2], mid[3];
    for (int k = 0; k < 3; ++k) {
      const float lo = cur.lo[k], hi = cur.hi[k];
      mid[k] = centre(lo, hi);
      int only = -1;  // the one side the ray can be in, or -1 for both
      float t_exit = kInfinity, t_enter = -kInfinity;
      const float delta = mid[k] - q.org[k];
      const float tm = delta * q.inv_dir[k];
      if (!splits(lo, mid[k], hi, m_tree.band)) {
        only = 0;  // the lower children span the whole axis
      } else if (std::fabs(delta) <= m_tree.band) {
        only = -1;  // the origin lies on the plane, within rounding
      } else if (std::isinf(q.inv_dir[k]) || std::isnan(tm)) {
        only = delta < 0 ? 1 : 0;  // parallel to the plane: the origin's side
      } else {
        t_exit = tm > 0 ? tm * kSlabPad : tm * (2.0f - kSlabPad);   // the near side's end, padded up
        t_enter = tm > 0 ? tm * (2.0f - kSlabPad) : tm * kSlabPad;  // the far side's start, padded down
      }
      const int near = q.dir_neg[k];  // the upper side first for a negative direction
      if (only >= 0) {
        start[k][only] = -kInfinity;
        end[k][only] = kInfinity;
        start[k][1 - only] = kInfinity;
        end[k][1 - only] = -kInfinity;
      } else {
        start[k][near] = -kInfinity;
        end[k][near] = t_exit;
        start[k][1 - near] = t_enter;
        end[k][1 - near] = kInfinity;
      }
    }
    int n = 0;
    for (int c = 0; c < 8; ++c) {
      if (m_tree.nodes[node.index + c].count == 0) continue;  // an empty leaf
      float s = cur.t0, e = cur.t1;
      for (int k = 0; k < 3; ++k) {
        const int side = (c >> k) & 1;
        s = std::max(s, start[k][side]);
        e = std::min(e, end[k][side]);
      }
      if (s > e || best < s) continue;
      // Insertion by entry distance, after the children entered at the same distance.
      int i = n++;
      for (; i > 0 && out[i - 1].t0 > s; --i) out[i] = out[i - 1];
      out[i].node = node.index + uint32_t(c);
      out[i].t0 = s;
      out[i].t1 = e;
      for (int k = 0; k < 3; ++k)
        child_range(cur.lo[k], mid[k], cur.hi[k], m_tree.band, (c >> k) & 1, out[i].lo[k], out[i].hi[k]);
    }
    return n;
  }

  /// The children of interior node `node` (box in `cur`) that meet `region`, written to `out`:
  /// for a ball in order of distance2 from the centre to their boxes (ties in child order), for
  /// a box in child order; returns their number. Empty leaves are left out.
  int region_children(const OctNode& node, const RegionTodo& cur, const QueryRegion& region,
                      RegionTodo* out) const {
    float mid[3];
    for (int k = 0; k < 3; ++k) mid[k] = centre(cur.lo[k], cur.hi[k]);
    float key[8];
    int n = 0;
    for (int c = 0; c < 8; ++c) {
      if (m_tree.nodes[node.index + c].count == 0) continue;  // an empty leaf
      RegionTodo kid;
      kid.node = node.index + uint32_t(c);
      for (int k = 0; k < 3; ++k)
        child_range(cur.lo[k], mid[k], cur.hi[k], m_tree.band, (c >> k) & 1, kid.lo[k], kid.hi[k]);
      const Bounds3f b = kid.box();
      if (!region_meets(region, b)) continue;
      const float d2 = region.is_box ? 0.0f : distance2(region.centre, b);
      // Insertion by distance, after the children at the same distance.
      int i = n++;
      for (; i > 0 && key[i - 1] > d2; --i) {
        out[i] = out[i - 1];
        key[i] = key[i - 1];
      }
      out[i] = kid;
      key[i] = d2;
    }
    return n;
  }

  OctreeConfig m_config;
  // Children in blocks of 8; m_tree.bounds is the root's box. Origins within m_tree.band of a mid
  // plane count as on it, and child boxes are widened by it before clipping.
  FlatTree<OctNode> m_tree;
};

}  // namespace

void validate(const OctreeConfig& c) {
  if (c.max_leaf_prims < 1 || c.max_leaf_prims > kMaxLeafPrimsLimit)
    throw std::invalid_argument("octree: max_leaf_prims must be in [1, 1024], got " +
                                std::to_string(c.max_leaf_prims));
  if (c.max_depth < 1 || c.max_depth > kMaxDepthLimit)
    throw std::invalid_argument("octree: max_depth must be in [1, 20], got " + std::to_string(c.max_depth));
  if (!(c.reference_budget >= 0 && c.reference_budget <= 64))
    throw std::invalid_argument("octree: reference_budget must be in [0, 64], got " +
                                format_number(c.reference_budget));
}

std::unique_ptr<Accelerator> make_octree_accelerator(std::span<const GeometryView> views,
                                                     const OctreeConfig& config) {
  return std::make_unique<OctreeAccelerator>(views, config);
}

std::optional<TreeWalk> walk_octree(const Accelerator& accel) {
  const auto* oct = dynamic_cast<const OctreeAccelerator*>(&accel);
  return oct ? std::optional(oct->walk()) : std::nullopt;
}

}  // namespace penumbra
