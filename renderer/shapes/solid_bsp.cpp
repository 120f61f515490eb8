// Solid BSP trees of closed meshes (Fuchs, Kedem & Naylor 1980 autopartition; Thibault & Naylor
// 1987 IN/OUT leaves): the mesh checks (closed, consistently oriented, outward), the build in
// double with explicit work lists, the point-in-solid walk, and SolidMesh's distance BVH with
// exact point-triangle distances (Ericson, "Real-Time Collision Detection", 2005, 5.1.5).
#include "renderer/shapes/solid_bsp.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "renderer/accel/polytope.h"

namespace penumbra {

namespace {

struct D3 {
  double x = 0, y = 0, z = 0;
};
D3 operator+(D3 a, D3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
D3 operator-(D3 a, D3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
D3 operator*(D3 a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(D3 a, D3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
D3 cross(D3 a, D3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double length(D3 a) {
  return std::sqrt(dot(a, a));
}
D3 to_d(Vec3f v) {
  return {v.x, v.y, v.z};
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

[[noreturn]] void refuse(const std::string& reason) {
  throw SolidMeshError(reason, false);
}

void validate(const SolidBspConfig& c) {
  const auto bad = [](const char* field, const std::string& range, const std::string& value) {
    throw std::invalid_argument(std::string("SolidBspConfig::") + field + " must be " + range + " (got " +
                                value + ")");
  };
  if (c.candidates < 1 || c.candidates > 4096)
    bad("candidates", "in [1, 4096]", std::to_string(c.candidates));
  if (c.score_sample < 1 || c.score_sample > (1 << 20))
    bad("score_sample", "in [1, 1048576]", std::to_string(c.score_sample));
  if (!(c.split_weight >= 0 && c.split_weight <= 1e6))
    bad("split_weight", "in [0, 1e6]", num(c.split_weight));
  if (!(c.relative_epsilon >= 1e-12 && c.relative_epsilon <= 1e-2))
    bad("relative_epsilon", "in [1e-12, 0.01]", num(c.relative_epsilon));
}

// ---------------------------------------------------------------------------------------------
// Mesh preparation: index and vertex checks, welding, topology, orientation.

struct PreparedMesh {
  std::vector<Vec3f> positions;    // welded vertices
  std::vector<uint32_t> original;  // welded vertex -> its first original index
  std::vector<uint32_t> tris;      // 3 per triangle (welded ids, three distinct), outward once oriented
  std::vector<uint8_t> zero_area;  // per triangle of tris
  uint64_t repeated = 0;           // triangles dropped for repeated (welded) vertices
  Bounds3f bounds;
  double diagonal = 0;
  double volume = 0;
  bool flipped = false;
};

// Welds vertices at exactly equal positions (the indices used; -0 equals 0) and rewrites the
// triangles on the welded vertices, dropping those whose vertices repeat.
void weld(std::span<const Vec3f> positions, std::span<const uint32_t> indices, PreparedMesh& out) {
  std::vector<uint32_t> used(indices.begin(), indices.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  for (const uint32_t v : used)
    if (!is_finite(positions[v]))
      refuse("has a non-finite vertex " + std::to_string(v) + " (" + num(positions[v].x) + ", " +
             num(positions[v].y) + ", " + num(positions[v].z) + ")");
  const auto less = [&](uint32_t a, uint32_t b) {
    const Vec3f p = positions[a], q = positions[b];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  std::sort(used.begin(), used.end(), less);
  std::vector<uint32_t> welded(positions.size(), 0);
  for (size_t i = 0; i < used.size(); ++i) {
    if (i == 0 || !(positions[used[i]] == positions[used[i - 1]])) {
      out.positions.push_back(positions[used[i]]);
      out.original.push_back(used[i]);  // the smallest index of its group: ties sort by index
    }
    welded[used[i]] = uint32_t(out.positions.size() - 1);
  }
  out.tris.reserve(indices.size());
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const uint32_t a = welded[indices[t]], b = welded[indices[t + 1]], c = welded[indices[t + 2]];
    if (a == b || b == c || a == c) {
      ++out.repeated;
      continue;
    }
    out.tris.insert(out.tris.end(), {a, b, c});
  }
}

// Every edge must be used by exactly one triangle in each direction. Reports the offending edge
// with the smallest (original) vertex indices.
void check_closed(const PreparedMesh& m) {
  struct Edge {
    uint32_t lo, hi;
    bool forward;  // the triangle runs lo -> hi
  };
  std::vector<Edge> edges;
  edges.reserve(m.tris.size());
  for (size_t t = 0; t < m.tris.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.tris[t + size_t(k)], b = m.tris[t + size_t((k + 1) % 3)];
      edges.push_back({std::min(a, b), std::max(a, b), a < b});
    }
  std::sort(edges.begin(), edges.end(), [](const Edge& e, const Edge& f) {
    return e.lo != f.lo ? e.lo < f.lo : (e.hi != f.hi ? e.hi < f.hi : e.forward < f.forward);
  });
  bool found = false;
  std::array<uint32_t, 2> worst{};
  std::string reason;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i, forward = 0;
    for (; j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi; ++j)
      forward += edges[j].forward;
    const size_t count = j - i, backward = count - forward;
    if (forward != 1 || backward != 1) {
      const uint32_t oa = m.original[edges[i].lo], ob = m.original[edges[i].hi];
      const std::array<uint32_t, 2> key{std::min(oa, ob), std::max(oa, ob)};
      if (!found || key < worst) {
        found = true;
        worst = key;
        const std::string edge = "edge (" + std::to_string(key[0]) + ", " + std::to_string(key[1]) + ")";
        if (count == 2) {  // both one way
          const bool lo_to_hi = forward == 2;
          const uint32_t from = lo_to_hi ? oa : ob, to = lo_to_hi ? ob : oa;
          reason = "is not consistently oriented: " + edge +
                   " is used by 2 triangles in the same direction (" + std::to_string(from) + " -> " +
                   std::to_string(to) + ")";
        } else {
          reason = "is not closed: " + edge + " is used by " + std::to_string(count) +
                   (count == 1 ? " triangle"
                               : " triangles (a closed surface uses each edge twice, once each way)");
        }
      }
    }
    i = j;
  }
  if (found) refuse(reason);
}

PreparedMesh prepare(std::span<const Vec3f> positions, std::span<const uint32_t> indices) {
  if (indices.size() % 3) refuse("has " + std::to_string(indices.size()) + " indices, not a multiple of 3");
  if (indices.empty()) refuse("has no triangles");
  for (size_t k = 0; k < indices.size(); ++k)
    if (indices[k] >= positions.size())
      refuse("has index " + std::to_string(indices[k]) + " at indices[" + std::to_string(k) +
             "] out of range (" + std::to_string(positions.size()) + " vertices)");
  PreparedMesh m;
  weld(positions, indices, m);
  if (m.tris.empty()) refuse("has no triangles of non-zero area");
  check_closed(m);
  for (const Vec3f& p : m.positions) m.bounds = merge(m.bounds, p);
  m.diagonal = length(to_d(m.bounds.hi) - to_d(m.bounds.lo));
  // Areas and the signed volume (about the box centre, against cancellation).
  const D3 o = to_d(m.bounds.center());
  const double area_floor = 1e-14 * m.diagonal * m.diagonal;
  m.zero_area.assign(m.tris.size() / 3, 0);
  bool any_area = false;
  double volume6 = 0;
  for (size_t t = 0; t < m.tris.size(); t += 3) {
    const D3 a = to_d(m.positions[m.tris[t]]) - o, b = to_d(m.positions[m.tris[t + 1]]) - o,
             c = to_d(m.positions[m.tris[t + 2]]) - o;
    const bool zero = !(length(cross(b - a, c - a)) > area_floor);
    m.zero_area[t / 3] = zero;
    any_area = any_area || !zero;
    volume6 += dot(a, cross(b, c));
  }
  if (!any_area) refuse("has no triangles of non-zero area");
  m.volume = volume6 / 6;
  if (!(std::abs(m.volume) > 1e-12 * m.diagonal * m.diagonal * m.diagonal))
    refuse("encloses no volume (signed volume " + num(m.volume) + ")");
  if (m.volume < 0) {  // wound inwards: reverse every triangle
    for (size_t t = 0; t < m.tris.size(); t += 3) std::swap(m.tris[t + 1], m.tris[t + 2]);
    m.volume = -m.volume;
    m.flipped = true;
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// The BSP build.

struct Plane {
  D3 n;
  double d = 0;
};

// A convex polygon: `count` vertices from `first` in the vertex pool, lying in planes[plane]
// (its triangle's), and a sphere holding it (most polygons lie wholly on one side of a plane
// farther than its radius: one test instead of one per vertex).
struct Poly {
  uint32_t plane = 0, first = 0, count = 0;
  D3 centre;
  double radius = 0;
};

enum class Side { Coplanar, Front, Back, Spanning };

// Largest node and fragment budget: the vertex pool (at most 16 per budget unit) stays within
// 32-bit offsets.
constexpr uint64_t kMaxBudget = uint64_t(1) << 27;

class BspBuilder {
 public:
  BspBuilder(const PreparedMesh& m, const SolidBspConfig& config, SolidBsp& out)
      : m_config(config), m_out(out) {
    m_eps = config.relative_epsilon * m.diagonal;
    for (size_t t = 0; t < m.tris.size(); t += 3) {
      if (m.zero_area[t / 3]) continue;
      const D3 a = to_d(m.positions[m.tris[t]]), b = to_d(m.positions[m.tris[t + 1]]),
               c = to_d(m.positions[m.tris[t + 2]]);
      const D3 n = cross(b - a, c - a);
      const D3 unit = n * (1 / length(n));
      const D3 centroid = (a + b + c) * (1.0 / 3);
      m_planes.push_back({unit, dot(unit, centroid)});
      m_pool.insert(m_pool.end(), {a, b, c});
      m_root.push_back(make_poly(uint32_t(m_planes.size() - 1), uint32_t(m_pool.size() - 3), 3));
    }
    m_triangles = m_root.size();
    const uint64_t automatic = 8 * m_triangles + 1024;
    m_budget = std::min<uint64_t>(config.max_nodes > 0 ? config.max_nodes : automatic, kMaxBudget);
    m_work_budget = config.max_classifications;
  }

  void build();

 private:
  struct Work {
    std::vector<Poly> polys;
    int32_t parent = -1;  // -1: the root
    bool front = false;   // which child of the parent
    int depth = 1;
  };

  double side_of(const Plane& pl, const D3& v) const { return dot(pl.n, v) - pl.d; }
  Poly make_poly(uint32_t plane, uint32_t first, uint32_t count) const;
  Side classify(const Poly& p, const Plane& pl);
  uint32_t choose_splitter(const std::vector<Poly>& polys);
  void split(const Poly& p, const Plane& pl, Poly& front, Poly& back);
  // `what` beyond its `limit`, set by the config field `field`.
  [[noreturn]] void over_budget(const std::string& what, uint64_t limit, const std::string& field) const {
    throw SolidMeshError("needs more than " + std::to_string(limit) + " " + what + " (" + field + ", for " +
                             std::to_string(m_triangles) + " triangles)",
                         true);
  }
  std::string nodes_field() const { return "SolidBspConfig::max_nodes = " + std::to_string(m_budget); }

  const SolidBspConfig& m_config;
  SolidBsp& m_out;
  double m_eps = 0;
  std::vector<Plane> m_planes;
  std::vector<D3> m_pool, m_scratch;
  std::vector<Poly> m_root;
  uint64_t m_triangles = 0, m_budget = 0, m_work_budget = 0;
};

// The polygon over pool[first, first + count) with its centroid and the distance to its farthest
// vertex (rounded up).
Poly BspBuilder::make_poly(uint32_t plane, uint32_t first, uint32_t count) const {
  Poly p{plane, first, count, {}, 0};
  for (uint32_t i = 0; i < count; ++i) p.centre = p.centre + m_pool[first + i];
  p.centre = p.centre * (1.0 / count);
  for (uint32_t i = 0; i < count; ++i) p.radius = std::max(p.radius, length(m_pool[first + i] - p.centre));
  p.radius = p.radius * (1 + 1e-9) + 1e-300;
  return p;
}

Side BspBuilder::classify(const Poly& p, const Plane& pl) {
  if (++m_out.stats.classifications > m_work_budget && m_work_budget > 0)
    over_budget("polygon-plane tests", m_work_budget,
                "SolidBspConfig::max_classifications = " + std::to_string(m_work_budget));
  const double centre = side_of(pl, p.centre);
  if (centre > p.radius + m_eps) return Side::Front;
  if (centre < -(p.radius + m_eps)) return Side::Back;
  bool front = false, back = false;
  for (uint32_t i = 0; i < p.count; ++i) {
    const double s = side_of(pl, m_pool[p.first + i]);
    front = front || s > m_eps;
    back = back || s < -m_eps;
  }
  return front ? (back ? Side::Spanning : Side::Front) : (back ? Side::Back : Side::Coplanar);
}

// The plane among up to `candidates` polygons evenly spaced in the list with the lowest score
// split_weight x splits + |front - back| over up to `score_sample` polygons evenly spaced; ties
// keep the earlier candidate.
uint32_t BspBuilder::choose_splitter(const std::vector<Poly>& polys) {
  const uint64_t n = polys.size();
  if (n == 1) return polys[0].plane;
  const uint64_t k = std::min<uint64_t>(uint64_t(m_config.candidates), n);
  const uint64_t s = std::min<uint64_t>(uint64_t(m_config.score_sample), n);
  double best_score = std::numeric_limits<double>::infinity();
  uint32_t best = polys[0].plane;
  for (uint64_t j = 0; j < k; ++j) {
    const uint32_t plane = polys[size_t(j * n / k)].plane;
    const Plane& pl = m_planes[plane];
    uint64_t front = 0, back = 0, spans = 0;
    for (uint64_t i = 0; i < s; ++i) switch (classify(polys[size_t(i * n / s)], pl)) {
        case Side::Front:
          ++front;
          break;
        case Side::Back:
          ++back;
          break;
        case Side::Spanning:
          ++spans;
          break;
        case Side::Coplanar:
          break;
      }
    const double score = m_config.split_weight * double(spans) + std::abs(double(front) - double(back));
    if (score < best_score) best_score = score, best = plane;
  }
  return best;
}

// Cuts a spanning polygon in two: vertices on the plane go to both parts, each edge crossing it
// adds the crossing point to both.
void BspBuilder::split(const Poly& p, const Plane& pl, Poly& front, Poly& back) {
  m_scratch.assign(m_pool.begin() + p.first, m_pool.begin() + p.first + p.count);
  const auto cls = [&](double s) { return s > m_eps ? 1 : (s < -m_eps ? -1 : 0); };
  std::vector<D3> f, b;
  for (uint32_t i = 0; i < p.count; ++i) {
    const D3 vi = m_scratch[i], vj = m_scratch[(i + 1) % p.count];
    const double si = side_of(pl, vi), sj = side_of(pl, vj);
    const int ci = cls(si), cj = cls(sj);
    if (ci >= 0) f.push_back(vi);
    if (ci <= 0) b.push_back(vi);
    if (ci * cj < 0) {
      const D3 x = vi + (vj - vi) * (si / (si - sj));
      f.push_back(x);
      b.push_back(x);
    }
  }
  if (m_pool.size() + f.size() + b.size() > 16 * m_budget)
    over_budget("polygon vertices", 16 * m_budget, "16 x " + nodes_field());
  m_pool.insert(m_pool.end(), f.begin(), f.end());
  front = make_poly(p.plane, uint32_t(m_pool.size() - f.size()), uint32_t(f.size()));
  m_pool.insert(m_pool.end(), b.begin(), b.end());
  back = make_poly(p.plane, uint32_t(m_pool.size() - b.size()), uint32_t(b.size()));
}

void BspBuilder::build() {
  SolidBspStats& st = m_out.stats;
  st.triangles = m_triangles;
  st.fragments = m_triangles;
  if (m_triangles > m_budget) over_budget("polygon fragments", m_budget, nodes_field());
  std::vector<Work> stack;
  stack.push_back({std::move(m_root), -1, false, 1});
  while (!stack.empty()) {
    Work w = std::move(stack.back());
    stack.pop_back();
    // Splitting plane, then the node, linked from its parent.
    const uint32_t chosen = choose_splitter(w.polys);
    const Plane& pl = m_planes[chosen];
    if (m_out.nodes.size() >= m_budget) over_budget("BSP nodes", m_budget, nodes_field());
    const int32_t index = int32_t(m_out.nodes.size());
    SolidBspNode node;
    node.nx = pl.n.x, node.ny = pl.n.y, node.nz = pl.n.z, node.d = pl.d;
    m_out.nodes.push_back(node);
    if (w.parent >= 0)
      (w.front ? m_out.nodes[size_t(w.parent)].front : m_out.nodes[size_t(w.parent)].back) = index;
    st.depth = std::max(st.depth, w.depth);
    // Partition: coplanar polygons (either facing; the splitter's own plane always) stay at the
    // node, spanning ones are cut. The back list is compacted in place (a convex part's chain
    // passes nearly every polygon back).
    std::vector<Poly> front;
    std::vector<Poly> back = std::move(w.polys);
    size_t kept = 0;
    for (size_t i = 0; i < back.size(); ++i) {
      const Poly p = back[i];
      switch (p.plane == chosen ? Side::Coplanar : classify(p, pl)) {
        case Side::Front:
          front.push_back(p);
          break;
        case Side::Back:
          back[kept++] = p;
          break;
        case Side::Spanning: {
          if (++st.fragments > m_budget) over_budget("polygon fragments", m_budget, nodes_field());
          ++st.splits;
          Poly f, b;
          split(p, pl, f, b);
          front.push_back(f);
          back[kept++] = b;
          break;
        }
        case Side::Coplanar:
          break;
      }
    }
    back.resize(kept);
    // Children: an empty side is a leaf, OUT in front of the surface, IN behind it.
    if (front.empty()) {
      m_out.nodes[size_t(index)].front = kSolidBspOut;
      ++st.out_leaves;
    } else {
      stack.push_back({std::move(front), index, true, w.depth + 1});
    }
    if (back.empty()) {
      m_out.nodes[size_t(index)].back = kSolidBspIn;
      ++st.in_leaves;
    } else {
      stack.push_back({std::move(back), index, false, w.depth + 1});
    }
  }
  m_out.nodes.shrink_to_fit();
}

SolidBsp build_from(const PreparedMesh& m, const SolidBspConfig& config) {
  SolidBsp out;
  out.flipped = m.flipped;
  out.volume = m.volume;
  out.tolerance = config.relative_epsilon * m.diagonal;
  out.bounds = m.bounds;
  BspBuilder builder(m, config, out);
  builder.build();
  for (const uint8_t z : m.zero_area) out.stats.degenerate += z;
  out.stats.degenerate += m.repeated;
  return out;
}

// ---------------------------------------------------------------------------------------------
// The distance BVH.

struct BvhBuild {
  const PreparedMesh& m;
  std::vector<uint32_t>& order;  // triangle ids (into m.tris / 3), reordered into leaves
  std::vector<Vec3f> centroid;
  std::vector<SolidMeshBvhNode>& nodes;

  Bounds3f triangle_box(uint32_t t) const {
    Bounds3f b;
    for (int k = 0; k < 3; ++k) b = merge(b, m.positions[m.tris[3 * size_t(t) + size_t(k)]]);
    return b;
  }

  // Median split on the widest axis of the centroids; depth <= log2(n / 4) + 1.
  uint32_t node(uint32_t begin, uint32_t end) {
    const uint32_t index = uint32_t(nodes.size());
    nodes.emplace_back();
    Bounds3f box, centres;
    for (uint32_t i = begin; i < end; ++i) {
      box = merge(box, triangle_box(order[i]));
      centres = merge(centres, centroid[order[i]]);
    }
    if (end - begin <= 4) {
      nodes[index] = {box.lo, box.hi, begin, end - begin};
      return index;
    }
    const Vec3f e = centres.extent();
    const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    const uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                     [&](uint32_t a, uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
    node(begin, mid);
    const uint32_t second = node(mid, end);
    nodes[index] = {box.lo, box.hi, second, 0};
    return index;
  }
};

// Closest point of triangle abc to p (polytope.h).
D3 closest_on_triangle(D3 p, D3 a, D3 b, D3 c) {
  auto d = [](D3 v) { return DVec3{v.x, v.y, v.z}; };
  const DVec3 q = penumbra::closest_on_triangle(d(p), d(a), d(b), d(c));
  return {q.x, q.y, q.z};
}

double box_distance2(const SolidMeshBvhNode& n, D3 p) {
  const double dx = std::max({double(n.lo.x) - p.x, 0.0, p.x - double(n.hi.x)});
  const double dy = std::max({double(n.lo.y) - p.y, 0.0, p.y - double(n.hi.y)});
  const double dz = std::max({double(n.lo.z) - p.z, 0.0, p.z - double(n.hi.z)});
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

SolidMeshError::SolidMeshError(const std::string& reason, bool over_budget)
    : std::invalid_argument("build_solid_bsp: the mesh " + reason),
      m_reason(reason),
      m_over_budget(over_budget) {}

SolidBsp build_solid_bsp(std::span<const Vec3f> positions, std::span<const uint32_t> indices,
                         const SolidBspConfig& config) {
  validate(config);
  return build_from(prepare(positions, indices), config);
}

bool solid_bsp_inside(const SolidBsp& bsp, Vec3f p) {
  const Bounds3f& b = bsp.bounds;
  if (bsp.nodes.empty() ||
      !(p.x >= b.lo.x && p.y >= b.lo.y && p.z >= b.lo.z && p.x <= b.hi.x && p.y <= b.hi.y && p.z <= b.hi.z))
    return false;
  const double x = p.x, y = p.y, z = p.z;
  int32_t i = 0;
  while (true) {
    const SolidBspNode& n = bsp.nodes[size_t(i)];
    const int32_t next = n.nx * x + n.ny * y + n.nz * z - n.d > 0 ? n.front : n.back;
    if (next < 0) return next == kSolidBspIn;
    if (next <= i || size_t(next) >= bsp.nodes.size()) return false;  // not a tree build_solid_bsp makes
    i = next;
  }
}

SolidMesh build_solid_mesh(std::span<const Vec3f> positions, std::span<const uint32_t> indices,
                           const SolidBspConfig& config) {
  validate(config);
  const PreparedMesh m = prepare(positions, indices);
  SolidMesh out;
  out.bsp = build_from(m, config);
  out.positions = m.positions;
  out.bounds = m.bounds;
  out.surface_distance = float(1e-5 * m.diagonal);
  // The BVH over the triangles of non-zero area; their indices in its leaf order, then the rest.
  std::vector<uint32_t> order;
  BvhBuild bvh{m, order, {}, out.bvh};
  bvh.centroid.resize(m.tris.size() / 3);
  for (uint32_t t = 0; t < uint32_t(m.tris.size() / 3); ++t) {
    const Bounds3f b = bvh.triangle_box(t);
    bvh.centroid[t] = b.center();
    if (!m.zero_area[t]) order.push_back(t);
  }
  bvh.node(0, uint32_t(order.size()));
  out.bvh.shrink_to_fit();
  out.bvh_triangles = uint32_t(order.size());
  for (uint32_t t = 0; t < uint32_t(m.tris.size() / 3); ++t)
    if (m.zero_area[t]) order.push_back(t);
  out.indices.reserve(m.tris.size());
  for (const uint32_t t : order)
    out.indices.insert(out.indices.end(), {m.tris[3 * t], m.tris[3 * t + 1], m.tris[3 * t + 2]});
  return out;
}

SolidMeshClosest solid_mesh_closest(const SolidMesh& mesh, Vec3f p) {
  SolidMeshClosest best;
  if (mesh.bvh.empty()) return best;
  const D3 q = to_d(p);
  double best2 = std::numeric_limits<double>::infinity();
  D3 best_point;
  constexpr int kStack = 64;  // the median-split BVH is at most 31 levels deep for 2^32 triangles
  uint32_t stack[kStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint32_t i = stack[--top];
    const SolidMeshBvhNode& n = mesh.bvh[i];
    if (box_distance2(n, q) > best2) continue;
    if (n.count > 0) {
      for (uint32_t t = n.first; t < n.first + n.count; ++t) {
        const uint32_t* v = &mesh.indices[3 * size_t(t)];
        const D3 c = closest_on_triangle(q, to_d(mesh.positions[v[0]]), to_d(mesh.positions[v[1]]),
                                         to_d(mesh.positions[v[2]]));
        const double d2 = dot(q - c, q - c);
        if (d2 < best2) best2 = d2, best_point = c, best.triangle = t;
      }
      continue;
    }
    if (top + 2 > kStack) continue;  // unreachable for the trees build_solid_mesh makes
    const uint32_t a = i + 1, b = n.first;
    const bool a_first = box_distance2(mesh.bvh[a], q) <= box_distance2(mesh.bvh[b], q);
    stack[top++] = a_first ? b : a;  // the farther child waits
    stack[top++] = a_first ? a : b;
  }
  best.distance = float(std::sqrt(best2));
  best.point = {float(best_point.x), float(best_point.y), float(best_point.z)};
  return best;
}

float solid_mesh_signed_distance(const SolidMesh& mesh, Vec3f p) {
  const float d = solid_mesh_closest(mesh, p).distance;
  return solid_bsp_inside(mesh.bsp, p) ? -d : d;
}

Vec3f solid_mesh_gradient(const SolidMesh& mesh, Vec3f p) {
  const SolidMeshClosest c = solid_mesh_closest(mesh, p);
  if (!(c.distance < kInfinity)) return {0, 0, 0};
  if (c.distance > mesh.surface_distance) {
    const Vec3f g = (p - c.point) / c.distance;
    return solid_bsp_inside(mesh.bsp, p) ? -g : g;
  }
  const uint32_t* v = &mesh.indices[3 * size_t(c.triangle)];
  const D3 a = to_d(mesh.positions[v[0]]), b = to_d(mesh.positions[v[1]]), cc = to_d(mesh.positions[v[2]]);
  const D3 n = cross(b - a, cc - a);
  const double l = length(n);
  return l > 0 ? Vec3f{float(n.x / l), float(n.y / l), float(n.z / l)} : Vec3f{0, 0, 0};
}

uint64_t solid_mesh_bytes(const SolidMesh& mesh) {
  return mesh.positions.capacity() * sizeof(Vec3f) + mesh.indices.capacity() * sizeof(uint32_t) +
         mesh.bvh.capacity() * sizeof(SolidMeshBvhNode) + mesh.bsp.nodes.capacity() * sizeof(SolidBspNode);
}

}  // namespace penumbra
