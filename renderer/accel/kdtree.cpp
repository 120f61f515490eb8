// SAH kD-tree. Build: I. Wald and V. Havran, "On building fast kd-Trees for Ray Tracing, and on
// doing that in O(N log N)", IEEE Symposium on Interactive Ray Tracing 2006 (events sorted once,
// split lists kept sorted, straddling triangles clipped to the child boxes: "perfect splits").
// Node layout and traversal after pbrt-v3's KdTreeAccel (Pharr, Jakob & Humphreys, 3rd ed.,
// sec. 4.4).
#include "renderer/accel/kdtree.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/clip.h"
#include "renderer/accel/common.h"
#include "renderer/accel/stats.h"
#include "renderer/accel/tree_common.h"

namespace penumbra {
namespace {

/// Flattened node, 8 bytes. The two children of an interior node are adjacent (below, then
/// above), so the far child usually shares the near child's cache line (Wald, "Realtime Ray
/// Tracing and Interactive Global Illumination", PhD thesis, 2004, sec. 7.3).
struct KdNode {
  union {
    float split;           // 4 bytes: interior: split position along `axis`
    uint32_t prim_offset;  //          leaf: first of its records in the leaf record array
  };
  uint32_t flags;  // 4 bytes: low 2 bits: 0/1/2 = split axis, 3 = leaf;
                   //          high 30 bits: interior: index of the below child (the above child
                   //          follows it); leaf: count
  bool leaf() const { return (flags & 3u) == 3u; }
  int axis() const { return int(flags & 3u); }
  uint32_t count() const { return flags >> 2; }
  uint32_t below() const { return flags >> 2; }
};
static_assert(sizeof(KdNode) == 8, "KdNode must stay 8 bytes");

constexpr int kMaxDepth = 64;
// Node and count fields are 30 bits.
constexpr TreeFormat kFormat{"kdtree", (1u << 30) - 1, "2^30 - 1"};

/// An interior node's plane: x[axis] = pos.
struct KdSplit {
  float pos = 0;
  int axis = 0;
};

/// The leaf and interior nodes flatten_tree() writes.
KdNode leaf_node(uint32_t first_record, uint32_t count) {
  KdNode n{};
  n.prim_offset = first_record;
  n.flags = (count << 2) | 3u;
  return n;
}

KdNode interior_node(uint32_t below, const KdSplit& s) {
  KdNode n{};
  n.split = s.pos;
  n.flags = (below << 2) | uint32_t(s.axis);
  return n;
}

// ---- Build-time types -------------------------------------------------------------------------

enum EventType : uint8_t { kEnd = 0, kPlanar = 1, kStart = 2 };

struct Event {
  float pos;
  uint32_t tri;
  uint8_t axis;
  uint8_t type;
};

/// Sort order of the event lists: axis, position, type (end < planar < start), triangle.
bool operator<(const Event& a, const Event& b) {
  if (a.axis != b.axis) return a.axis < b.axis;
  if (a.pos != b.pos) return a.pos < b.pos;
  if (a.type != b.type) return a.type < b.type;
  return a.tri < b.tri;
}

void add_events(std::vector<Event>& out, uint32_t tri, const Bounds3f& b) {
  for (uint8_t k = 0; k < 3; ++k) {
    if (b.lo[k] == b.hi[k]) {
      out.push_back({b.lo[k], tri, k, kPlanar});
    } else {
      out.push_back({b.lo[k], tri, k, kStart});
      out.push_back({b.hi[k], tri, k, kEnd});
    }
  }
}

/// child[0] below the plane, child[1] above it; a leaf's triangles ascending.
using BuildNode = TreeBuildNode<2, KdSplit>;

class Builder {
 public:
  Builder(const KdTreeConfig& c, const std::vector<PrimitiveRecord>& tris, int max_depth)
      : m_config(c), m_tris(tris), m_max_depth(max_depth) {}

  std::unique_ptr<BuildNode> build(std::vector<Event> events, uint32_t n, const Bounds3f& box, int depth) {
    auto node = std::make_unique<BuildNode>();
    node->area = surface_area(box);
    // Phase 1: find the cheapest plane by sweeping the sorted events (Wald & Havran, alg. 4).
    Split best;
    if (depth < m_max_depth && n > 0 && surface_area(box) > 0) best = find_plane(events, n, box);
    if (best.axis < 0 || best.cost >= m_config.intersection_cost * float(n)) {
      make_leaf(*node, events);
      return node;
    }
    // Phase 2: classify triangles as left only, right only or both (alg. 5).
    auto& cls = m_classes.local();
    if (cls.size() < m_tris.size()) cls.resize(m_tris.size());
    for (const Event& e : events) cls[e.tri] = kBoth;
    for (const Event& e : events) {
      if (e.axis != best.axis) continue;
      if (e.type == kEnd && e.pos <= best.pos)
        cls[e.tri] = kLeftOnly;
      else if (e.type == kStart && e.pos >= best.pos)
        cls[e.tri] = kRightOnly;
      else if (e.type == kPlanar) {
        if (e.pos < best.pos || (e.pos == best.pos && best.planar_left)) cls[e.tri] = kLeftOnly;
        if (e.pos > best.pos || (e.pos == best.pos && !best.planar_left)) cls[e.tri] = kRightOnly;
      }
    }
    // Phase 3: split the event list; the one-sided events stay sorted.
    Bounds3f lbox = box, rbox = box;
    lbox.hi[best.axis] = best.pos;
    rbox.lo[best.axis] = best.pos;
    std::vector<Event> left, right, left_new, right_new;
    uint32_t nl = 0, nr = 0;
    for (const Event& e : events) {
      const bool first = e.axis == 0 && e.type != kEnd;  // exactly one per triangle
      if (cls[e.tri] == kLeftOnly) {
        left.push_back(e);
        nl += first;
      } else if (cls[e.tri] == kRightOnly) {
        right.push_back(e);
        nr += first;
      } else if (first) {
        // Straddling triangle: clip it to each child box (perfect splits, sec. 4.3).
        const Bounds3f lb = clip_primitive_bounds(m_tris[e.tri], lbox),
                       rb = clip_primitive_bounds(m_tris[e.tri], rbox);
        if (!lb.empty()) {
          add_events(left_new, e.tri, lb);
          ++nl;
        }
        if (!rb.empty()) {
          add_events(right_new, e.tri, rb);
          ++nr;
        }
      }
    }
    std::vector<Event>().swap(events);
    std::sort(left_new.begin(), left_new.end());
    std::sort(right_new.begin(), right_new.end());
    left = merge_sorted(std::move(left), left_new);
    right = merge_sorted(std::move(right), right_new);
    node->leaf = false;
    node->split = {best.pos, best.axis};
    // Phase 4: recurse; large nodes build their children in parallel. The tree's shape never
    // depends on scheduling.
    if (n >= m_config.parallel_threshold) {
      tbb::parallel_invoke([&] { node->child[0] = build(std::move(left), nl, lbox, depth + 1); },
                           [&] { node->child[1] = build(std::move(right), nr, rbox, depth + 1); });
    } else {
      node->child[0] = build(std::move(left), nl, lbox, depth + 1);
      node->child[1] = build(std::move(right), nr, rbox, depth + 1);
    }
    return node;
  }

 private:
  enum Class : uint8_t { kBoth = 0, kLeftOnly = 1, kRightOnly = 2 };

  struct Split {
    int axis = -1;
    float pos = 0;
    float cost = kInfinity;
    bool planar_left = true;
  };

  float sah(float pl, float pr, uint32_t nl, uint32_t nr) const {
    const float lambda = (nl == 0 || nr == 0) ? 1.0f - m_config.empty_bonus : 1.0f;
    return lambda *
           (m_config.traversal_cost + m_config.intersection_cost * (pl * float(nl) + pr * float(nr)));
  }

  Split find_plane(const std::vector<Event>& ev, uint32_t n, const Bounds3f& box) const {
    Split best;
    const float inv_area = 1.0f / surface_area(box);
    const Vec3f d = box.extent();
    uint32_t nl[3] = {0, 0, 0}, np[3] = {0, 0, 0}, nr[3] = {n, n, n};
    for (size_t i = 0; i < ev.size();) {
      const int k = ev[i].axis;
      const float p = ev[i].pos;
      uint32_t ends = 0, planars = 0, starts = 0;
      while (i < ev.size() && ev[i].axis == k && ev[i].pos == p && ev[i].type == kEnd) ++ends, ++i;
      while (i < ev.size() && ev[i].axis == k && ev[i].pos == p && ev[i].type == kPlanar) ++planars, ++i;
      while (i < ev.size() && ev[i].axis == k && ev[i].pos == p && ev[i].type == kStart) ++starts, ++i;
      np[k] = planars;
      nr[k] -= planars + ends;
      // Only planes strictly inside the box: a split on a face cuts off nothing.
      if (p > box.lo[k] && p < box.hi[k]) {
        const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;
        const float cap = d[k1] * d[k2];
        const float pl = 2 * (cap + (p - box.lo[k]) * (d[k1] + d[k2])) * inv_area;
        const float pr = 2 * (cap + (box.hi[k] - p) * (d[k1] + d[k2])) * inv_area;
        const float cl = sah(pl, pr, nl[k] + np[k], nr[k]);
        const float cr = sah(pl, pr, nl[k], nr[k] + np[k]);
        if (cl < best.cost) best = {k, p, cl, true};
        if (cr < best.cost) best = {k, p, cr, false};
      }
      nl[k] += starts + planars;
      np[k] = 0;
    }
    return best;
  }

  static void make_leaf(BuildNode& node, const std::vector<Event>& events) {
    for (const Event& e : events)
      if (e.axis == 0 && e.type != kEnd) node.prims.push_back(e.tri);
    std::sort(node.prims.begin(), node.prims.end());
  }

  static std::vector<Event> merge_sorted(std::vector<Event> a, const std::vector<Event>& b) {
    if (b.empty()) return a;
    std::vector<Event> out(a.size() + b.size());
    std::merge(a.begin(), a.end(), b.begin(), b.end(), out.begin());
    return out;
  }

  const KdTreeConfig& m_config;
  const std::vector<PrimitiveRecord>& m_tris;
  int m_max_depth;
  tbb::enumerable_thread_specific<std::vector<uint8_t>> m_classes;
};

// ---- The accelerator ----------------------------------------------------------------------------

class KdTreeAccelerator final : public TraversalAccelerator<KdTreeAccelerator> {
  friend class TraversalAccelerator<KdTreeAccelerator>;

 public:
  KdTreeAccelerator(std::span<const GeometryView> meshes, const KdTreeConfig& config) : m_config(config) {
    validate(config);
    build_tree(
        meshes, kFormat, {config.traversal_cost, config.intersection_cost}, m_shapes, m_tree,
        [this](const std::vector<PrimitiveRecord>& prims) { return build_root(prims); }, leaf_node,
        interior_node);
  }

  Bounds3f bounds() const override { return m_tree.bounds; }

  TreeWalk walk() const {
    return walk_flat_tree<2>(m_tree, [](const KdNode& n) {
      return n.leaf() ? TreeNodeView{true, n.prim_offset, n.count()} : TreeNodeView{false, n.below(), 0};
    });
  }

  AccelStats stats() const override {
    return tree_stats(m_tree, kFormat,
                      sah_tree_config(m_config.traversal_cost, m_config.intersection_cost,
                                      m_config.empty_bonus, m_max_depth),
                      m_shapes.size());
  }

  /// Depth first from the root, whose box is m_tree.clip; a child's box is its parent's cut at
  /// the split. Both children are taken, the one on the centre's side of the split first for a
  /// ball (the other is pushed); each node is tested against the region when it is reached, so
  /// a radius shrunk meanwhile prunes the pushed ones.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (m_tree.nodes.empty()) return;
    RegionTodo todo[kMaxDepth + 1];  // each interior node on the path pushes one child
    int sp = 0;
    RegionTodo cur{0,
                   {m_tree.clip.lo.x, m_tree.clip.lo.y, m_tree.clip.lo.z},
                   {m_tree.clip.hi.x, m_tree.clip.hi.y, m_tree.clip.hi.z}};
    for (;;) {
      if (region_meets(region, cur.box())) {
        const KdNode& node = m_tree.nodes[cur.node];
        if (cost) ++cost->nodes;
        if (!node.leaf()) {
          const int axis = node.axis();
          RegionTodo below = cur, above = cur;
          below.node = node.below();
          below.hi[axis] = node.split;
          above.node = node.below() + 1;
          above.lo[axis] = node.split;
          const bool below_first = region.is_box || region.centre[axis] <= node.split;
          todo[sp++] = below_first ? above : below;
          cur = below_first ? below : above;
          continue;
        }
        const PrimitiveRecord* recs = m_tree.leaf_prims.data() + node.prim_offset;
        for (uint32_t i = 0; i < node.count(); ++i)
          visitor.visit(recs[i].geom_id, record_prim_id(recs[i], m_shapes.data()), region);
      }
      if (sp == 0) return;
      cur = todo[--sp];
    }
  }

 private:
  struct Todo {
    uint32_t node;
    float tmin, tmax;
  };

  /// A node of a region query and its box (plain arrays: the stack is never initialised as a
  /// whole).
  struct RegionTodo {
    uint32_t node;
    float lo[3], hi[3];
    Bounds3f box() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
  };

  /// The ray's origin, direction and reciprocal direction as arrays, so a node step reads its
  /// split axis with one indexed load.
  struct PlaneQuery {
    float org[3], dir[3], inv_dir[3];
  };

  /// The build tree over `prims` (null if there are none), after setting m_max_depth for them.
  std::unique_ptr<BuildNode> build_root(const std::vector<PrimitiveRecord>& prims) {
    m_max_depth = tree_max_depth(m_config.max_depth, prims.size(), kMaxDepth);
    if (prims.empty()) return nullptr;
    std::vector<Event> events;
    events.reserve(prims.size() * 6);
    for (uint32_t i = 0; i < prims.size(); ++i) add_events(events, i, primitive_bounds(prims[i]));
    std::sort(events.begin(), events.end());
    Builder builder(m_config, prims, m_max_depth);
    return builder.build(std::move(events), uint32_t(prims.size()), m_tree.bounds, 0);
  }

  /// Front-to-back traversal with early exit: stops once `best` (narrowed by closest-hit
  /// visitors) lies before the next node's entry. `visit(w, tri)` returns true to stop
  /// (any-hit). Returns true iff a visitor stopped it.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    TreeRay r;
    if (!enter_tree(m_tree, ray, r)) return false;
    float tmin = r.t0, tmax = r.t1;
    const PlaneQuery pq{{ray.org.x, ray.org.y, ray.org.z},
                        {ray.dir.x, ray.dir.y, ray.dir.z},
                        {r.q.inv_dir.x, r.q.inv_dir.y, r.q.inv_dir.z}};
    Todo todo[kMaxDepth + 1];
    int sp = 0;
    uint32_t idx = 0;
    Mailbox mailbox;
    for (;;) {
      if (best < tmin) return false;  // nothing further can be closer
      const KdNode& node = m_tree.nodes[idx];
      counter.node();
      if (!node.leaf()) {
        idx = step(node, pq, tmin, tmax, todo, sp);
        continue;
      }
      if (visit_leaf(m_tree, node.prim_offset, node.count(), r.w, mailbox, visit)) return true;
      if (sp == 0) return false;
      --sp;
      idx = todo[sp].node;
      tmin = todo[sp].tmin;
      tmax = todo[sp].tmax;
    }
  }

  /// One interior-node step (pbrt-v3 KdTreeAccel::Intersect): returns the node to visit next,
  /// narrowing [tmin, tmax] and pushing the far child when the ray crosses the plane.
  uint32_t step(const KdNode& node, const PlaneQuery& q, float& tmin, float& tmax, Todo* todo,
                int& sp) const {
    const int axis = node.axis();
    const float o = q.org[axis], d = q.dir[axis];
    const bool below_first = o < node.split || (o == node.split && d <= 0);
    const uint32_t below = node.below(), above = below + 1;
    const uint32_t first = below_first ? below : above;
    const uint32_t second = below_first ? above : below;
    const float delta = node.split - o;
    const float tplane = delta * q.inv_dir[axis];
    const bool on_plane = std::fabs(delta) <= m_tree.band;
    if (!on_plane && d != 0 && !std::isnan(tplane)) [[likely]] {
      // The common case as selects rather than branches (the three outcomes are unpredictable
      // for incoherent rays): near child only, far child only, or both with the far one pushed.
      const bool near_only = tplane > pad_up(tmax) || tplane < 0;
      const bool far_only = !near_only && tplane < tmin * (2.0f - kSlabPad);
      const bool both = !near_only && !far_only;
      todo[sp] = {second, tplane, tmax};  // kept only when both children are visited
      sp += int(both);
      tmax = both ? tplane : tmax;
      return far_only ? second : first;
    }
    if (d == 0 || std::isnan(tplane)) {  // parallel to the plane: the origin's side, or both
      if (on_plane) todo[sp++] = {second, tmin, tmax};
      return first;
    }
    // Origin on the plane (within rounding): the ray heads into `into`, but surfaces lying in
    // the plane may be stored on the other side. Visit that side first, over [tmin, tplane] (at
    // least tmin), then `into`, so the stack stays ordered front to back.
    const uint32_t into = d > 0 ? above : below;
    const uint32_t other = d > 0 ? below : above;
    todo[sp++] = {into, tmin, tmax};
    tmax = std::clamp(tplane, tmin, tmax);
    return other;
  }

  KdTreeConfig m_config;
  int m_max_depth = 0;
  // Children in adjacent pairs (below, above); origins within m_tree.band of a split plane count
  // as on it.
  FlatTree<KdNode> m_tree;
};

}  // namespace

void validate(const KdTreeConfig& c) {
  if (!(c.traversal_cost > 0) || !(c.intersection_cost > 0))
    throw std::invalid_argument("kdtree: traversal_cost and intersection_cost must be > 0");
  if (!(c.empty_bonus >= 0 && c.empty_bonus < 1))
    throw std::invalid_argument("kdtree: empty_bonus must be in [0, 1)");
  if (c.max_depth < 0 || c.max_depth > kMaxDepth)
    throw std::invalid_argument("kdtree: max_depth must be in [0, 64], got " + std::to_string(c.max_depth));
}

std::unique_ptr<Accelerator> make_kdtree_accelerator(std::span<const GeometryView> meshes,
                                                     const KdTreeConfig& config) {
  return std::make_unique<KdTreeAccelerator>(meshes, config);
}

std::optional<TreeWalk> walk_kdtree(const Accelerator& accel) {
  const auto* kd = dynamic_cast<const KdTreeAccelerator*>(&accel);
  return kd ? std::optional(kd->walk()) : std::nullopt;
}

}  // namespace penumbra
