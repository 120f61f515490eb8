// Continuous collision detection on linearly moving triangle meshes: the coplanarity cubics of
// vertex-face and edge-edge pairs, their roots in [0, 1], and the proximity checks.
#include "renderer/collision/mesh_ccd.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "renderer/collision/gjk.h"
#include "renderer/collision/mesh_contact.h"

namespace penumbra {

namespace {

DVec3 cross3(DVec3 a, DVec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// A point moving from p to p + d.
struct Track {
  DVec3 p, d;
  DVec3 at(double u) const { return p + d * u; }
};

// The cubic w(u) . (e1(u) x e2(u)) for vectors moving linearly: coefficients c[0..3] of u^k.
// Returns its scale: the product of the three vectors' largest lengths over [0, 1], which
// bounds |f| and the coefficients' rounding relative to it.
double triple_cubic(const Track& w, const Track& e1, const Track& e2, double (&c)[4]) {
  const DVec3 x0 = cross3(e1.p, e2.p), x1 = cross3(e1.p, e2.d) + cross3(e1.d, e2.p), x2 = cross3(e1.d, e2.d);
  c[0] = dot(w.p, x0);
  c[1] = dot(w.p, x1) + dot(w.d, x0);
  c[2] = dot(w.p, x2) + dot(w.d, x1);
  c[3] = dot(w.d, x2);
  auto reach = [](const Track& t) { return std::max(length(t.p), length(t.p + t.d)); };
  return reach(w) * reach(e1) * reach(e2);
}

double cubic_at(const double (&c)[4], double u) {
  return ((c[3] * u + c[2]) * u + c[1]) * u + c[0];
}

// The roots of the cubic in [0, 1], ascending (at most 5 candidates): the interval split at the
// roots of the derivative, each monotone piece whose ends differ in sign (or end at zero)
// bisected to the last representable step; a root of the derivative where |f| <= zero (a
// double root that rounding may lift off zero: a grazing touch) is a candidate too. A cubic
// whose coefficients all lie below `zero` is identically zero for this purpose and has none.
int cubic_roots(const double (&c)[4], double zero, double (&roots)[5]) {
  if (std::abs(c[0]) <= zero && std::abs(c[1]) <= zero && std::abs(c[2]) <= zero && std::abs(c[3]) <= zero)
    return 0;
  double cuts[4] = {0, 0, 0, 1};
  int n = 1;
  // f' = 3 c3 u^2 + 2 c2 u + c1.
  const double qa = 3 * c[3], qb = 2 * c[2], qc = c[1];
  double crit[2];
  int nc = 0;
  if (qa != 0) {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc >= 0) {
      const double s = std::sqrt(disc), q = -0.5 * (qb + std::copysign(s, qb));
      if (q != 0)
        crit[nc++] = q / qa, crit[nc++] = qc / q;
      else
        crit[nc++] = 0;
    }
  } else if (qb != 0) {
    crit[nc++] = -qc / qb;
  }
  std::sort(crit, crit + nc);
  for (int i = 0; i < nc; ++i)
    if (crit[i] > 0 && crit[i] < 1) cuts[n++] = crit[i];
  cuts[n++] = 1;
  int found = 0;
  for (int i = 0; i + 1 < n; ++i) {
    double lo = cuts[i], hi = cuts[i + 1];
    double flo = cubic_at(c, lo), fhi = cubic_at(c, hi);
    if (flo == 0 || (i > 0 && std::abs(flo) <= zero)) {
      if (found == 0 || roots[found - 1] != lo) roots[found++] = lo;
      if (flo == 0) continue;
    }
    if (fhi != 0 && (flo > 0) == (fhi > 0)) continue;
    for (int it = 0; it < 200 && hi - lo > 0; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (mid <= lo || mid >= hi) break;
      const double fm = cubic_at(c, mid);
      if (fm == 0) {
        lo = hi = mid;
        break;
      }
      if ((fm > 0) == (flo > 0))
        lo = mid, flo = fm;
      else
        hi = mid;
    }
    const double r = fhi == 0 && lo == cuts[i] ? hi : lo;
    if (found == 0 || roots[found - 1] != r) roots[found++] = r;
  }
  return found;
}

// Rounding of the cubics relative to their scale: below it they are identically zero.
constexpr double kCubicZero = 1e-13;

// The first root below `best` of the cubic k (of scale `scale`) at which meets(u) holds, or best.
template <class Meets>
double first_meeting(const double (&k)[4], double scale, double best, Meets&& meets) {
  double roots[5];
  const int n = cubic_roots(k, kCubicZero * scale, roots);
  for (int i = 0; i < n && roots[i] < best; ++i)
    if (meets(roots[i])) return roots[i];
  return best;
}

// The first u (< best) at which moving point p meets moving triangle abc, or best; `point`
// gets where.
double vertex_face(const Track& p, const Track& a, const Track& b, const Track& c, double eta, double best,
                   DVec3& point) {
  double k[4];
  const double scale =
      triple_cubic({p.p - a.p, p.d - a.d}, {b.p - a.p, b.d - a.d}, {c.p - a.p, c.d - a.d}, k);
  return first_meeting(k, scale, best, [&](double u) {
    const DVec3 q = p.at(u);
    if (length(closest_on_triangle(q, a.at(u), b.at(u), c.at(u)) - q) > eta) return false;
    point = q;
    return true;
  });
}

// The first u (< best) at which moving edges ab and cd meet, or best; `point` gets where (the
// midpoint of their closest points).
double edge_edge(const Track& a, const Track& b, const Track& c, const Track& d, double eta, double best,
                 DVec3& point) {
  double k[4];
  const double scale =
      triple_cubic({c.p - a.p, c.d - a.d}, {b.p - a.p, b.d - a.d}, {d.p - c.p, d.d - c.d}, k);
  return first_meeting(k, scale, best, [&](double u) {
    DVec3 x, y;
    if (segment_distance(a.at(u), b.at(u), c.at(u), d.at(u), x, y) > eta) return false;
    point = (x + y) * 0.5;
    return true;
  });
}

}  // namespace

SweptTree build_swept_tree(const MovingMesh& m) {
  SweptTree out;
  if (m.start.size() != m.end.size()) return out;
  const size_t n = m.triangles.size() / 3;
  out.corners.resize(2 * n);
  out.segments.resize(3 * n);
  for (size_t t = 0; t < n; ++t) {
    DVec3 lo = m.start[m.triangles[3 * t]], hi = lo;
    for (int k = 0; k < 3; ++k)
      for (const DVec3& p :
           {m.start[m.triangles[3 * t + size_t(k)]], m.end[m.triangles[3 * t + size_t(k)]]}) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
    out.corners[2 * t] = lo, out.corners[2 * t + 1] = hi;
    out.segments[3 * t] = uint32_t(2 * t),
                     out.segments[3 * t + 1] = out.segments[3 * t + 2] = uint32_t(2 * t + 1);
  }
  out.tree = build_contact_tree({out.corners, out.segments});
  return out;
}

MeshFirstContact mesh_first_contact(const MovingMesh& a, const SweptTree& sa, const MovingMesh& b,
                                    const SweptTree& sb, const MeshCcdConfig& config) {
  MeshFirstContact out;
  const ContactTree &ta = sa.tree, &tb = sb.tree;
  if (ta.nodes.empty() || tb.nodes.empty() || a.start.size() != a.end.size() ||
      b.start.size() != b.end.size())
    return out;
  const DVec3 lo{std::min(ta.nodes[0].lo.x, tb.nodes[0].lo.x), std::min(ta.nodes[0].lo.y, tb.nodes[0].lo.y),
                 std::min(ta.nodes[0].lo.z, tb.nodes[0].lo.z)};
  const DVec3 hi{std::max(ta.nodes[0].hi.x, tb.nodes[0].hi.x), std::max(ta.nodes[0].hi.y, tb.nodes[0].hi.y),
                 std::max(ta.nodes[0].hi.z, tb.nodes[0].hi.z)};
  const double eta = config.tolerance * length(hi - lo);
  auto track = [](const MovingMesh& m, uint32_t t, int k) {
    const uint32_t v = m.triangles[3 * size_t(t) + size_t(k)];
    return Track{m.start[v], m.end[v] - m.start[v]};
  };
  double best = 2;  // past the interval: none yet
  DVec3 point{};
  for_overlapping_leaves(ta, tb, [&](uint32_t s, uint32_t t) {
    if (out.triangle_pairs >= config.max_triangle_pairs) {
      out.converged = false;
      return false;
    }
    ++out.triangle_pairs;
    const Track pa[3] = {track(a, s, 0), track(a, s, 1), track(a, s, 2)};
    const Track pb[3] = {track(b, t, 0), track(b, t, 1), track(b, t, 2)};
    const double before = best;
    for (int k = 0; k < 3; ++k) {
      best = vertex_face(pa[k], pb[0], pb[1], pb[2], eta, best, point);
      best = vertex_face(pb[k], pa[0], pa[1], pa[2], eta, best, point);
      for (int l = 0; l < 3; ++l)
        best = edge_edge(pa[k], pa[(k + 1) % 3], pb[l], pb[(l + 1) % 3], eta, best, point);
    }
    out.feature_tests += 15;
    if (best < before) out.triangle_a = s, out.triangle_b = t;
    return true;
  });
  if (best > 1 || !out.converged) return out;
  out.hit = true;
  out.u = best;
  out.point = point;
  // The normal from a towards b: the direction between the two triangles' closest points just
  // before contact.
  const Track pa[3] = {track(a, out.triangle_a, 0), track(a, out.triangle_a, 1), track(a, out.triangle_a, 2)};
  const Track pb[3] = {track(b, out.triangle_b, 0), track(b, out.triangle_b, 1), track(b, out.triangle_b, 2)};
  for (double back : {1e-6, 1e-3, 1.0}) {
    const double u = std::max(0.0, out.u - back * out.u);
    const DVec3 qa[3] = {pa[0].at(u), pa[1].at(u), pa[2].at(u)},
                qb[3] = {pb[0].at(u), pb[1].at(u), pb[2].at(u)};
    const ConvexDistance d = gjk_distance({qa, 0}, {qb, 0});
    if (!d.intersect && d.distance > 0) {
      out.normal = (d.b - d.a) * (1 / d.distance);
      break;
    }
  }
  return out;
}

MeshFirstContact mesh_first_contact(const MovingMesh& a, const MovingMesh& b, const MeshCcdConfig& config) {
  return mesh_first_contact(a, build_swept_tree(a), b, build_swept_tree(b), config);
}

}  // namespace penumbra
