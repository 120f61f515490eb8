// BSP tree with arbitrary planes: I. Ize, I. Wald and S. G. Parker, "Ray Tracing with the BSP
// Tree", IEEE Symposium on Interactive Ray Tracing 2008. Candidate planes along fixed directions
// (the axes and the k-DOP-26 diagonals) and along the planes of the node's own triangles
// ("autopartition"), each scored by the SAH with the exact surface areas of the two convex
// polytopes it cuts the node's region into (accel/polytope.h); triangles clipped to the node as
// the kD-tree's perfect splits clip them to boxes (Wald & Havran 2006). Node layout and
// front-to-back traversal after the kD-tree (accel/kdtree.cpp), with every plane step widened by
// a tolerance on both sides so that no rounding loses a hit. bsp.h lists the build's rules.
#include "renderer/accel/bsp.h"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/clip.h"
#include "renderer/accel/common.h"
#include "renderer/accel/polytope.h"
#include "renderer/accel/stats.h"
#include "renderer/accel/tree_common.h"

namespace penumbra {
namespace {

/// Flattened node, 20 bytes. The two children of an interior node are adjacent (negative side,
/// then positive side), as in the kD-tree.
struct BspNode {
  float n[3];  // 12 bytes: interior: the plane's unit normal; leaf: 0
  union {
    float k;               //  4 bytes: interior: the plane's offset, dot(n, p) = k on the plane
    uint32_t prim_offset;  //           leaf: first of its records in the leaf record array
  };
  uint32_t flags;  //  4 bytes: bit 0: 1 = leaf; bits 1-31: interior: index of the negative child
                   //           (the positive child follows it); leaf: record count
  bool leaf() const { return (flags & 1u) != 0; }
  uint32_t count() const { return flags >> 1; }
  uint32_t negative() const { return flags >> 1; }
};
static_assert(sizeof(BspNode) == 20, "BspNode must stay 20 bytes");

constexpr int kMaxDepth = 64;
// Node and count fields are 31 bits.
constexpr TreeFormat kFormat{"bsp", (1u << 31) - 1, "2^31 - 1"};

/// The leaf and interior nodes flatten_tree() writes.
BspNode leaf_node(uint32_t first_record, uint32_t count) {
  BspNode n{};
  n.prim_offset = first_record;
  n.flags = (count << 1) | 1u;
  return n;
}

BspNode interior_node(uint32_t negative, const BspPlane& p) {
  BspNode n{};
  n.n[0] = p.n.x;
  n.n[1] = p.n.y;
  n.n[2] = p.n.z;
  n.k = p.k;
  n.flags = negative << 1;
  return n;
}

/// Extra references all splits together may add, as a multiple of the primitive count.
constexpr double kReferenceBudget = 3.0;
/// Relative error allowance of a traversal step's two float dot products (with margin: the sum
/// of three products and a difference, each within 2^-24 relative, is within 4 x 2^-23 of the
/// sum of the magnitudes).
constexpr float kDotError = 0x1p-20f;

/// The fixed directions: the three axes, then the six face diagonals and the four body diagonals
/// of the cube (the k-DOP-26 set), in float as the nodes store them.
constexpr float kD2 = 0.70710678f, kD3 = 0.57735027f;
constexpr std::array<Vec3f, 13> kFixedDirections{{{1, 0, 0},
                                                  {0, 1, 0},
                                                  {0, 0, 1},
                                                  {kD2, kD2, 0},
                                                  {kD2, -kD2, 0},
                                                  {kD2, 0, kD2},
                                                  {kD2, 0, -kD2},
                                                  {0, kD2, kD2},
                                                  {0, kD2, -kD2},
                                                  {kD3, kD3, kD3},
                                                  {kD3, kD3, -kD3},
                                                  {kD3, -kD3, kD3},
                                                  {kD3, -kD3, -kD3}}};

bool is_axis(const Vec3f& n) {
  return int(n.x != 0) + int(n.y != 0) + int(n.z != 0) == 1;
}

// ---- Build ------------------------------------------------------------------------------------

/// Which children a primitive goes to.
struct Sides {
  bool neg, pos;
};

/// The sides of the plane at position p along a direction that a primitive's part spanning
/// [lo, hi] along it goes to: a side it reaches more than eps into; a part within eps of the
/// plane (lying in it) goes to the negative side only. Sound because a traversal widens both
/// children's intervals by at least eps: a point of the part within eps of the plane lies in
/// both children's intervals, so the part is found from either side (the child it is in). A
/// part touching the plane from one side (a mesh cut exactly at a vertex) is thus not
/// duplicated.
inline Sides sides(double lo, double hi, double p, double eps) {
  const bool pos = hi > p + eps;
  return {lo < p - eps || !pos, pos};
}

/// Most candidate directions of a node: the 13 fixed ones and up to 16 from triangles.
constexpr size_t kMaxDirections = 13 + 16;
/// Largest primitives x directions whose ranges a node keeps between its two passes.
constexpr size_t kMaxKeptRanges = size_t(1) << 18;

/// Nodes with at most this many primitives try the ends of their parts as positions (2N per
/// direction) instead of bins.
constexpr size_t kMaxEventPrims = 32;
/// Directions with more candidate positions measure the areas at kAnchors of them first and
/// at the others only where those bound the cost below the best so far.
constexpr size_t kMaxMeasuredPositions = 12;
constexpr size_t kAnchors = 8;
/// Positions closer than this fraction of the region's extent to its ends are not tried.
constexpr double kMinCut = 1e-6;
/// Smallest share of a node's surface area that cutting off an empty side must remove for the
/// empty bonus to apply.
constexpr double kMinEmptyCut = 0.1;

/// Most points of a reference's polygon: a triangle cut by up to kMaxDepth planes, or a box's
/// eight corners.
constexpr int kMaxPoints = 3 + kMaxDepth + 1;

/// A plane on the path from the root and the side of it the path takes (trivially constructible:
/// nodes keep arrays of them).
struct Cut {
  double nx, ny, nz, k;  // the plane dot(n, p) = k
  bool positive;
  double eval(const DVec3& p) const { return nx * p.x + ny * p.y + nz * p.z - k; }
  DVec3 normal() const { return {nx, ny, nz}; }
};

/// The cuts of a node's ancestors, as a list from the node up (each lives in its builder's frame).
struct PathLink {
  const PathLink* up = nullptr;
  Cut cut;
};

/// One primitive in a node: its index and the ancestors' planes (bit d: the plane at depth d)
/// that cut it, so the part of a triangle inside the node is the triangle clipped by them.
struct Ref {
  uint32_t id = 0;
  uint64_t cut = 0;
};

/// child[0] on the plane's negative side, child[1] on its positive side; `area` is the surface
/// area of the node's polytope.
using BuildNode = TreeBuildNode<2, BspPlane>;

class Builder {
 public:
  Builder(const BspConfig& c, const std::vector<PrimitiveRecord>& prims, int max_depth, double eps)
      : m_config(c), m_prims(prims), m_max_depth(max_depth), m_eps(eps) {}

  std::unique_ptr<BuildNode> build(std::vector<Ref> refs, Polytope region, int depth, double budget,
                                   const PathLink* path) {
    auto node = std::make_unique<BuildNode>();
    node->area = region.area();
    Cut cuts[kMaxDepth];
    int d = depth;
    for (const PathLink* p = path; p; p = p->up) cuts[size_t(--d)] = p->cut;
    const size_t n = refs.size();
    // Phase 1: the cheapest plane, if it beats a leaf.
    Split best;
    const double leaf_cost = double(m_config.intersection_cost) * double(n);
    if (depth < m_max_depth && n > 1 && node->area > 0)
      best = find_split(refs, cuts, region, node->area, budget, leaf_cost);
    if (!(best.cost < leaf_cost)) {
      make_leaf(*node, refs, cuts);
      return node;
    }
    // Phase 2: classify the part of each primitive inside the node (sides()); straddlers go
    // to both children and are clipped by the plane below them; parts that clipping left
    // empty go to neither.
    const Cut split{best.plane.n.x, best.plane.n.y, best.plane.n.z, best.plane.k, false};
    const uint64_t bit = uint64_t(1) << depth;
    std::vector<Ref> neg, pos;
    DVec3 pts[kMaxPoints];
    for (const Ref& r : refs) {
      const int np = points(r, cuts, pts);
      if (np == 0) continue;
      double lo = INFINITY, hi = -INFINITY;
      for (int i = 0; i < np; ++i) {
        const double f = split.eval(pts[i]);
        lo = std::min(lo, f);
        hi = std::max(hi, f);
      }
      const bool triangle = !is_shape(m_prims[r.id]);
      const Sides to = sides(lo, hi, 0, m_eps);
      if (to.neg) neg.push_back({r.id, r.cut | (triangle && hi > m_eps ? bit : 0)});
      if (to.pos) pos.push_back({r.id, r.cut | (triangle && lo < -m_eps ? bit : 0)});
    }
    if (neg.size() == n && pos.size() == n) {  // every primitive straddles: no progress
      make_leaf(*node, refs, cuts);
      return node;
    }
    std::vector<Ref>().swap(refs);
    node->leaf = false;
    node->split = best.plane;
    Polytope rneg = region.clip(split.normal(), split.k, false),
             rpos = region.clip(split.normal(), split.k, true);
    region = Polytope{};
    // Phase 3: the unused budget goes to the children by their counts; recurse, large nodes in
    // parallel. The tree's shape never depends on scheduling.
    const double nl = double(neg.size()), nr = double(pos.size());
    const double spare = std::max(0.0, budget - (nl + nr - double(n)));
    const double bl = nl + nr > 0 ? spare * nl / (nl + nr) : 0, br = spare - bl;
    const PathLink lneg{path, split}, lpos{path, {split.nx, split.ny, split.nz, split.k, true}};
    if (n >= m_config.parallel_threshold) {
      tbb::parallel_invoke(
          [&] { node->child[0] = build(std::move(neg), std::move(rneg), depth + 1, bl, &lneg); },
          [&] { node->child[1] = build(std::move(pos), std::move(rpos), depth + 1, br, &lpos); });
    } else {
      node->child[0] = build(std::move(neg), std::move(rneg), depth + 1, bl, &lneg);
      node->child[1] = build(std::move(pos), std::move(rpos), depth + 1, br, &lpos);
    }
    return node;
  }

 private:
  struct Split {
    BspPlane plane;
    double cost = INFINITY;
  };

  /// One candidate direction and its positions: `bins` + 1 evenly spaced over [base, base +
  /// bins x step] (when step > 0) and exact ones (triangle planes, or the parts' ends in small
  /// nodes) with their counts.
  struct Direction {
    Vec3f n;
    DVec3 nd{};
    double region_lo = 0, region_hi = 0;               // the polytope's extent along n
    double prims_lo = INFINITY, prims_hi = -INFINITY;  // the primitives' extent along n
    double base = 0, step = 0;
    std::vector<double> exact;
    std::vector<uint32_t> exact_neg, exact_pos;
  };

  /// Per-thread working memory of find_split(), reused from node to node.
  struct Scratch {
    std::vector<Direction> dirs;
    std::vector<double> ranges;  // kept ranges: per primitive, per direction: lo, hi
    std::vector<uint32_t> neg_bins, pos_bins;
    std::vector<double> positions, neg_area, pos_area;
    std::vector<uint32_t> neg_count, pos_count;
    std::vector<double> los, his;  // small nodes: the parts' ends along one direction
    PolytopeSlicer slicer;
  };

  static Scratch& scratch() {
    thread_local Scratch s;
    return s;
  }

  /// A leaf holding the primitives whose part inside the node is not empty.
  void make_leaf(BuildNode& node, const std::vector<Ref>& refs, const Cut* cuts) const {
    node.prims.reserve(refs.size());
    DVec3 pts[kMaxPoints];
    for (const Ref& r : refs)
      if (r.cut == 0 || points(r, cuts, pts) > 0) node.prims.push_back(r.id);
  }

  /// The points of the part of r's primitive inside the node: a triangle's vertices clipped by
  /// the cuts in r.cut, each kept side widened by eps (Sutherland-Hodgman), or a shape's box
  /// corners. Returns their count, 0 if nothing is left. `cuts` are the node's ancestors by
  /// depth.
  int points(const Ref& r, const Cut* cuts, DVec3* out) const {
    const PrimitiveRecord& p = m_prims[r.id];
    if (is_shape(p)) {
      for (int i = 0; i < 8; ++i)
        out[i] = {(i & 1) ? p.b.x : p.a.x, (i & 2) ? p.b.y : p.a.y, (i & 4) ? p.b.z : p.a.z};
      return 8;
    }
    out[0] = to_dvec(p.a);
    out[1] = to_dvec(p.b);
    out[2] = to_dvec(p.c);
    int n = 3;
    DVec3 tmp[kMaxPoints];
    for (uint64_t bits = r.cut; bits != 0 && n > 0; bits &= bits - 1) {
      const Cut& c = cuts[std::countr_zero(bits)];
      // Keep points with s (dot(n, x) - k) >= -eps, s = +1 on the positive side, -1 on the negative.
      const double s = c.positive ? 1.0 : -1.0;
      double e[kMaxPoints];
      bool all_in = true;
      for (int i = 0; i < n; ++i) {
        e[i] = s * c.eval(out[i]) + m_eps;
        all_in &= e[i] >= 0;
      }
      if (all_in) continue;
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const int j = i + 1 == n ? 0 : i + 1;
        if (e[i] >= 0) tmp[m++] = out[i];
        if ((e[i] < 0 && e[j] > 0) || (e[i] > 0 && e[j] < 0))
          tmp[m++] = out[i] + (out[j] - out[i]) * (e[i] / (e[i] - e[j]));
      }
      n = m;
      std::copy(tmp, tmp + m, out);
    }
    return n;
  }

  /// Adds direction n with an exact candidate position through point p (when p is given), or
  /// only the position when n is (to rounding) one of dirs[0, nd). Returns the new count.
  static size_t add_direction(std::vector<Direction>& dirs, size_t nd, Vec3f n, const Vec3f* p) {
    const DVec3 v = to_dvec(n);
    for (size_t j = 0; j < nd; ++j)
      if (std::fabs(dot(dirs[j].nd, v)) > 1 - 1e-9) {
        if (p) dirs[j].exact.push_back(dot(dirs[j].nd, to_dvec(*p)));
        return nd;
      }
    if (dirs.size() <= nd) dirs.resize(nd + 1);
    Direction& d = dirs[nd];
    d.n = n;
    d.nd = v;
    d.prims_lo = INFINITY;
    d.prims_hi = -INFINITY;
    d.base = d.step = 0;
    d.exact.clear();
    if (p) d.exact.push_back(dot(v, to_dvec(*p)));
    return nd + 1;
  }

  /// The directions of a node into dirs[0, count): the fixed ones, then the normals of its
  /// largest triangles (through which their planes are candidates).
  size_t directions(const std::vector<Ref>& refs, std::vector<Direction>& dirs) const {
    size_t nd = 0;
    const int fixed = m_config.fixed_directions ? 13 : 3;
    for (int i = 0; i < fixed; ++i) nd = add_direction(dirs, nd, kFixedDirections[size_t(i)], nullptr);
    const int want = m_config.triangle_planes;
    if (want == 0) return nd;
    // The `want` largest triangles (ties: the first met), as (twice the area, squared; id).
    std::array<std::pair<float, uint32_t>, 16> top{};
    int have = 0;
    for (const Ref& ref : refs) {
      const PrimitiveRecord& r = m_prims[ref.id];
      if (is_shape(r)) continue;
      const Vec3f c = cross(r.b - r.a, r.c - r.a);
      const float a2 = dot(c, c);
      if (!(a2 > 0) || (have == want && a2 <= top[size_t(have - 1)].first)) continue;
      int i = have < want ? have++ : have - 1;
      for (; i > 0 && top[size_t(i - 1)].first < a2; --i) top[size_t(i)] = top[size_t(i - 1)];
      top[size_t(i)] = {a2, ref.id};
    }
    for (int i = 0; i < have; ++i) {
      const PrimitiveRecord& r = m_prims[top[size_t(i)].second];
      const DVec3 c = cross(to_dvec(r.b) - to_dvec(r.a), to_dvec(r.c) - to_dvec(r.a));
      const double len = std::sqrt(dot(c, c));
      if (!(len > 0) || !std::isfinite(len)) continue;
      const Vec3f n = normalize(Vec3f{float(c.x / len), float(c.y / len), float(c.z / len)});
      if (!(dot(n, n) > 0)) continue;
      nd = add_direction(dirs, nd, n, &r.a);
    }
    return nd;
  }

  /// The parts of a node's primitives projected onto its directions dirs[0, nd): project()
  /// sets a part's range along direction j to [range[j], range[nd + j]] (lo > hi when the part
  /// is empty).
  struct Projection {
    size_t nd = 0;
    double nx[kMaxDirections], ny[kMaxDirections], nz[kMaxDirections];
    double range[2 * kMaxDirections];
    DVec3 pts[kMaxPoints];
  };

  /// Projection `p` of the part of r's primitive inside the node (`cuts`: its ancestors by depth).
  void project(const Ref& r, const Cut* cuts, Projection& p) const {
    const int np = points(r, cuts, p.pts);
    double* lo = p.range;
    double* hi = p.range + p.nd;
    for (size_t j = 0; j < p.nd; ++j) lo[j] = INFINITY, hi[j] = -INFINITY;
    for (int i = 0; i < np; ++i) {
      const double x = p.pts[i].x, y = p.pts[i].y, z = p.pts[i].z;
      for (size_t j = 0; j < p.nd; ++j) {
        const double f = p.nx[j] * x + p.ny[j] * y + p.nz[j] * z;
        lo[j] = f < lo[j] ? f : lo[j];
        hi[j] = f > hi[j] ? f : hi[j];
      }
    }
  }

  /// The cheapest candidate plane within the budget that beats `leaf_cost` (cost infinite if
  /// none does).
  Split find_split(const std::vector<Ref>& refs, const Cut* cuts, const Polytope& region, double area,
                   double budget, double leaf_cost) const {
    Scratch& sc = scratch();
    Projection proj;
    proj.nd = directions(refs, sc.dirs);
    // Phase 1: the extents of the region and of each primitive's part along each direction,
    // kept for phase 3 unless the node is large (then computed again there).
    const bool keep = refs.size() * proj.nd <= kMaxKeptRanges;
    measure_extents(refs, cuts, region, keep, proj, sc);
    // Phase 2: the positions. Few primitives: the ends of every part, exactly (the events of
    // a kD-tree's sweep, which cut between primitives rather than through them); otherwise
    // bins over the primitives' extent within the region.
    const bool events = refs.size() <= kMaxEventPrims && keep;
    place_positions(refs.size(), proj.nd, events, sc);
    // Phase 3: count the primitives on each side of each position, by sides() (binned: to
    // rounding of the bin index; exact positions: exactly).
    const size_t stride = size_t(m_config.bins) + 1;
    sc.neg_bins.assign(proj.nd * stride, 0);
    sc.pos_bins.assign(proj.nd * stride, 0);
    if (events) {
      count_event_sides(refs.size(), proj.nd, sc);
    } else {
      count_binned_sides(refs, cuts, keep, proj, sc);
    }
    // Phase 4: the SAH of every position cutting the region, with the areas of both parts.
    Split best;
    best.cost = leaf_cost;  // only splits cheaper than a leaf
    for (size_t j = 0; j < proj.nd; ++j) {
      collect_candidates(j, double(refs.size()), budget, area, best.cost, sc);
      if (!sc.positions.empty()) measure_candidates(sc.dirs[j], region, area, best, sc);
    }
    return best;
  }

  /// Phase 1 of find_split(): the region's extent (region_lo, region_hi) and the primitives'
  /// (prims_lo, prims_hi) along each direction; each part's ranges go to sc.ranges when `keep`.
  void measure_extents(const std::vector<Ref>& refs, const Cut* cuts, const Polytope& region, bool keep,
                       Projection& proj, Scratch& sc) const {
    const size_t nd = proj.nd;
    std::vector<Direction>& dirs = sc.dirs;
    for (size_t j = 0; j < nd; ++j) region.extent(dirs[j].nd, dirs[j].region_lo, dirs[j].region_hi);
    if (keep) sc.ranges.resize(2 * refs.size() * nd);
    for (size_t j = 0; j < nd; ++j)
      proj.nx[j] = dirs[j].nd.x, proj.ny[j] = dirs[j].nd.y, proj.nz[j] = dirs[j].nd.z;
    for (size_t r = 0; r < refs.size(); ++r) {
      project(refs[r], cuts, proj);
      for (size_t j = 0; j < nd; ++j) {
        dirs[j].prims_lo = std::min(dirs[j].prims_lo, proj.range[j]);
        dirs[j].prims_hi = std::max(dirs[j].prims_hi, proj.range[nd + j]);
      }
      if (keep) std::copy(proj.range, proj.range + 2 * nd, sc.ranges.begin() + ptrdiff_t(2 * nd * r));
    }
  }

  /// Phase 2 of find_split(): each direction's exact positions (with `events`, the ends of the
  /// kept parts, sorted and without repeats) or bins, and zeroed exact counts.
  void place_positions(size_t nrefs, size_t nd, bool events, Scratch& sc) const {
    for (size_t j = 0; j < nd; ++j) {
      Direction& d = sc.dirs[j];
      if (events) {
        for (size_t r = 0; r < nrefs; ++r) {
          const double lo = sc.ranges[2 * nd * r + j], hi = sc.ranges[2 * nd * r + nd + j];
          if (lo > hi) continue;
          d.exact.push_back(lo);
          d.exact.push_back(hi);
        }
      } else {
        const double lo = std::max(d.region_lo, d.prims_lo), hi = std::min(d.region_hi, d.prims_hi);
        if (hi > lo) {
          d.base = lo;
          d.step = (hi - lo) / m_config.bins;
        }
      }
      std::sort(d.exact.begin(), d.exact.end());  // meshes share vertices: many repeat
      d.exact.erase(std::unique(d.exact.begin(), d.exact.end()), d.exact.end());
      d.exact_neg.assign(d.exact.size(), 0);
      d.exact_pos.assign(d.exact.size(), 0);
    }
  }

  /// Phase 3 of find_split() for small nodes (kept ranges, exact positions only): sweeps the
  /// sorted positions over the sorted ends of the parts: a part thicker than 2 eps is on the
  /// negative side of p iff lo < p - eps and on the positive side iff hi > p + eps; thinner
  /// parts are counted by sides() itself.
  void count_event_sides(size_t nrefs, size_t nd, Scratch& sc) const {
    for (size_t j = 0; j < nd; ++j) {
      Direction& d = sc.dirs[j];
      sc.los.clear();
      sc.his.clear();
      for (size_t r = 0; r < nrefs; ++r) {
        const double lo = sc.ranges[2 * nd * r + j], hi = sc.ranges[2 * nd * r + nd + j];
        if (lo > hi) continue;  // an empty part
        if (hi - lo > 2 * m_eps) {
          sc.los.push_back(lo);
          sc.his.push_back(hi);
          continue;
        }
        count_exact(d, lo, hi);  // a thin part: by the rule itself
      }
      std::sort(sc.los.begin(), sc.los.end());
      std::sort(sc.his.begin(), sc.his.end());
      size_t below = 0, ended = 0;
      for (size_t e = 0; e < d.exact.size(); ++e) {
        const double p = d.exact[e];
        while (below < sc.los.size() && sc.los[below] < p - m_eps) ++below;
        while (ended < sc.his.size() && sc.his[ended] <= p + m_eps) ++ended;
        d.exact_neg[e] += uint32_t(below);
        d.exact_pos[e] += uint32_t(sc.his.size() - ended);
      }
    }
  }

  /// Phase 3 of find_split() for binned nodes: per part, the first bin position on its
  /// negative side and the last on its positive side (to rounding), and sides() at each exact
  /// position. Parts are projected again unless their ranges were kept.
  void count_binned_sides(const std::vector<Ref>& refs, const Cut* cuts, bool keep, Projection& proj,
                          Scratch& sc) const {
    const size_t nd = proj.nd;
    const int bins = m_config.bins;
    const size_t stride = size_t(bins) + 1;
    for (size_t r = 0; r < refs.size(); ++r) {
      const double* rr = proj.range;
      if (keep) {
        rr = &sc.ranges[2 * nd * r];
      } else {
        project(refs[r], cuts, proj);
      }
      if (rr[0] > rr[nd]) continue;  // an empty part
      for (size_t j = 0; j < nd; ++j) {
        Direction& d = sc.dirs[j];
        const double lo = rr[j], hi = rr[nd + j];
        if (d.step > 0) {
          // First position p_i = base + i step on the negative side (p_i > min(lo + eps,
          // hi - eps)) and last on the positive side (p_i < hi - eps), to rounding.
          const double a = std::floor((std::min(lo + m_eps, hi - m_eps) - d.base) / d.step) + 1;
          const double b = std::ceil((hi - m_eps - d.base) / d.step) - 1;
          if (a <= bins) ++sc.neg_bins[j * stride + size_t(std::max(a, 0.0))];
          if (b >= 0) ++sc.pos_bins[j * stride + size_t(std::min(b, double(bins)))];
        }
        count_exact(d, lo, hi);
      }
    }
  }

  /// Adds a part spanning [lo, hi] to the counts of every exact position of `d`, by sides().
  void count_exact(Direction& d, double lo, double hi) const {
    for (size_t e = 0; e < d.exact.size(); ++e) {
      const Sides to = sides(lo, hi, d.exact[e], m_eps);
      d.exact_neg[e] += to.neg;
      d.exact_pos[e] += to.pos;
    }
  }

  /// The SAH's factor for a split leaving nl and nr primitives on its sides, where `kept` is
  /// the area of the non-empty side: the empty bonus needs a cut that removes a real share of
  /// the surface (otherwise shaving a node's corners along all 13 directions would always look
  /// cheap).
  double bonus_factor(double nl, double nr, double kept, double area) const {
    return (nl == 0 || nr == 0) && kept <= (1 - kMinEmptyCut) * area ? 1.0 - m_config.empty_bonus : 1.0;
  }

  /// Phase 4 of find_split(), first half: the positions of direction j inside its region (not
  /// within kMinCut of its ends) that fit in the budget and may still beat `best_cost`, into
  /// sc.positions with their counts. Since the parts' areas sum to at least the node's, a
  /// position costs at least K_T + K_I min(N_L, N_R) (times the bonus factor).
  void collect_candidates(size_t j, double n, double budget, double area, double best_cost,
                          Scratch& sc) const {
    const Direction& d = sc.dirs[j];
    sc.positions.clear();
    sc.neg_count.clear();
    sc.pos_count.clear();
    const auto candidate = [&](double p, uint32_t nl, uint32_t nr) {
      if (double(nl) + double(nr) - n > budget) return;
      const double bound = bonus_factor(nl, nr, 0, area) *
                           (m_config.traversal_cost + m_config.intersection_cost * double(std::min(nl, nr)));
      if (bound >= best_cost) return;
      sc.positions.push_back(p);
      sc.neg_count.push_back(nl);
      sc.pos_count.push_back(nr);
    };
    const double margin = kMinCut * (d.region_hi - d.region_lo);  // no slivers
    const auto inside = [&](double p) { return p > d.region_lo + margin && p < d.region_hi - margin; };
    if (d.step > 0) {
      const int bins = m_config.bins;
      const size_t stride = size_t(bins) + 1;
      uint32_t below = 0, above = 0;
      for (int i = 0; i <= bins; ++i) above += sc.pos_bins[j * stride + size_t(i)];
      for (int i = 0; i <= bins; ++i) {
        below += sc.neg_bins[j * stride + size_t(i)];
        const double p = d.base + d.step * i;
        if (inside(p)) candidate(p, below, above);
        above -= sc.pos_bins[j * stride + size_t(i)];
      }
    }
    for (size_t e = 0; e < d.exact.size(); ++e)
      if (inside(d.exact[e])) candidate(d.exact[e], d.exact_neg[e], d.exact_pos[e]);
  }

  /// Phase 4 of find_split(), second half: the SAH cost of sc.positions along `d` with the
  /// exact areas of the region's two parts, narrowing `best`. With many positions (sorted),
  /// areas are measured at every stride-th (the anchors) and at those between anchors a < i < b
  /// whose bound by the anchors' areas can still win: a part only grows with its side (convex
  /// sets), so A_neg(p_i) >= A_neg(p_a) and A_pos(p_i) >= A_pos(p_b).
  void measure_candidates(const Direction& d, const Polytope& region, double area, Split& best,
                          Scratch& sc) const {
    const size_t m = sc.positions.size();
    sc.slicer.reset(region, d.nd);
    sc.neg_area.resize(m);
    sc.pos_area.resize(m);
    const auto evaluate = [&](size_t i) {
      double& al = sc.neg_area[i];
      double& ar = sc.pos_area[i];
      sc.slicer.areas(sc.positions[i], al, ar);
      if (!(al > 0) || !(ar > 0)) return;
      const double nl = sc.neg_count[i], nr = sc.pos_count[i];
      const double cost = bonus_factor(nl, nr, nl == 0 ? ar : al, area) *
                          (m_config.traversal_cost + m_config.intersection_cost * (al * nl + ar * nr) / area);
      if (cost < best.cost) best = {{d.n, float(sc.positions[i])}, cost};
    };
    const bool sorted = std::is_sorted(sc.positions.begin(), sc.positions.end());
    if (m <= kMaxMeasuredPositions || !sorted) {
      for (size_t i = 0; i < m; ++i) evaluate(i);
      return;
    }
    const size_t every = (m + kAnchors - 1) / kAnchors;
    for (size_t i = 0; i < m; i += every) evaluate(i);
    evaluate(m - 1);
    for (size_t i = 0; i < m; ++i) {
      if (i % every == 0 || i == m - 1) continue;
      const size_t a = i - i % every, b = std::min(a + every, m - 1);
      const double nl = sc.neg_count[i], nr = sc.pos_count[i];
      const double bound = bonus_factor(nl, nr, 0, area) *
                           (m_config.traversal_cost +
                            m_config.intersection_cost * (sc.neg_area[a] * nl + sc.pos_area[b] * nr) / area) *
                           (1 - 1e-9);
      if (bound < best.cost) evaluate(i);
    }
  }

  const BspConfig& m_config;
  const std::vector<PrimitiveRecord>& m_prims;
  int m_max_depth;
  double m_eps;
};

// ---- The accelerator ----------------------------------------------------------------------------

class BspAccelerator final : public TraversalAccelerator<BspAccelerator> {
  friend class TraversalAccelerator<BspAccelerator>;

 public:
  BspAccelerator(std::span<const GeometryView> views, const BspConfig& config) : m_config(config) {
    validate(config);
    build_tree(
        views, kFormat, {config.traversal_cost, config.intersection_cost}, m_shapes, m_tree,
        [this](const std::vector<PrimitiveRecord>& prims) { return build_root(prims); }, leaf_node,
        [this](uint32_t negative, const BspPlane& p) {
          m_oblique += !is_axis(p.n);
          return interior_node(negative, p);
        });
  }

  Bounds3f bounds() const override { return m_tree.bounds; }

  TreeWalk walk() const {
    return walk_flat_tree<2>(m_tree, [](const BspNode& n) {
      return n.leaf() ? TreeNodeView{true, n.prim_offset, n.count()} : TreeNodeView{false, n.negative(), 0};
    });
  }

  AccelStats stats() const override {
    return tree_stats(m_tree, kFormat,
                      sah_tree_config(m_config.traversal_cost, m_config.intersection_cost,
                                      m_config.empty_bonus, m_max_depth) +
                          ", bins " + std::to_string(m_config.bins) + ", triangle_planes " +
                          std::to_string(m_config.triangle_planes) + ", fixed_directions " +
                          (m_config.fixed_directions ? "on" : "off") + ", " + std::to_string(m_oblique) +
                          " oblique planes",
                      m_shapes.size());
  }

  /// Depth-first walk over the nodes the region may reach, nearer side first for a ball. Nodes
  /// store no box, so a side is skipped when the region lies beyond its plane by more than the
  /// tolerance of step() (the build's band and the rounding of the plane's evaluation); for a
  /// ball each pushed node keeps a lower bound on its distance from the centre, checked again
  /// when popped, as the visitor may shrink the radius.
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (m_tree.nodes.empty() || !region_meets(region, m_tree.clip)) return;
    // The rounding of a plane's evaluation at the region's points, besides the offset's share.
    const Vec3f mag = region.is_box ? max(abs(region.box.lo), abs(region.box.hi)) : abs(region.centre);
    const float region_eps = 2 * m_tree.band + kDotError * (mag.x + mag.y + mag.z);
    RegionTodo todo[kMaxDepth + 1];
    int sp = 0;
    RegionTodo cur{0, 0};
    for (;;) {
      if (ball_reaches(region, cur.distance)) {
        const BspNode& node = m_tree.nodes[cur.node];
        if (cost) ++cost->nodes;
        if (node.leaf()) {
          offer_leaf(node, region, visitor);
        } else {
          RegionTodo next[2];
          const int n = region_children(node, region, region_eps, cur.distance, next);
          if (n > 1) todo[sp++] = next[1];
          if (n > 0) {
            cur = next[0];
            continue;
          }
        }
      }
      if (sp == 0) return;
      cur = todo[--sp];
    }
  }

  std::optional<BspPlane> root_plane() const {
    if (m_tree.nodes.empty() || m_tree.nodes[0].leaf()) return std::nullopt;
    const BspNode& r = m_tree.nodes[0];
    return BspPlane{{r.n[0], r.n[1], r.n[2]}, r.k};
  }

 private:
  struct Todo {
    uint32_t node;
    float tmin, tmax;
  };

  /// The build tree over `prims` (null if there are none), after setting m_max_depth for them.
  std::unique_ptr<BuildNode> build_root(const std::vector<PrimitiveRecord>& prims) {
    m_max_depth = tree_max_depth(m_config.max_depth, prims.size(), kMaxDepth);
    if (prims.empty()) return nullptr;
    std::vector<Ref> refs(prims.size());
    for (uint32_t i = 0; i < refs.size(); ++i) refs[i].id = i;
    Builder builder(m_config, prims, m_max_depth, double(m_tree.band));
    return builder.build(std::move(refs), Polytope(m_tree.clip), 0, kReferenceBudget * double(prims.size()),
                         nullptr);
  }

  /// Front-to-back traversal: visits the child whose t-interval starts first and pushes the
  /// other; skips nodes whose interval starts beyond `best` (narrowed by closest-hit visitors).
  /// The children's intervals overlap, so the stack is not sorted by entry distance: skipped
  /// entries are popped, never the rest of the stack. `visit(w, rec)` returns true to stop
  /// (any-hit). Returns true iff a visitor stopped it.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    TreeRay r;
    if (!enter_tree(m_tree, ray, r)) return false;
    float tmin = r.t0, tmax = r.t1;
    const float org_eps =
        2 * m_tree.band + kDotError * (std::fabs(ray.org.x) + std::fabs(ray.org.y) + std::fabs(ray.org.z));
    Todo todo[kMaxDepth + 1];
    int sp = 0;
    uint32_t idx = 0;
    Mailbox mailbox;
    for (;;) {
      if (!(best < tmin)) {
        const BspNode& node = m_tree.nodes[idx];
        counter.node();
        if (!node.leaf()) {
          if (step(node, ray, org_eps, idx, tmin, tmax, todo, sp)) continue;
        } else {
          if (visit_leaf(m_tree, node.prim_offset, node.count(), r.w, mailbox, visit)) return true;
        }
      }
      if (sp == 0) return false;
      --sp;
      idx = todo[sp].node;
      tmin = todo[sp].tmin;
      tmax = todo[sp].tmax;
    }
  }

  /// One interior-node step. With d = dot(n, org) - k and s = dot(n, dir), the positive child
  /// covers the t where d + t s >= -eps and the negative child the t where d + t s <= eps, each
  /// within [tmin, tmax] and padded outward by the slab margin. eps is twice the scene's
  /// rounding band plus the float error of d and s: one band for the build, which leaves a
  /// primitive within a band of the plane on one side only (sides()), one for the distance of a
  /// reported hit from its triangle. Sets idx, tmin, tmax to the child whose interval
  /// starts first and pushes the other when both are non-empty; returns false when neither is.
  bool step(const BspNode& node, const Ray& ray, float org_eps, uint32_t& idx, float& tmin, float& tmax,
            Todo* todo, int& sp) const {
    const float d = node.n[0] * ray.org.x + node.n[1] * ray.org.y + node.n[2] * ray.org.z - node.k;
    const float s = node.n[0] * ray.dir.x + node.n[1] * ray.dir.y + node.n[2] * ray.dir.z;
    const float eps = org_eps + kDotError * std::fabs(node.k);
    float n0 = tmin, n1 = tmax, p0 = tmin, p1 = tmax;
    // Comparisons are written so that a NaN bound (overflowed products) constrains nothing.
    const auto lower_bound = [](float t, float& lo) {
      t = t > 0 ? t * (2.0f - kSlabPad) : t * kSlabPad;
      if (t > lo) lo = t;
    };
    const auto upper_bound = [](float t, float& hi) {
      t = t > 0 ? t * kSlabPad : t * (2.0f - kSlabPad);
      if (t < hi) hi = t;
    };
    if (s != 0) {
      const float inv = 1.0f / s;
      const float tp = (-eps - d) * inv;  // d + t s = -eps
      const float tn = (eps - d) * inv;   // d + t s = +eps
      if (s > 0) {
        lower_bound(tp, p0);
        upper_bound(tn, n1);
      } else {
        upper_bound(tp, p1);
        lower_bound(tn, n0);
      }
    } else {  // parallel: the sides whose inequality holds at the origin
      if (d < -eps) p0 = kInfinity;
      if (d > eps) n0 = kInfinity;
    }
    const bool neg_ok = n0 <= n1, pos_ok = p0 <= p1;
    const uint32_t neg = node.negative(), pos = neg + 1;
    if (neg_ok && pos_ok) {
      const bool neg_first = n0 < p0 || (n0 == p0 && s < 0);
      todo[sp++] = neg_first ? Todo{pos, p0, p1} : Todo{neg, n0, n1};
      idx = neg_first ? neg : pos;
      tmin = neg_first ? n0 : p0;
      tmax = neg_first ? n1 : p1;
      return true;
    }
    if (!neg_ok && !pos_ok) return false;
    idx = neg_ok ? neg : pos;
    tmin = neg_ok ? n0 : p0;
    tmax = neg_ok ? n1 : p1;
    return true;
  }

  /// A node a region query has still to visit.
  struct RegionTodo {
    uint32_t node;
    float distance;  // ball: lower bound on the centre's distance to the node's primitives; box: 0
  };

  /// False when `region` is a ball whose padded radius is below `distance`.
  static bool ball_reaches(const QueryRegion& region, float distance) {
    return region.is_box || !(distance > 0) || distance * distance <= region.radius2 * kRegionPad;
  }

  /// The children of interior `node` that `region` may reach, into next[0, returned count),
  /// nearer first for a ball. With e the plane's tolerance (region_eps plus the offset's
  /// rounding), the negative child holds the primitives' points with dot(n, p) - k <= e and the
  /// positive child those with dot(n, p) - k >= -e (sides() in the build). `distance` is the
  /// node's lower bound on the ball's distance, which its children inherit.
  int region_children(const BspNode& node, const QueryRegion& region, float region_eps, float distance,
                      RegionTodo* next) const {
    const uint32_t neg = node.negative(), pos = neg + 1;
    const float eps = region_eps + kDotError * std::fabs(node.k);
    int count = 0;
    if (region.is_box) {
      // The box's range along n, each bound at the corner the signs of n pick.
      float lo = -node.k, hi = -node.k;
      for (int a = 0; a < 3; ++a) {
        const float n = node.n[a];
        lo += n * (n >= 0 ? region.box.lo[a] : region.box.hi[a]);
        hi += n * (n >= 0 ? region.box.hi[a] : region.box.lo[a]);
      }
      if (lo <= eps) next[count++] = {neg, 0};
      if (hi >= -eps) next[count++] = {pos, 0};
      return count;
    }
    const Vec3f& c = region.centre;
    const float s = node.n[0] * c.x + node.n[1] * c.y + node.n[2] * c.z - node.k;
    // The centre's distance to each child's half-space, at least the node's.
    const RegionTodo to_neg{neg, std::max(distance, s - eps)}, to_pos{pos, std::max(distance, -s - eps)};
    const RegionTodo& nearer = s >= 0 ? to_pos : to_neg;
    const RegionTodo& farther = s >= 0 ? to_neg : to_pos;
    if (ball_reaches(region, nearer.distance)) next[count++] = nearer;
    if (ball_reaches(region, farther.distance)) next[count++] = farther;
    return count;
  }

  /// Offers the leaf's records whose bounds meet the region (read again before each).
  void offer_leaf(const BspNode& node, QueryRegion& region, RegionVisitor& visitor) const {
    const PrimitiveRecord* recs = m_tree.leaf_prims.data() + node.prim_offset;
    for (uint32_t i = 0, n = node.count(); i < n; ++i) {
      const PrimitiveRecord& rec = recs[i];
      if (region_meets(region, primitive_bounds(rec)))
        visitor.visit(rec.geom_id, record_prim_id(rec, m_shapes.data()), region);
    }
  }

  BspConfig m_config;
  int m_max_depth = 0;
  // Children in adjacent pairs (negative, positive); m_tree.clip is the root's region and
  // m_tree.band also the build's tolerance.
  FlatTree<BspNode> m_tree;
  uint64_t m_oblique = 0;  // interior nodes whose plane is not axis-aligned
};

}  // namespace

void validate(const BspConfig& c) {
  const auto fail = [](const std::string& what, const std::string& value) {
    throw std::invalid_argument("bsp: " + what + ", got " + value);
  };
  if (!(c.traversal_cost > 0) || !std::isfinite(c.traversal_cost))
    fail("traversal_cost must be finite and > 0", format_number(c.traversal_cost));
  if (!(c.intersection_cost > 0) || !std::isfinite(c.intersection_cost))
    fail("intersection_cost must be finite and > 0", format_number(c.intersection_cost));
  if (!(c.empty_bonus >= 0 && c.empty_bonus < 1))
    fail("empty_bonus must be in [0, 1)", format_number(c.empty_bonus));
  if (c.max_depth < 0 || c.max_depth > kMaxDepth)
    fail("max_depth must be in [0, 64]", std::to_string(c.max_depth));
  if (c.bins < 2 || c.bins > 64) fail("bins must be in [2, 64]", std::to_string(c.bins));
  if (c.triangle_planes < 0 || c.triangle_planes > 16)
    fail("triangle_planes must be in [0, 16]", std::to_string(c.triangle_planes));
}

std::unique_ptr<Accelerator> make_bsp_accelerator(std::span<const GeometryView> views,
                                                  const BspConfig& config) {
  return std::make_unique<BspAccelerator>(views, config);
}

std::optional<TreeWalk> walk_bsp(const Accelerator& accel) {
  const auto* bsp = dynamic_cast<const BspAccelerator*>(&accel);
  return bsp ? std::optional(bsp->walk()) : std::nullopt;
}

std::optional<BspPlane> bsp_root_plane(const Accelerator& accel) {
  const auto* bsp = dynamic_cast<const BspAccelerator*>(&accel);
  return bsp ? bsp->root_plane() : std::nullopt;
}

}  // namespace penumbra
