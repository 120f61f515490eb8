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
void triple_cubic(const Track& w, const Track& e1, const Track& e2, double (&c)[4]) {
  const DVec3 x0 = cross3(e1.p, e2.p), x1 = cross3(e1.p, e2.d) + cross3(e1.d, e2.p), x2 = cross3(e1.d, e2.d);
  c[0] = dot(w.p, x0);
  c[1] = dot(w.p, x1) + dot(w.d, x0);
  c[2] = dot(w.p, x2) + dot(w.d, x1);
  c[3] = dot(w.d, x2);
}

double cubic_at(const double (&c)[4], double u) {
  return ((c[3] * u + c[2]) * u + c[1]) * u + c[0];
}

// The roots of the cubic in [0, 1], ascending (at most 3): the interval split at the roots of
// the derivative, each monotone piece whose ends differ in sign (or end at zero) bisected to
// the last representable step. A cubic whose coefficients all lie below `zero` is identically
// zero for this purpose and has none.
int cubic_roots(const double (&c)[4], double zero, double (&roots)[3]) {
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
    if (flo == 0) {
      if (found == 0 || roots[found - 1] != lo) roots[found++] = lo;
      continue;
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
    if (found == 3) break;
  }
  return found;
}

// The first root below `best` of the cubic k at which meets(u) holds, or best.
template <class Meets>
double first_meeting(const double (&k)[4], double zero3, double best, Meets&& meets) {
  double roots[3];
  const int n = cubic_roots(k, zero3, roots);
  for (int i = 0; i < n && roots[i] < best; ++i)
    if (meets(roots[i])) return roots[i];
  return best;
}

// The first u (< best) at which moving point p meets moving triangle abc, or best.
double vertex_face(const Track& p, const Track& a, const Track& b, const Track& c, double eta, double zero3,
                   double best) {
  double k[4];
  triple_cubic({p.p - a.p, p.d - a.d}, {b.p - a.p, b.d - a.d}, {c.p - a.p, c.d - a.d}, k);
  return first_meeting(k, zero3, best, [&](double u) {
    const DVec3 q = p.at(u);
    return length(closest_on_triangle(q, a.at(u), b.at(u), c.at(u)) - q) <= eta;
  });
}

// The first u (< best) at which moving edges ab and cd meet, or best.
double edge_edge(const Track& a, const Track& b, const Track& c, const Track& d, double eta, double zero3,
                 double best) {
  double k[4];
  triple_cubic({c.p - a.p, c.d - a.d}, {b.p - a.p, b.d - a.d}, {d.p - c.p, d.d - c.d}, k);
  return first_meeting(k, zero3, best, [&](double u) {
    DVec3 x, y;
    return segment_distance(a.at(u), b.at(u), c.at(u), d.at(u), x, y) <= eta;
  });
}

// The swept boxes of a moving mesh's triangles as a tree: each triangle stands for the segment
// from its six corners' lower to their upper corner (build_contact_tree sees only boxes).
ContactTree swept_tree(const MovingMesh& m, std::vector<DVec3>& corners, std::vector<uint32_t>& segments) {
  const size_t n = m.triangles.size() / 3;
  corners.resize(2 * n);
  segments.resize(3 * n);
  for (size_t t = 0; t < n; ++t) {
    DVec3 lo = m.start[m.triangles[3 * t]], hi = lo;
    for (int k = 0; k < 3; ++k)
      for (const DVec3& p : {m.start[m.triangles[3 * t + k]], m.end[m.triangles[3 * t + k]]}) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
    corners[2 * t] = lo, corners[2 * t + 1] = hi;
    segments[3 * t] = uint32_t(2 * t), segments[3 * t + 1] = segments[3 * t + 2] = uint32_t(2 * t + 1);
  }
  return build_contact_tree({corners, segments});
}

}  // namespace

MeshFirstContact mesh_first_contact(const MovingMesh& a, const MovingMesh& b, const MeshCcdConfig& config) {
  MeshFirstContact out;
  std::vector<DVec3> ca, cb;
  std::vector<uint32_t> sa, sb;
  const ContactTree ta = swept_tree(a, ca, sa), tb = swept_tree(b, cb, sb);
  if (ta.nodes.empty() || tb.nodes.empty()) return out;
  const DVec3 lo{std::min(ta.nodes[0].lo.x, tb.nodes[0].lo.x), std::min(ta.nodes[0].lo.y, tb.nodes[0].lo.y),
                 std::min(ta.nodes[0].lo.z, tb.nodes[0].lo.z)};
  const DVec3 hi{std::max(ta.nodes[0].hi.x, tb.nodes[0].hi.x), std::max(ta.nodes[0].hi.y, tb.nodes[0].hi.y),
                 std::max(ta.nodes[0].hi.z, tb.nodes[0].hi.z)};
  const double size = std::max(length(hi - lo), 1e-300);
  const double eta = config.tolerance * size;
  // The cubics' coefficients scale as size^3: below this they are rounding.
  const double zero3 = 1e-14 * size * size * size;
  auto track = [](const MovingMesh& m, uint32_t t, int k) {
    const uint32_t v = m.triangles[3 * size_t(t) + size_t(k)];
    return Track{m.start[v], m.end[v] - m.start[v]};
  };
  double best = 2;  // past the interval: none yet
  uint32_t best_a = 0, best_b = 0;
  for_overlapping_leaves(ta, tb, [&](uint32_t s, uint32_t t) {
    ++out.triangle_pairs;
    const Track pa[3] = {track(a, s, 0), track(a, s, 1), track(a, s, 2)};
    const Track pb[3] = {track(b, t, 0), track(b, t, 1), track(b, t, 2)};
    const double before = best;
    for (int k = 0; k < 3; ++k) {
      best = vertex_face(pa[k], pb[0], pb[1], pb[2], eta, zero3, best);
      best = vertex_face(pb[k], pa[0], pa[1], pa[2], eta, zero3, best);
      for (int l = 0; l < 3; ++l)
        best = edge_edge(pa[k], pa[(k + 1) % 3], pb[l], pb[(l + 1) % 3], eta, zero3, best);
    }
    out.feature_tests += 15;
    if (best < before) best_a = s, best_b = t;
  });
  if (best > 1) return out;
  out.hit = true;
  out.u = best;
  out.triangle_a = best_a, out.triangle_b = best_b;
  // Where and how they touch: the closest points of the two triangles at u, and the normal
  // from a towards b (the closest points' direction just before u, else the faces' normals).
  const Track pa[3] = {track(a, best_a, 0), track(a, best_a, 1), track(a, best_a, 2)};
  const Track pb[3] = {track(b, best_b, 0), track(b, best_b, 1), track(b, best_b, 2)};
  auto closest_pair = [&](double u, DVec3& x, DVec3& y) {
    const DVec3 qa[3] = {pa[0].at(u), pa[1].at(u), pa[2].at(u)},
                qb[3] = {pb[0].at(u), pb[1].at(u), pb[2].at(u)};
    const ConvexDistance d = gjk_distance({qa, 0}, {qb, 0});
    x = d.a, y = d.b;
    return d;
  };
  DVec3 x, y;
  const ConvexDistance at = closest_pair(out.u, x, y);
  out.point = at.intersect ? pa[0].at(out.u) : (x + y) * 0.5;
  if (at.intersect) {
    // Meeting exactly: the point of a's triangle nearest to b's.
    double nearest = INFINITY;
    for (int k = 0; k < 3; ++k) {
      const DVec3 q = pa[k].at(out.u);
      const double dist =
          length(closest_on_triangle(q, pb[0].at(out.u), pb[1].at(out.u), pb[2].at(out.u)) - q);
      if (dist < nearest) nearest = dist, out.point = q;
    }
  }
  for (double back : {1e-6, 1e-3, 1.0}) {
    const double u = std::max(0.0, out.u - back * out.u);
    const ConvexDistance d = closest_pair(u, x, y);
    if (!d.intersect && d.distance > 0) {
      out.normal = (y - x) * (1 / d.distance);
      break;
    }
  }
  return out;
}

}  // namespace penumbra
