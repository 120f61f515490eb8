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

constexpr int kMailboxSize = 64;  // power of two

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
    char config[160];
    std::snprintf(config, sizeof config, "lambda %g, resolution %ux%ux%u", double(m_config.lambda), m_res[0],
                  m_res[1], m_res[2]);
    AccelStats s = make_stats(m_stats, "grid", config, m_input_triangles,
                              m_offsets.size() * sizeof(uint32_t) + m_refs.size() * sizeof(uint32_t) +
                                  m_tris.size() * sizeof(PrimitiveRecord),
                              m_build_seconds);
    s.shapes = m_shapes.size();
    return s;
  }

 private:
  /// 3D-DDA over the cells the ray crosses, front to back. `visit(w, tri)` is called once per
  /// triangle (mailboxed) and returns true to stop (any-hit). `best` is the current closest hit
  /// distance (updated by the visitor for closest-hit queries): traversal stops as soon as it
  /// lies within the current cell. Returns true iff a visitor returned true.
  template <typename Visit, typename Counter, bool AnyHit>
  bool traverse(const Ray& ray, const float& best, Visit&& visit, const Counter& counter,
                std::bool_constant<AnyHit>) const {
    const WatertightRay w = prepare_watertight(ray);
    if (!w.valid || m_tris.empty()) return false;
    const RayBoxQuery q = prepare_box_query(ray);
    float t0 = w.tnear, t1 = ray.tfar;
    if (!intersect_box(m_grid.lo, m_grid.hi, q, t0, t1)) return false;

    // Set-up: entry cell, distance to the next cell boundary per axis, step per axis.
    int cell[3], step[3], out[3];
    double next[3];
    for (int k = 0; k < 3; ++k) {
      const double o = ray.org[k], d = ray.dir[k];
      const double p = o + d * double(std::max(t0, 0.0f));
      cell[k] = m_cell_size[k] > 0
                    ? int(std::clamp(std::floor((p - m_lo[k]) / m_cell_size[k]), 0.0, double(m_res[k] - 1)))
                    : 0;
      if (d > 0) {
        step[k] = 1;
        out[k] = int(m_res[k]);
        next[k] = (m_lo[k] + (cell[k] + 1) * m_cell_size[k] - o) / d;
      } else if (d < 0) {
        step[k] = -1;
        out[k] = -1;
        next[k] = (m_lo[k] + cell[k] * m_cell_size[k] - o) / d;
      } else {
        step[k] = 0;
        out[k] = -1;
        next[k] = kInfinity;
      }
    }
    uint32_t mailbox[kMailboxSize];
    std::fill(mailbox, mailbox + kMailboxSize, Hit::kInvalidId);

    // Walk.
    for (;;) {
      const size_t c = (size_t(cell[2]) * m_res[1] + size_t(cell[1])) * m_res[0] + size_t(cell[0]);
      counter.node();
      for (uint32_t i = m_offsets[c], e = m_offsets[c + 1]; i < e; ++i) {
        const uint32_t r = m_refs[i];
        uint32_t& slot = mailbox[r & (kMailboxSize - 1)];
        if (slot == r) continue;  // already tested against this ray
        slot = r;
        if (visit(w, m_tris[r])) return true;
      }
      const int k = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
      if (double(best) <= next[k]) break;  // the closest hit lies in this cell
      if (next[k] > double(t1)) break;     // the ray leaves the grid or its range
      cell[k] += step[k];
      if (cell[k] == out[k]) break;
      // Recompute from the cell index rather than accumulate, so long rays do not drift.
      next[k] = (m_lo[k] + (cell[k] + (step[k] > 0 ? 1 : 0)) * m_cell_size[k] - double(ray.org[k])) /
                double(ray.dir[k]);
    }
    return false;
  }

  void build() {
    // Phase 1: resolution. Cell size s with (prod of non-flat extents) / s^k = lambda N. The
    // grid spans the bounds widened by the rounding band (see common.h).
    m_grid = widen_for_rounding(m_bounds);
    const Vec3f ext = m_grid.extent();
    const double max_ext = max_component(ext);
    double volume = 1;
    int dims = 0;
    for (int k = 0; k < 3; ++k)
      if (ext[k] > 1e-7 * max_ext) volume *= ext[k], ++dims;
    const double n = double(m_tris.size());
    double s = dims > 0 ? std::pow(volume / (double(m_config.lambda) * n), 1.0 / dims) : 1.0;
    for (;;) {
      uint64_t cells = 1;
      for (int k = 0; k < 3; ++k) {
        const bool flat = !(ext[k] > 1e-7 * max_ext);
        m_res[k] =
            flat ? 1u : uint32_t(std::clamp(std::ceil(ext[k] / s), 1.0, double(m_config.max_resolution)));
        cells *= m_res[k];
      }
      // Too many cells, or (for scenes of large overlapping triangles) too many candidate
      // cell references, bounded by the triangles' bounding boxes: coarsen. This bounds both
      // build time and memory, whatever the input.
      if (cells <= m_config.max_cells && bbox_references(ext, s) <= kMaxCandidateRefs) break;
      s *= 1.25;
    }
    double max_abs = 0;
    for (int k = 0; k < 3; ++k) {
      m_lo[k] = m_grid.lo[k];
      m_cell_size[k] = (double(m_grid.hi[k]) - double(m_grid.lo[k])) / m_res[k];
      max_abs = std::max({max_abs, std::fabs(double(m_grid.lo[k])), std::fabs(double(m_grid.hi[k]))});
    }
    // Cells are widened by a margin for the overlap test, so a triangle that touches a cell
    // within rounding error is listed in it (a ray may enter either neighbour).
    double margin[3];
    for (int k = 0; k < 3; ++k) margin[k] = 1e-5 * m_cell_size[k] + 1e-6 * max_abs + 1e-30;
    const size_t ncells = size_t(m_res[0]) * m_res[1] * m_res[2];

    // Phase 2: per triangle, the cells it overlaps (counted, then written), in parallel.
    auto cell_range = [&](const PrimitiveRecord& t, int lo[3], int hi[3]) {
      const Bounds3f b = primitive_bounds(t);
      for (int k = 0; k < 3; ++k) {
        if (m_cell_size[k] <= 0) {
          lo[k] = hi[k] = 0;
          continue;
        }
        const int last = int(m_res[k]) - 1;
        lo[k] =
            int(std::clamp(std::floor((b.lo[k] - margin[k] - m_lo[k]) / m_cell_size[k]), 0.0, double(last)));
        hi[k] =
            int(std::clamp(std::floor((b.hi[k] + margin[k] - m_lo[k]) / m_cell_size[k]), 0.0, double(last)));
      }
    };
    auto for_each_cell = [&](const PrimitiveRecord& t, auto&& f) {
      int lo[3], hi[3];
      cell_range(t, lo, hi);
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            const int idx[3] = {x, y, z};
            double blo[3], bhi[3];
            for (int k = 0; k < 3; ++k) {
              blo[k] = m_lo[k] + idx[k] * m_cell_size[k] - margin[k];
              bhi[k] = m_lo[k] + (idx[k] + 1) * m_cell_size[k] + margin[k];
            }
            if (is_shape(t) ? box_overlap(blo, bhi, t.a, t.b) : triangle_box_overlap(blo, bhi, t.a, t.b, t.c))
              f(uint32_t((size_t(z) * m_res[1] + size_t(y)) * m_res[0] + size_t(x)));
          }
    };
    std::vector<uint64_t> tri_offset(m_tris.size() + 1, 0);
    tbb::parallel_for(size_t(0), m_tris.size(), [&](size_t i) {
      uint64_t cnt = 0;
      for_each_cell(m_tris[i], [&](uint32_t) { ++cnt; });
      tri_offset[i + 1] = cnt;
    });
    for (size_t i = 0; i < m_tris.size(); ++i) tri_offset[i + 1] += tri_offset[i];
    const uint64_t total = tri_offset.back();
    if (total >= 0xffffffffull)
      throw std::runtime_error("grid: more than 2^32 cell references; lower lambda or max_cells");
    std::vector<uint32_t> pair_cell(total);
    tbb::parallel_for(size_t(0), m_tris.size(), [&](size_t i) {
      uint64_t o = tri_offset[i];
      for_each_cell(m_tris[i], [&](uint32_t c) { pair_cell[o++] = c; });
    });

    // Phase 3: counting sort by cell, keeping triangle order within each cell (deterministic).
    m_offsets.assign(ncells + 1, 0);
    for (uint32_t c : pair_cell) ++m_offsets[c + 1];
    for (size_t c = 0; c < ncells; ++c) m_offsets[c + 1] += m_offsets[c];
    m_refs.resize(total);
    std::vector<uint32_t> fill(m_offsets.begin(), m_offsets.end() - 1);
    for (size_t i = 0; i < m_tris.size(); ++i)
      for (uint64_t j = tri_offset[i]; j < tri_offset[i + 1]; ++j) m_refs[fill[pair_cell[j]]++] = uint32_t(i);

    LeafTally tally;
    for (size_t c = 0; c < ncells; ++c) tally.add(m_offsets[c + 1] - m_offsets[c]);
    tally.fill(m_stats);
    m_stats.nodes = ncells;
  }

  /// Upper bound on the cell references with cell size s: the cells each triangle's bounding
  /// box covers, summed (stops counting past the limit).
  uint64_t bbox_references(const Vec3f& ext, double s) const {
    uint64_t total = 0;
    for (const auto& t : m_tris) {
      const Bounds3f b = primitive_bounds(t);
      uint64_t c = 1;
      for (int k = 0; k < 3; ++k) {
        const double res = std::ceil(ext[k] / s);
        c *= uint64_t(std::min(res, std::floor((b.hi[k] - b.lo[k]) / s) + 2.0));
      }
      total += c;
      if (total > kMaxCandidateRefs) break;
    }
    return total;
  }

  static constexpr uint64_t kMaxCandidateRefs = 1ull << 26;  // 256 MiB of references at most

  GridConfig m_config;
  std::vector<PrimitiveRecord> m_tris;
  std::vector<uint32_t> m_offsets;  // per cell (x fastest): first reference; ncells + 1 entries
  std::vector<uint32_t> m_refs;     // triangle indices, grouped by cell
  Bounds3f m_bounds;                // exact bounds of the triangles
  Bounds3f m_grid;                  // the grid's box: m_bounds widened by the rounding band
  double m_lo[3] = {0, 0, 0}, m_cell_size[3] = {0, 0, 0};
  uint32_t m_res[3] = {0, 0, 0};
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
}

std::unique_ptr<Accelerator> make_grid_accelerator(std::span<const GeometryView> meshes,
                                                   const GridConfig& config) {
  return std::make_unique<GridAccelerator>(meshes, config);
}

}  // namespace penumbra
