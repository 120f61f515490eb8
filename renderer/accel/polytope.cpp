// Convex polytopes: faces clipped one by one (Sutherland & Hodgman, "Reentrant polygon clipping",
// CACM 1974) with the crossing points shared between the two faces of an edge, and the cut closed
// by the convex hull of the points in the plane (A. M. Andrew, "Another efficient algorithm for
// convex hulls in two dimensions", IPL 1979).
#include "renderer/accel/polytope.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace penumbra {
namespace {

constexpr double kSnap = 1e-13;  // relative distance within which a point lies on a cutting plane

/// Twice the area vector of the polygon `pts` (any order of iteration that visits it once).
struct AreaAccumulator {
  DVec3 first{}, prev{}, sum{};
  int count = 0;
  void add(DVec3 p) {
    if (count == 0) {
      first = p;
    } else if (count >= 2) {
      sum = sum + cross(prev - first, p - first);
    }
    prev = p;
    ++count;
  }
};

/// Signed distances dot(n, v) - k of the polytope's vertices, snapped to 0 within kSnap of the
/// plane's scale; returns whether some are < 0 and some > 0 through the flags.
void signed_distances(std::span<const DVec3> verts, std::span<const double> proj, double k, double* out,
                      bool& any_neg, bool& any_pos) {
  double scale = std::fabs(k);
  for (const double p : proj) scale = std::max(scale, std::fabs(p));
  const double tol = kSnap * scale;
  any_neg = any_pos = false;
  for (size_t i = 0; i < verts.size(); ++i) {
    double e = proj[i] - k;
    if (std::fabs(e) <= tol) e = 0;
    out[i] = e;
    any_neg |= e < 0;
    any_pos |= e > 0;
  }
}

}  // namespace

Polytope::Polytope(const Bounds3f& b) {
  for (int k = 0; k < 3; ++k)
    if (!(b.hi[k] > b.lo[k]) || !std::isfinite(b.lo[k]) || !std::isfinite(b.hi[k])) return;
  // Vertex i has x from bit 0, y from bit 1, z from bit 2 (0: lo, 1: hi).
  for (int i = 0; i < 8; ++i)
    m_vertices.push_back({(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z});
  const std::array<std::array<uint32_t, 4>, 6> loops{
      {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}}};
  const std::array<DVec3, 6> normals{{{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}}};
  for (int f = 0; f < 6; ++f) {
    const uint32_t begin = uint32_t(m_loops.size());
    m_loops.insert(m_loops.end(), loops[f].begin(), loops[f].end());
    add_face(begin, normals[f]);
  }
}

void Polytope::add_face(uint32_t begin, DVec3 normal) {
  const uint32_t count = uint32_t(m_loops.size()) - begin;
  AreaAccumulator acc;
  for (uint32_t i = begin; i < begin + count; ++i) acc.add(m_vertices[m_loops[i]]);
  double area = 0.5 * dot(acc.sum, normal);
  if (area < 0) {  // wound the other way round: turn it
    std::reverse(m_loops.begin() + begin, m_loops.end());
    area = -area;
  }
  if (count < 3 || !(area > 0)) {
    m_loops.resize(begin);
    return;
  }
  m_faces.push_back({begin, count, normal, area});
  // The fan of triangles (first vertex, j, j + 1) of the (convex) face, by area.
  m_fan_area.resize(m_loops.size());
  const DVec3 o = m_vertices[m_loops[begin]];
  for (uint32_t j = 1; j + 1 < count; ++j) {
    const DVec3 c = cross(m_vertices[m_loops[begin + j]] - o, m_vertices[m_loops[begin + j + 1]] - o);
    m_fan_area[begin + j] = std::max(0.0, 0.5 * dot(c, normal));
  }
}

double Polytope::area() const {
  double a = 0;
  for (const Face& f : m_faces) a += f.area;
  return a;
}

double Polytope::volume() const {
  double v = 0;
  for (const Face& f : m_faces) v += dot(m_vertices[m_loops[f.begin]], f.normal) * f.area;
  return v / 3;
}

void Polytope::extent(DVec3 n, double& lo, double& hi) const {
  lo = INFINITY;
  hi = -INFINITY;
  for (const DVec3& v : m_vertices) {
    const double p = dot(n, v);
    lo = std::min(lo, p);
    hi = std::max(hi, p);
  }
}

Polytope Polytope::clip(DVec3 n, double k, bool positive) const {
  if (empty()) return {};
  const size_t nv = m_vertices.size();
  thread_local std::vector<double> proj, e;
  proj.resize(nv);
  e.resize(nv);
  for (size_t i = 0; i < nv; ++i) proj[i] = dot(n, m_vertices[i]);
  bool any_neg, any_pos;
  signed_distances(m_vertices, proj, k, e.data(), any_neg, any_pos);
  if (!positive)
    for (double& x : e) x = -x;  // kept: e >= 0
  if (!(positive ? any_pos : any_neg)) return {};
  if (!(positive ? any_neg : any_pos)) return *this;

  // Phase 1: the kept vertices, and the points of the cap (kept vertices in the plane and the
  // crossings of cut edges, each made once for the two faces sharing its edge).
  Polytope out;
  thread_local std::vector<uint32_t> remap, cap;
  remap.assign(nv, UINT32_MAX);
  cap.clear();
  for (size_t i = 0; i < nv; ++i) {
    if (e[i] < 0) continue;
    remap[i] = uint32_t(out.m_vertices.size());
    out.m_vertices.push_back(m_vertices[i]);
    if (e[i] == 0) cap.push_back(remap[i]);
  }
  thread_local std::vector<std::array<uint32_t, 3>> crossings;  // (lower, higher vertex, new index)
  crossings.clear();
  const auto crossing = [&](uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    for (const auto& c : crossings)
      if (c[0] == a && c[1] == b) return c[2];
    const double t = e[a] / (e[a] - e[b]);
    const uint32_t idx = uint32_t(out.m_vertices.size());
    out.m_vertices.push_back(m_vertices[a] + (m_vertices[b] - m_vertices[a]) * t);
    crossings.push_back({a, b, idx});
    cap.push_back(idx);
    return idx;
  };

  // Phase 2: each face clipped to the kept side.
  for (const Face& f : m_faces) {
    const uint32_t begin = uint32_t(out.m_loops.size());
    for (uint32_t j = 0; j < f.count; ++j) {
      const uint32_t a = m_loops[f.begin + j], b = m_loops[f.begin + (j + 1) % f.count];
      if (e[a] >= 0) out.m_loops.push_back(remap[a]);
      if ((e[a] > 0 && e[b] < 0) || (e[a] < 0 && e[b] > 0)) out.m_loops.push_back(crossing(a, b));
    }
    out.add_face(begin, f.normal);
  }

  // Phase 3: the cap, the convex hull of the points in the plane (in a basis (u, v) of it).
  const double len = length(n);
  const DVec3 nu = n * (1 / len);
  const DVec3 axis = std::fabs(nu.x) <= std::fabs(nu.y) && std::fabs(nu.x) <= std::fabs(nu.z)
                         ? DVec3{1, 0, 0}
                         : (std::fabs(nu.y) <= std::fabs(nu.z) ? DVec3{0, 1, 0} : DVec3{0, 0, 1});
  DVec3 u = cross(nu, axis);
  u = u * (1 / length(u));
  const DVec3 v = cross(nu, u);
  struct P2 {
    double x, y;
    uint32_t idx;
  };
  thread_local std::vector<P2> pts, hull;
  pts.clear();
  for (const uint32_t i : cap) pts.push_back({dot(out.m_vertices[i], u), dot(out.m_vertices[i], v), i});
  std::sort(pts.begin(), pts.end(), [](const P2& a, const P2& b) {
    return a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.idx < b.idx)));
  });
  const auto turn = [](const P2& o, const P2& a, const P2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  if (pts.size() < 3) return out;
  hull.resize(2 * pts.size());
  size_t h = 0;
  for (size_t i = 0; i < pts.size(); ++i) {  // lower chain
    while (h >= 2 && turn(hull[h - 2], hull[h - 1], pts[i]) <= 0) --h;
    hull[h++] = pts[i];
  }
  for (size_t i = pts.size() - 1, lower = h + 1; i-- > 0;) {  // upper chain
    while (h >= lower && turn(hull[h - 2], hull[h - 1], pts[i]) <= 0) --h;
    hull[h++] = pts[i];
  }
  --h;  // the last point repeats the first
  if (h >= 3) {
    const uint32_t begin = uint32_t(out.m_loops.size());
    for (size_t i = 0; i < h; ++i) out.m_loops.push_back(hull[i].idx);
    out.add_face(begin, positive ? nu * -1.0 : nu);
  }
  return out;
}

void Polytope::triangles(std::vector<uint32_t>& indices) const {
  for (const Face& f : m_faces)
    for (uint32_t j = 1; j + 1 < f.count; ++j) {
      indices.push_back(m_loops[f.begin]);
      indices.push_back(m_loops[f.begin + j]);
      indices.push_back(m_loops[f.begin + j + 1]);
    }
}

void Polytope::split_areas(DVec3 n, std::span<const double> positions, std::span<double> negative,
                           std::span<double> positive) const {
  thread_local PolytopeSlicer slicer;
  slicer.reset(*this, n);
  for (size_t p = 0; p < positions.size(); ++p) slicer.areas(positions[p], negative[p], positive[p]);
}

void PolytopeSlicer::reset(const Polytope& p, DVec3 n) {
  m_poly = &p;
  const size_t nv = p.m_vertices.size(), nf = p.m_faces.size();
  m_proj.resize(nv);
  m_face_lo.resize(nf);
  m_face_hi.resize(nf);
  m_face_cos.resize(nf);
  m_fan.resize(p.m_loops.size());
  m_ready.assign(nf, 0);
  m_scale = 0;
  for (size_t i = 0; i < nv; ++i) {
    m_proj[i] = dot(n, p.m_vertices[i]);
    m_scale = std::max(m_scale, std::fabs(m_proj[i]));
  }
  const double inv_len = 1 / length(n);
  for (size_t f = 0; f < nf; ++f) {
    const Polytope::Face& face = p.m_faces[f];
    double lo = INFINITY, hi = -INFINITY;
    for (uint32_t j = face.begin; j < face.begin + face.count; ++j) {
      lo = std::min(lo, m_proj[p.m_loops[j]]);
      hi = std::max(hi, m_proj[p.m_loops[j]]);
    }
    m_face_lo[f] = lo;
    m_face_hi[f] = hi;
    m_face_cos[f] = dot(n, face.normal) * inv_len;
  }
  m_total = p.area();
}

void PolytopeSlicer::areas(double k, double& negative, double& positive) {
  negative = positive = 0;
  const Polytope& p = *m_poly;
  if (p.empty()) return;
  const double tol = kSnap * std::max(m_scale, std::fabs(k));
  double neg = 0, pos = 0, cap = 0;  // cap: minus the n-component of the negative faces' area
  bool any_neg = false, any_pos = false;
  for (size_t f = 0; f < p.m_faces.size(); ++f) {
    const Polytope::Face& face = p.m_faces[f];
    if (m_face_hi[f] <= k + tol) {  // wholly on the negative side
      neg += face.area;
      cap -= m_face_cos[f] * face.area;
      any_neg |= m_face_lo[f] < k - tol;
      continue;
    }
    if (m_face_lo[f] >= k - tol) {  // wholly on the positive side
      pos += face.area;
      any_pos |= m_face_hi[f] > k + tol;
      continue;
    }
    any_neg = any_pos = true;
    // The face's part below k, triangle by triangle of its fan: the part of a triangle with
    // heights a <= b <= c below k is (k - a)^2 / ((b - a)(c - a)) of it up to b, and all but
    // (c - k)^2 / ((c - a)(c - b)) of it from b on.
    FanTriangle* fan = &m_fan[face.begin];
    if (!m_ready[f]) {
      const uint32_t* loop = &p.m_loops[face.begin];
      const double h0 = m_proj[loop[0]];
      for (uint32_t j = 1; j + 1 < face.count; ++j) {
        const double h1 = m_proj[loop[j]], h2 = m_proj[loop[j + 1]];
        const double lo = std::min(h0, std::min(h1, h2)), hi = std::max(h0, std::max(h1, h2));
        const double mid = std::max(std::min(h0, h1), std::min(std::max(h0, h1), h2));
        const double t = p.m_fan_area[face.begin + j];
        fan[j] = {lo,
                  mid,
                  hi,
                  t,
                  mid > lo ? t / ((mid - lo) * (hi - lo)) : 0.0,
                  hi > mid ? t / ((hi - lo) * (hi - mid)) : 0.0};
      }
      m_ready[f] = 1;
    }
    double a = 0;
    for (uint32_t j = 1; j + 1 < face.count; ++j) {
      const FanTriangle& t = fan[j];
      if (k >= t.c) {
        a += t.area;
      } else if (k > t.b) {
        a += t.area - t.upper * (t.c - k) * (t.c - k);
      } else if (k > t.a) {
        a += t.lower * (k - t.a) * (k - t.a);
      }
    }
    a = std::clamp(a, 0.0, face.area);
    neg += a;
    pos += face.area - a;
    cap -= m_face_cos[f] * a;
  }
  // The negative part is closed by a cap with outward normal n: the area vectors sum to 0.
  if (!any_pos || !any_neg) {  // no cut: one side is everything, the other nothing
    (any_pos ? positive : negative) = m_total;
    return;
  }
  cap = std::max(0.0, cap);
  negative = neg + cap;
  positive = pos + cap;
}

DVec3 closest_on_triangle(DVec3 p, DVec3 a, DVec3 b, DVec3 c) {
  const DVec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const DVec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0 && d1 - d3 > 0) return a + ab * (d1 / (d1 - d3));
  const DVec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0 && d2 - d6 > 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0 && (d4 - d3) + (d5 - d6) > 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  // A triangle without area whose corner and edge regions all failed (its corners coincide).
  if (!(va + vb + vc > 0)) return a;
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace penumbra
