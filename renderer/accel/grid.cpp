// Uniform grid. Resolution after Cleary & Wyvill (1988) / Ize et al. (2006): cells of equal size
// with about lambda cells per triangle. Traversal: J. Amanatides and A. Woo, "A Fast Voxel
// Traversal Algorithm for Ray Tracing", Eurographics 1987, evaluated in double precision so that
// the cell sequence of long rays does not drift. Mailboxing with a small hashed per-ray table
// (after Benthin, "Realtime Ray Tracing on Current CPU Architectures", 2006).
#include "renderer/accel/grid.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "renderer/accel/common.h"
#include "renderer/accel/stats.h"

namespace penumbra {

bool triangle_box_overlap(const double lo[3], const double hi[3], Vec3f a, Vec3f b, Vec3f c) {
  double h[3], v[3][3];
  for (int k = 0; k < 3; ++k) {
    const double ctr = 0.5 * (lo[k] + hi[k]);
    h[k] = 0.5 * (hi[k] - lo[k]);
    v[0][k] = a[k] - ctr;
    v[1][k] = b[k] - ctr;
    v[2][k] = c[k] - ctr;
  }
  // Separated along axis L if the projected triangle lies outside [-r, r].
  auto separated = [&](const double L[3]) {
    const double p0 = v[0][0] * L[0] + v[0][1] * L[1] + v[0][2] * L[2];
    const double p1 = v[1][0] * L[0] + v[1][1] * L[1] + v[1][2] * L[2];
    const double p2 = v[2][0] * L[0] + v[2][1] * L[1] + v[2][2] * L[2];
    const double r = h[0] * std::fabs(L[0]) + h[1] * std::fabs(L[1]) + h[2] * std::fabs(L[2]);
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  // 1. The box's face normals (the triangle's bounding box against the box).
  for (int k = 0; k < 3; ++k) {
    const double L[3] = {k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0};
    if (separated(L)) return false;
  }
  // 2. The triangle's normal (plane-box test).
  double e[3][3];
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) e[i][k] = v[(i + 1) % 3][k] - v[i][k];
  const double n[3] = {e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                       e[0][0] * e[1][1] - e[0][1] * e[1][0]};
  if (separated(n)) return false;
  // 3. The nine cross products of triangle edges with the box axes.
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      double L[3] = {0, 0, 0};
      const int k1 = (k + 1) % 3, k2 = (k + 2) % 3;  // L = axis_k x e_i
      L[k1] = -e[i][k2];
      L[k2] = e[i][k1];
      if (separated(L)) return false;
    }
  return true;
}

namespace {

// True if the boxes [lo, hi] (double) and [a, b] overlap, faces included.
bool box_overlap(const double lo[3], const double hi[3], Vec3f a, Vec3f b) {
  for (int k = 0; k < 3; ++k)
    if (double(b[k]) < lo[k] || double(a[k]) > hi[k]) return false;
  return true;
}

// The float box enclosing the double box [lo, hi] (rounded outward).
Bounds3f outward_box(const double lo[3], const double hi[3]) {
  Bounds3f b;
  for (int k = 0; k < 3; ++k) {
    float l = float(lo[k]), h = float(hi[k]);
    if (double(l) > lo[k]) l = std::nextafter(l, -kInfinity);
    if (double(h) < hi[k]) h = std::nextafter(h, kInfinity);
    b.lo[k] = l;
    b.hi[k] = h;
  }
  return b;
}

constexpr int kMailboxSize = 64;  // power of two
// A cell's first-reference offset with this bit set holds a sub-grid: its one "reference" is
// the sub-grid's level index. The flag shares the cell's cache line with its range.
constexpr uint32_t kChildBit = 0x80000000u;
constexpr uint32_t kOffsetMask = ~kChildBit;
// Most cell references a level may create, bounded by the triangles' bounding boxes: the top
// level 2^26 (256 MiB), a sub-grid kChildRefsPerTriangle per triangle of its cell.
constexpr uint64_t kMaxCandidateRefs = 1ull << 26;
constexpr uint64_t kChildRefsPerTriangle = 8;

/// One grid of the hierarchy: the top grid, or the sub-grid of one cell of its parent, spanning
/// the part of that cell its triangles occupy. 88 bytes: lo, cell_size (2 x 24) + box (24) +
/// res (12) + first_cell (4).
struct GridLevel {
  double lo[3] = {0, 0, 0};         ///< low corner of cell (0, 0, 0)
  double cell_size[3] = {0, 0, 0};  ///< cell extent per axis
  Bounds3f box;                     ///< the grid's box (rays are clipped to it), rounded outward
  uint32_t res[3] = {0, 0, 0};      ///< cells per axis
  uint32_t first_cell = 0;          ///< index of cell (0, 0, 0) in the cell arrays (x fastest)
};
static_assert(sizeof(GridLevel) == 88);

/// A built grid and its sub-grids: levels[0] is the grid itself; cell and level indices are
/// local (the parent shifts them when it appends this subtree after its own cells).
struct GridTree {
  std::vector<GridLevel> levels;
  std::vector<uint32_t> offsets;  ///< per cell: first reference (| kChildBit); cells + 1 entries
  std::vector<uint32_t> refs;     ///< triangle indices grouped by cell, or a sub-grid's level
  uint32_t depth = 0;             ///< levels on the deepest path (0: nothing built)
};

/// Result of one step of the DDA at some level.
enum class Walk { Continue, Stop, Done };  // go on; a visitor stopped; the closest hit is found

class GridAccelerator final : public TraversalAccelerator<GridAccelerator> {
  friend class TraversalAccelerator<GridAccelerator>;

 public:
  GridAccelerator(std::span<const GeometryView> meshes, const GridConfig& config) : m_config(config) {
    validate(config);
    const BuildTimer timer;
    m_tris = gather_primitives(meshes, m_shapes);
    m_input_triangles = count_input_triangles(meshes);
    for (const auto& t : m_tris) m_bounds = merge(m_bounds, primitive_bounds(t));
    if (!m_tris.empty()) build();
    m_build_seconds = timer.seconds();
  }

  Bounds3f bounds() const override { return m_bounds; }

  AccelStats stats() const override {
    char config[200];
    const uint32_t* res = m_levels.empty() ? nullptr : m_levels[0].res;
    std::snprintf(config, sizeof config,
                  "lambda %g (coarse %g), levels %u, split above %u, resolution %ux%ux%u, %zu sub-grids",
                  double(m_config.lambda), double(m_config.coarse_lambda), m_config.max_depth,
                  m_config.split_threshold, res ? res[0] : 0, res ? res[1] : 0, res ? res[2] : 0,
                  m_levels.empty() ? size_t(0) : m_levels.size() - 1);
    AccelStats s =
        make_stats(m_stats, "grid", config, m_input_triangles,
                   m_offsets.size() * sizeof(uint32_t) + m_refs.size() * sizeof(uint32_t) +
                       m_levels.size() * sizeof(GridLevel) + m_tris.size() * sizeof(PrimitiveRecord),
                   m_build_seconds);
    s.shapes = m_shapes.size();
    return s;
  }

  /// The top grid's cells that meet the region, descending into sub-grids (visit_level).
  void visit_region(QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const override {
    if (!m_levels.empty()) visit_level(0, region, visitor, cost);
  }

 private:
  // ---- Region queries ---------------------------------------------------------------------------

  /// The cell of level `g` holding coordinate x along axis k, clamped into the grid (x may be
  /// infinite, never NaN).
  static int cell_index(const GridLevel& g, int k, double x) {
    if (!(g.cell_size[k] > 0)) return 0;
    return int(std::clamp(std::floor((x - g.lo[k]) / g.cell_size[k]), 0.0, double(g.res[k] - 1)));
  }

  /// The cells of level `g` that the box [lo, hi] covers, per axis, clamped into the grid.
  static void cell_range(const GridLevel& g, const double lo[3], const double hi[3], int first[3],
                         int last[3]) {
    for (int k = 0; k < 3; ++k) {
      first[k] = cell_index(g, k, lo[k]);
      last[k] = cell_index(g, k, hi[k]);
    }
  }

  /// Level `li` (the top grid, or a sub-grid a cell of its parent holds): nothing if its box
  /// does not meet the region; for a box, the cells it covers; for a ball, the cells in shells
  /// around its centre (visit_shells); for a ball with a non-finite centre, every cell that meets
  /// it. Recursion follows the sub-grids, at most GridConfig::max_depth levels deep.
  void visit_level(uint32_t li, QueryRegion& region, RegionVisitor& visitor, TraversalCost* cost) const {
    const GridLevel& g = m_levels[li];
    if (!region_meets(region, g.box)) return;
    if (!region.is_box && is_finite(region.centre)) {
      visit_shells(g, region, visitor, cost);
      return;
    }
    const Bounds3f& b = region.is_box ? region.box : g.box;
    const double lo[3] = {b.lo.x, b.lo.y, b.lo.z}, hi[3] = {b.hi.x, b.hi.y, b.hi.z};
    int first[3], last[3];
    cell_range(g, lo, hi, first, last);
    for (int z = first[2]; z <= last[2]; ++z)
      for (int y = first[1]; y <= last[1]; ++y)
        for (int x = first[0]; x <= last[0]; ++x) visit_cell(g, x, y, z, region, visitor, cost);
  }

  /// A ball over level `g`, in Chebyshev rings d = 0, 1, 2, ... of cells around c0, the cell of
  /// the centre clamped into the grid. Each ring is limited to the cells covered by the ball's
  /// bounding box at the current radius. Stops when the nearest point a ring's cells may hold
  /// lies beyond the current radius (padded as region_meets pads), or when the ring has no
  /// cell within that box (then neither have the rings after it, as the radius never grows).
  void visit_shells(const GridLevel& g, QueryRegion& region, RegionVisitor& visitor,
                    TraversalCost* cost) const {
    const double p[3] = {region.centre.x, region.centre.y, region.centre.z};
    int c0[3];
    double out2[3];  // squared distance from the centre to the grid's slab along each axis
    for (int k = 0; k < 3; ++k) {
      c0[k] = cell_index(g, k, p[k]);
      const double hi = g.lo[k] + g.res[k] * g.cell_size[k];
      const double o = p[k] < g.lo[k] ? g.lo[k] - p[k] : (p[k] > hi ? p[k] - hi : 0.0);
      out2[k] = o * o;
    }
    for (int d = 0;; ++d) {
      const double r2 = double(region.radius2) * double(kRegionPad);
      if (ring_distance2(g, p, c0, out2, d) > r2) return;
      const double r = std::sqrt(r2);
      const double lo[3] = {p[0] - r, p[1] - r, p[2] - r}, hi[3] = {p[0] + r, p[1] + r, p[2] + r};
      int first[3], last[3];  // contain c0: cell_index is monotone
      cell_range(g, lo, hi, first, last);
      bool reaches = d == 0;
      for (int k = 0; k < 3; ++k) {
        reaches = reaches || c0[k] - d >= first[k] || c0[k] + d <= last[k];
        first[k] = std::max(first[k], c0[k] - d);
        last[k] = std::min(last[k], c0[k] + d);
      }
      if (!reaches) return;
      // Ring d: the cells of [first, last] at Chebyshev distance d from c0. A row (fixed y, z)
      // on the ring's faces in y or z is whole; any other row holds its two ends along x.
      for (int z = first[2]; z <= last[2]; ++z)
        for (int y = first[1]; y <= last[1]; ++y) {
          if (std::abs(z - c0[2]) == d || std::abs(y - c0[1]) == d) {
            for (int x = first[0]; x <= last[0]; ++x) visit_cell(g, x, y, z, region, visitor, cost);
            continue;
          }
          if (c0[0] - d >= first[0]) visit_cell(g, c0[0] - d, y, z, region, visitor, cost);
          if (c0[0] + d <= last[0]) visit_cell(g, c0[0] + d, y, z, region, visitor, cost);
        }
    }
  }

  /// A lower bound on the squared distance from p to the cells of level `g` at Chebyshev
  /// distance d from cell c0 (+inf if there are none): such a cell lies d cells from c0 along
  /// some axis k, so beyond the plane on that side of the cells within d - 1 of c0, and inside
  /// the grid along the other axes (out2: p's squared distance to the grid's slab per axis).
  static double ring_distance2(const GridLevel& g, const double p[3], const int c0[3], const double out2[3],
                               int d) {
    if (d == 0) return out2[0] + out2[1] + out2[2];
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double others = out2[0] + out2[1] + out2[2] - out2[k];
      if (c0[k] + d <= int(g.res[k]) - 1) {
        const double gap = std::max(0.0, g.lo[k] + (c0[k] + d) * g.cell_size[k] - p[k]);
        best = std::min(best, gap * gap + others);
      }
      if (c0[k] - d >= 0) {
        const double gap = std::max(0.0, p[k] - (g.lo[k] + (c0[k] - d + 1) * g.cell_size[k]));
        best = std::min(best, gap * gap + others);
      }
    }
    return best;
  }

  /// Cell (x, y, z) of level `g`, if its box (rounded outward to float) meets the region:
  /// counted, then its sub-grid visited (visit_level) or each of its primitives offered.
  void visit_cell(const GridLevel& g, int x, int y, int z, QueryRegion& region, RegionVisitor& visitor,
                  TraversalCost* cost) const {
    const int idx[3] = {x, y, z};
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = g.lo[k] + idx[k] * g.cell_size[k];
      hi[k] = g.lo[k] + (idx[k] + 1) * g.cell_size[k];
    }
    if (!region_meets(region, outward_box(lo, hi))) return;
    if (cost) ++cost->nodes;
    const size_t c = g.first_cell + (size_t(z) * g.res[1] + size_t(y)) * g.res[0] + size_t(x);
    const uint32_t begin = m_offsets[c];
    if (begin & kChildBit) {
      visit_level(m_refs[begin & kOffsetMask], region, visitor, cost);
      return;
    }
    for (uint32_t i = begin, e = m_offsets[c + 1] & kOffsetMask; i < e; ++i) {
      const PrimitiveRecord& rec = m_tris[m_refs[i]];
      visitor.visit(rec.geom_id, record_prim_id(rec, m_shapes.data()), region);
    }
  }

  // ---- Ray traversal ----------------------------------------------------------------------------

  /// 3D-DDA over the cells the ray crosses, front to back, descending into sub-grids.
  /// `visit(w, tri)` is called once per triangle (mailboxed) and returns true to stop (any-hit).
  /// `best` is the current closest hit distance (updated by the visitor for closest-hit
  /// queries): traversal stops as soon as it lies within the current cell. Returns true iff a
  /// visitor returned true.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid || m_levels.empty()) return false;
    const RayBoxQuery q = prepare_box_query(ray);
    uint32_t mailbox[kMailboxSize];
    std::fill(mailbox, mailbox + kMailboxSize, Hit::kInvalidId);
    const double inv_dir[3] = {1.0 / double(ray.dir.x), 1.0 / double(ray.dir.y), 1.0 / double(ray.dir.z)};
    return walk(0, ray, w, q, inv_dir, best, visit, counter, mailbox) == Walk::Stop;
  }

  /// The DDA through level `li` over the ray's range clipped to the level's box and to `best`
  /// (sub-grids nest at most GridConfig::max_depth deep, so the recursion is bounded).
  /// `inv_dir` is 1 / ray.dir in double (infinite where a component is 0, then unused).
  template <typename Visit, typename Counter>
  Walk walk(uint32_t li, const Ray& ray, const WatertightRay& w, const RayBoxQuery& q,
            const double inv_dir[3], const float& best, Visit& visit, const Counter& counter,
            uint32_t* mailbox) const {
    const GridLevel& g = m_levels[li];
    float t0 = w.tnear, t1 = best;
    if (!intersect_box(g.box.lo, g.box.hi, q, t0, t1)) return Walk::Continue;

    // Set-up: entry cell, distance to the next cell boundary per axis, step per axis.
    int cell[3], step[3], out[3];
    double next[3];
    for (int k = 0; k < 3; ++k) {
      const double o = ray.org[k], d = ray.dir[k];
      const double p = o + d * double(std::max(t0, 0.0f));
      cell[k] = g.cell_size[k] > 0
                    ? int(std::clamp(std::floor((p - g.lo[k]) / g.cell_size[k]), 0.0, double(g.res[k] - 1)))
                    : 0;
      if (d > 0) {
        step[k] = 1;
        out[k] = int(g.res[k]);
        next[k] = (g.lo[k] + (cell[k] + 1) * g.cell_size[k] - o) * inv_dir[k];
      } else if (d < 0) {
        step[k] = -1;
        out[k] = -1;
        next[k] = (g.lo[k] + cell[k] * g.cell_size[k] - o) * inv_dir[k];
      } else {
        step[k] = 0;
        out[k] = -1;
        next[k] = kInfinity;
      }
    }

    // Walk.
    for (;;) {
      const size_t c =
          g.first_cell + (size_t(cell[2]) * g.res[1] + size_t(cell[1])) * g.res[0] + size_t(cell[0]);
      counter.node();
      const uint32_t begin = m_offsets[c];
      if (begin & kChildBit) {
        const Walk r = walk(m_refs[begin & kOffsetMask], ray, w, q, inv_dir, best, visit, counter, mailbox);
        if (r != Walk::Continue) return r;
      } else {
        for (uint32_t i = begin, e = m_offsets[c + 1] & kOffsetMask; i < e; ++i) {
          const uint32_t r = m_refs[i];
          uint32_t& slot = mailbox[r & (kMailboxSize - 1)];
          if (slot == r) continue;  // already tested against this ray
          slot = r;
          if (visit(w, m_tris[r])) return Walk::Stop;
        }
      }
      const int k = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
      if (double(best) <= next[k]) return Walk::Done;   // the closest hit lies in this cell
      if (next[k] > double(t1)) return Walk::Continue;  // the ray leaves the level or its range
      cell[k] += step[k];
      if (cell[k] == out[k]) return Walk::Continue;
      // Recompute from the cell index rather than accumulate, so long rays do not drift.
      next[k] =
          (g.lo[k] + (cell[k] + (step[k] > 0 ? 1 : 0)) * g.cell_size[k] - double(ray.org[k])) * inv_dir[k];
    }
  }

  // ---- Build ------------------------------------------------------------------------------------

  void build() {
    // The top grid spans the bounds widened by the rounding band (see common.h).
    m_band = rounding_band(m_bounds);
    std::vector<uint32_t> all(m_tris.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
    GridTree tree = build_tree(widen_for_rounding(m_bounds), all, 0);
    m_levels = std::move(tree.levels);
    m_offsets = std::move(tree.offsets);
    m_refs = std::move(tree.refs);

    LeafTally tally;
    for (size_t c = 0; c + 1 < m_offsets.size(); ++c)
      if (!(m_offsets[c] & kChildBit)) tally.add((m_offsets[c + 1] & kOffsetMask) - m_offsets[c]);
    tally.fill(m_stats);
    m_stats.nodes = m_offsets.size() - 1;
    m_stats.max_depth = tree.depth > 0 ? tree.depth - 1 : 0;
  }

  /// Cells per axis for a grid over `box` holding triangles `tris` (Cleary & Wyvill's rule,
  /// about lambda cells per triangle). Cells are cubes, except when the median triangle is
  /// longer than two cubic cells along exactly one axis (needles, not plates): along it a cell
  /// is as long as the median triangle and the other axes are refined to keep lambda N cells,
  /// so that long thin triangles along one direction are not each listed in hundreds of cells. Coarsened
  /// until the cells and the references bounded by bounding boxes fit `ref_limit`. False if nothing fits.
  bool choose_resolution(const Bounds3f& box, std::span<const uint32_t> tris, float lambda,
                         uint64_t ref_limit, uint32_t res[3]) const {
    const Vec3f ext = box.extent();
    const double max_ext = max_component(ext);
    bool flat[3];
    double s[3], volume = 1;
    int dims = 0;
    for (int k = 0; k < 3; ++k) {
      flat[k] = !(ext[k] > 1e-7 * max_ext);
      if (!flat[k]) volume *= ext[k], ++dims;
    }
    const double cells = std::max(double(lambda) * double(tris.size()), 1.0);
    const double cube = dims > 0 ? std::pow(volume / cells, 1.0 / dims) : 1.0;
    const Vec3f median = median_extent(tris);
    double fixed_cells = 1, free_volume = 1;
    int free_dims = 0;
    for (int k = 0; k < 3; ++k) {
      s[k] = cube;
      if (flat[k]) continue;
      if (median[k] > 2 * cube) {
        s[k] = std::min(double(median[k]), double(ext[k]));
        fixed_cells *= double(ext[k]) / s[k];
      } else {
        free_volume *= ext[k], ++free_dims;
      }
    }
    if (dims > 1 && free_dims == dims - 1) {
      const double free = std::pow(free_volume / std::max(cells / fixed_cells, 1.0), 1.0 / free_dims);
      for (int k = 0; k < 3; ++k)
        if (!flat[k] && !(median[k] > 2 * cube)) s[k] = free;
    } else {
      for (int k = 0; k < 3; ++k) s[k] = cube;
    }
    for (int iter = 0; iter < 200; ++iter) {
      uint64_t n = 1;
      for (int k = 0; k < 3; ++k) {
        res[k] = flat[k]
                     ? 1u
                     : uint32_t(std::clamp(std::ceil(ext[k] / s[k]), 1.0, double(m_config.max_resolution)));
        n *= res[k];
      }
      // Too many cells, or (for large overlapping triangles) too many candidate references:
      // coarsen. This bounds both build time and memory, whatever the input.
      if (n <= m_config.max_cells && bbox_references(tris, box, res, ref_limit) <= ref_limit) return true;
      if (n == 1) return false;
      for (double& v : s) v *= 1.25;
    }
    return false;
  }

  /// Per axis, the median extent of the triangles (of at most 1025 evenly spaced ones).
  Vec3f median_extent(std::span<const uint32_t> tris) const {
    if (tris.empty()) return {0, 0, 0};
    const size_t stride = std::max<size_t>(1, tris.size() / 1024);
    std::vector<float> e[3];
    for (size_t i = 0; i < tris.size(); i += stride) {
      const Vec3f x = primitive_bounds(m_tris[tris[i]]).extent();
      for (int k = 0; k < 3; ++k) e[k].push_back(x[k]);
    }
    Vec3f m;
    for (int k = 0; k < 3; ++k) {
      std::nth_element(e[k].begin(), e[k].begin() + e[k].size() / 2, e[k].end());
      m[k] = e[k][e[k].size() / 2];
    }
    return m;
  }

  /// Upper bound on the cell references of a grid of res cells over `box`: the cells each
  /// triangle's bounding box covers, summed (stops counting past the limit).
  uint64_t bbox_references(std::span<const uint32_t> tris, const Bounds3f& box, const uint32_t res[3],
                           uint64_t limit) const {
    double scale[3];
    for (int k = 0; k < 3; ++k) {
      const double e = double(box.hi[k]) - double(box.lo[k]);
      scale[k] = e > 0 ? res[k] / e : 0;
    }
    uint64_t total = 0;
    for (uint32_t i : tris) {
      const Bounds3f b = primitive_bounds(m_tris[i]);
      uint64_t c = 1;
      for (int k = 0; k < 3; ++k) {
        const double last = double(res[k]) - 1;
        const double lo = std::clamp(std::floor((b.lo[k] - box.lo[k]) * scale[k]), 0.0, last);
        const double hi = std::clamp(std::floor((b.hi[k] - box.lo[k]) * scale[k]), 0.0, last);
        c *= uint64_t(hi - lo) + 1;
      }
      total += c;
      if (total > limit) break;
    }
    return total;
  }

  /// The grid over `box` holding triangles `tris` at depth `depth` (0: the top grid), with a
  /// sub-grid for every cell holding more than split_threshold triangles while levels remain
  /// (Jevans & Wyvill, "Adaptive voxel subdivision for ray tracing", Graphics Interface 1989;
  /// Kalojanov, Billeter & Slusallek, "Two-Level Grids for Ray Tracing on GPUs", Eurographics
  /// 2011). A sub-grid spans its cell clipped to its triangles' bounds. Empty (depth 0) when a
  /// sub-grid cannot be finer than one cell.
  GridTree build_tree(const Bounds3f& box, std::span<const uint32_t> tris, uint32_t depth) const {
    GridTree tree;
    // Phase 1: resolution and cell geometry.
    GridLevel g;
    const uint64_t ref_limit = depth == 0 ? kMaxCandidateRefs : kChildRefsPerTriangle * tris.size();
    const float lambda = depth + 1 < m_config.max_depth ? m_config.coarse_lambda : m_config.lambda;
    if (!choose_resolution(box, tris, lambda, ref_limit, g.res) && depth > 0) return tree;
    if (depth > 0 && g.res[0] * g.res[1] * g.res[2] == 1) return tree;
    g.box = box;
    double max_abs = 0;
    for (int k = 0; k < 3; ++k) {
      g.lo[k] = box.lo[k];
      g.cell_size[k] = (double(box.hi[k]) - double(box.lo[k])) / g.res[k];
      max_abs = std::max({max_abs, std::fabs(double(box.lo[k])), std::fabs(double(box.hi[k]))});
    }
    // Cells are widened by a margin for the overlap test, so a triangle that touches a cell
    // within rounding error is listed in it (a ray may enter either neighbour).
    double margin[3];
    for (int k = 0; k < 3; ++k) margin[k] = 1e-5 * g.cell_size[k] + 1e-6 * max_abs + 1e-30;
    const size_t ncells = size_t(g.res[0]) * g.res[1] * g.res[2];
    auto cell_box = [&](const int idx[3], double blo[3], double bhi[3]) {
      for (int k = 0; k < 3; ++k) {
        blo[k] = g.lo[k] + idx[k] * g.cell_size[k] - margin[k];
        bhi[k] = g.lo[k] + (idx[k] + 1) * g.cell_size[k] + margin[k];
      }
    };

    // Phase 2: per triangle, the cells it overlaps (counted, then written), in parallel.
    auto for_each_cell = [&](const PrimitiveRecord& t, auto&& f) {
      const Bounds3f b = primitive_bounds(t);
      int lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        const double last = double(g.res[k]) - 1;
        lo[k] = g.cell_size[k] > 0
                    ? int(std::clamp(std::floor((b.lo[k] - margin[k] - g.lo[k]) / g.cell_size[k]), 0.0, last))
                    : 0;
        hi[k] = g.cell_size[k] > 0
                    ? int(std::clamp(std::floor((b.hi[k] + margin[k] - g.lo[k]) / g.cell_size[k]), 0.0, last))
                    : 0;
      }
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            const int idx[3] = {x, y, z};
            double blo[3], bhi[3];
            cell_box(idx, blo, bhi);
            if (is_shape(t) ? box_overlap(blo, bhi, t.a, t.b) : triangle_box_overlap(blo, bhi, t.a, t.b, t.c))
              f(uint32_t((size_t(z) * g.res[1] + size_t(y)) * g.res[0] + size_t(x)));
          }
    };
    std::vector<uint64_t> tri_offset(tris.size() + 1, 0);
    tbb::parallel_for(size_t(0), tris.size(), [&](size_t i) {
      uint64_t cnt = 0;
      for_each_cell(m_tris[tris[i]], [&](uint32_t) { ++cnt; });
      tri_offset[i + 1] = cnt;
    });
    for (size_t i = 0; i < tris.size(); ++i) tri_offset[i + 1] += tri_offset[i];
    const uint64_t total = tri_offset.back();
    if (total >= kChildBit)
      throw std::runtime_error("grid: more than 2^31 cell references; lower lambda or max_cells");
    std::vector<uint32_t> pair_cell(total);
    tbb::parallel_for(size_t(0), tris.size(), [&](size_t i) {
      uint64_t o = tri_offset[i];
      for_each_cell(m_tris[tris[i]], [&](uint32_t c) { pair_cell[o++] = c; });
    });

    // Phase 3: counting sort by cell, keeping triangle order within each cell (deterministic).
    std::vector<uint32_t> offsets(ncells + 1, 0), refs(total);
    for (uint32_t c : pair_cell) ++offsets[c + 1];
    for (size_t c = 0; c < ncells; ++c) offsets[c + 1] += offsets[c];
    std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (size_t i = 0; i < tris.size(); ++i)
      for (uint64_t j = tri_offset[i]; j < tri_offset[i + 1]; ++j) refs[fill[pair_cell[j]]++] = tris[i];

    // Phase 4: sub-grids of the crowded cells, in parallel, over each cell's box clipped to
    // the bounds of its triangles (widened by the rounding band).
    std::vector<uint32_t> split;
    if (depth + 1 < m_config.max_depth)
      for (size_t c = 0; c < ncells; ++c)
        if (offsets[c + 1] - offsets[c] > m_config.split_threshold) split.push_back(uint32_t(c));
    std::vector<GridTree> children(split.size());
    tbb::parallel_for(size_t(0), split.size(), [&](size_t i) {
      const uint32_t c = split[i];
      const std::span<const uint32_t> in(refs.data() + offsets[c], offsets[c + 1] - offsets[c]);
      Bounds3f tb;
      for (uint32_t t : in) tb = merge(tb, primitive_bounds(m_tris[t]));
      const int idx[3] = {int(c % g.res[0]), int(c / g.res[0] % g.res[1]), int(c / g.res[0] / g.res[1])};
      double blo[3], bhi[3];
      cell_box(idx, blo, bhi);
      for (int k = 0; k < 3; ++k) {
        blo[k] = std::max(blo[k], double(tb.lo[k]) - m_band);
        bhi[k] = std::min(bhi[k], double(tb.hi[k]) + m_band);
      }
      children[i] = build_tree(outward_box(blo, bhi), in, depth + 1);
    });

    // Phase 5: this level's cells and references, then each sub-grid's after them (sub-grid
    // i becomes level level_base[i]).
    std::vector<uint32_t> level_base(split.size());
    uint32_t levels = 1;
    for (size_t i = 0; i < split.size(); ++i) {
      level_base[i] = levels;
      levels += uint32_t(children[i].levels.size());
    }
    tree.levels.push_back(g);
    tree.offsets.reserve(ncells + 1);
    size_t next_split = 0;
    for (size_t c = 0; c < ncells; ++c) {
      const bool split_here = next_split < split.size() && split[next_split] == c;
      if (split_here && children[next_split].depth > 0) {
        tree.offsets.push_back(uint32_t(tree.refs.size()) | kChildBit);
        tree.refs.push_back(level_base[next_split]);
      } else {
        tree.offsets.push_back(uint32_t(tree.refs.size()));
        tree.refs.insert(tree.refs.end(), refs.begin() + offsets[c], refs.begin() + offsets[c + 1]);
      }
      next_split += split_here;
    }
    uint32_t depth_below = 0;
    for (size_t i = 0; i < split.size(); ++i) {
      GridTree& ch = children[i];
      if (ch.depth == 0) continue;
      const uint32_t cell_base = uint32_t(tree.offsets.size()), ref_base = uint32_t(tree.refs.size());
      for (GridLevel l : ch.levels) {
        l.first_cell += cell_base;
        tree.levels.push_back(l);
      }
      for (size_t c = 0; c + 1 < ch.offsets.size(); ++c) {
        const uint32_t o = ch.offsets[c];
        if (o & kChildBit) ch.refs[o & kOffsetMask] += level_base[i];
        tree.offsets.push_back(((o & kOffsetMask) + ref_base) | (o & kChildBit));
      }
      tree.refs.insert(tree.refs.end(), ch.refs.begin(), ch.refs.end());
      depth_below = std::max(depth_below, ch.depth);
    }
    if (tree.refs.size() >= kChildBit)
      throw std::runtime_error("grid: more than 2^31 cell references; lower lambda or max_cells");
    tree.offsets.push_back(uint32_t(tree.refs.size()));
    tree.depth = 1 + depth_below;
    return tree;
  }

  GridConfig m_config;
  std::vector<PrimitiveRecord> m_tris;
  std::vector<GridLevel> m_levels;  // the top grid first, then the sub-grids
  std::vector<uint32_t> m_offsets;  // per cell of every level: first reference (| kChildBit); + 1
  std::vector<uint32_t> m_refs;     // triangle indices grouped by cell, or a sub-grid's level
  Bounds3f m_bounds;                // exact bounds of the triangles
  float m_band = 0;                 // rounding band of m_bounds: sub-grid boxes are widened by it
  uint64_t m_input_triangles = 0;
  AccelStats m_stats;
  double m_build_seconds = 0;
};

}  // namespace

void validate(const GridConfig& c) {
  if (!(c.lambda > 0 && c.lambda <= 64)) throw std::invalid_argument("grid: lambda must be in (0, 64]");
  if (c.max_resolution < 1 || c.max_resolution > 4096)
    throw std::invalid_argument("grid: max_resolution must be in [1, 4096]");
  if (c.max_cells < 1 || c.max_cells > (1ull << 30))
    throw std::invalid_argument("grid: max_cells must be in [1, 2^30]");
  if (!(c.coarse_lambda > 0 && c.coarse_lambda <= 64))
    throw std::invalid_argument("grid: coarse_lambda must be in (0, 64]");
  if (c.max_depth < 1 || c.max_depth > 4) throw std::invalid_argument("grid: max_depth must be in [1, 4]");
  if (c.split_threshold < 1 || c.split_threshold > (1u << 20))
    throw std::invalid_argument("grid: split_threshold must be in [1, 2^20]");
}

std::unique_ptr<Accelerator> make_grid_accelerator(std::span<const GeometryView> meshes,
                                                   const GridConfig& config) {
  return std::make_unique<GridAccelerator>(meshes, config);
}

}  // namespace penumbra
