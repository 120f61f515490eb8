// GJK distance between convex cores.
#include "renderer/collision/gjk.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {

/// Distances below this fraction of the Minkowski difference's size count as touching.
constexpr double kTouch = 1e-10;

DVec3 support(std::span<const DVec3> points, DVec3 d) {
  DVec3 best = points[0];
  double best_dot = dot(best, d);
  for (const DVec3& p : points) {
    const double s = dot(p, d);
    if (s > best_dot) best_dot = s, best = p;
  }
  return best;
}

// A simplex vertex: w = a - b of the two support points.
struct Vertex {
  DVec3 w{}, a{}, b{};
};

struct Simplex {
  Vertex v[4];
  double bary[4] = {};
  int n = 0;
};

// Keeps the vertices of `s` listed in `keep` (with their weights): the support set.
void reduce(Simplex& s, const int* keep, const double* weights, int count) {
  Simplex r;
  for (int i = 0; i < count; ++i) {
    r.v[i] = s.v[keep[i]];
    r.bary[i] = weights[i];
  }
  r.n = count;
  s = r;
}

// The point of segment s.v[i] s.v[j] nearest the origin, the simplex reduced to its support.
void closest_segment(Simplex& s, int i, int j) {
  const DVec3 a = s.v[i].w, ab = s.v[j].w - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(-dot(a, ab) / len2, 0.0, 1.0) : 0.0;
  if (t <= 0) {
    const int keep[1] = {i};
    const double w[1] = {1};
    reduce(s, keep, w, 1);
  } else if (t >= 1) {
    const int keep[1] = {j};
    const double w[1] = {1};
    reduce(s, keep, w, 1);
  } else {
    const int keep[2] = {i, j};
    const double w[2] = {1 - t, t};
    reduce(s, keep, w, 2);
  }
}

// The point of triangle (i, j, k) nearest the origin by its Voronoi regions (Ericson 5.1.5).
void closest_triangle(Simplex& s, int i, int j, int k) {
  const DVec3 a = s.v[i].w, b = s.v[j].w, c = s.v[k].w;
  const DVec3 ab = b - a, ac = c - a, ap = a * -1;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return closest_segment(s, i, i);
  const DVec3 bp = b * -1;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return closest_segment(s, j, j);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return closest_segment(s, i, j);
  const DVec3 cp = c * -1;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return closest_segment(s, k, k);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return closest_segment(s, i, k);
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return closest_segment(s, j, k);
  const double denom = va + vb + vc;
  if (!(denom > 0)) return closest_segment(s, i, j);  // degenerate: an edge's answer
  const double v = vb / denom, w = vc / denom;
  const int keep[3] = {i, j, k};
  const double weights[3] = {1 - v - w, v, w};
  reduce(s, keep, weights, 3);
}

DVec3 point_of(const Simplex& s) {
  DVec3 p{0, 0, 0};
  for (int i = 0; i < s.n; ++i) p = p + s.v[i].w * s.bary[i];
  return p;
}

// The tetrahedron's nearest point: inside (returns true) or that of the nearest face the origin
// lies outside of.
bool closest_tetrahedron(Simplex& s) {
  static const int faces[4][4] = {{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}};
  bool outside_any = false;
  Simplex best;
  double best_d2 = INFINITY;
  for (const auto& f : faces) {
    const DVec3 a = s.v[f[0]].w, b = s.v[f[1]].w, c = s.v[f[2]].w, d = s.v[f[3]].w;
    const DVec3 n = cross(b - a, c - a);
    const double sp = dot(a * -1, n), sd = dot(d - a, n);
    // Outside this face: the origin and the fourth vertex on opposite sides (or a flat tetrahedron).
    if (sp * sd > 0 && std::abs(sd) > 1e-15 * (dot(n, n) + 1e-300)) continue;
    outside_any = true;
    Simplex t = s;
    closest_triangle(t, f[0], f[1], f[2]);
    const DVec3 p = point_of(t);
    if (dot(p, p) < best_d2) best_d2 = dot(p, p), best = t;
  }
  if (!outside_any) return true;
  s = best;
  return false;
}

}  // namespace

void box_corners(const OrientedBox& box, DVec3 out[8]) {
  for (int i = 0; i < 8; ++i)
    out[i] = box.center + box.axis[0] * (i & 1 ? box.half.x : -box.half.x) +
             box.axis[1] * (i & 2 ? box.half.y : -box.half.y) +
             box.axis[2] * (i & 4 ? box.half.z : -box.half.z);
}

double segment_distance(DVec3 p1, DVec3 q1, DVec3 p2, DVec3 q2, DVec3& c1, DVec3& c2) {
  const DVec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
    s = t = 0;
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = dot(d1, r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = dot(d1, d2), denom = a * e - b * b;
      s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + d1 * s;
  c2 = p2 + d2 * t;
  return length(c1 - c2);
}

ConvexDistance gjk_distance(const ConvexCore& a, const ConvexCore& b) {
  ConvexDistance out;
  Simplex s;
  s.v[0] = {a.points[0] - b.points[0], a.points[0], b.points[0]};
  s.bary[0] = 1;
  s.n = 1;
  DVec3 v = s.v[0].w;
  double scale = 0;  // the largest support value seen, for relative tolerances
  for (int it = 0; it < 128; ++it) {
    out.iterations = it + 1;
    const double v2 = dot(v, v);
    if (v2 <= kTouch * kTouch * std::max(scale, 1e-300)) {
      out.intersect = true;
      break;
    }
    const DVec3 sa = support(a.points, v * -1), sb = support(b.points, v);
    const Vertex w{sa - sb, sa, sb};
    scale = std::max(scale, dot(w.w, w.w));
    if (v2 - dot(v, w.w) <= 1e-12 * v2) break;  // no support point comes nearer: converged
    bool seen = false;
    for (int i = 0; i < s.n; ++i) seen |= s.v[i].w.x == w.w.x && s.v[i].w.y == w.w.y && s.v[i].w.z == w.w.z;
    if (seen) break;
    s.v[s.n] = w;
    ++s.n;
    switch (s.n) {
      case 2:
        closest_segment(s, 0, 1);
        break;
      case 3:
        closest_triangle(s, 0, 1, 2);
        break;
      default:
        if (closest_tetrahedron(s)) out.intersect = true;
    }
    if (out.intersect) break;
    const DVec3 nv = point_of(s);
    const bool progress = dot(nv, nv) < v2;
    v = nv;
    if (!progress) break;  // no progress (rounding): v is the answer
  }
  const double core = out.intersect ? 0 : length(v);
  // The origin on the simplex to rounding (it may lie in a face's plane): the cores touch.
  if (core <= a.radius + b.radius + kTouch * std::sqrt(scale)) {
    out.intersect = true;
    out.distance = 0;
  } else {
    out.distance = core - a.radius - b.radius;
  }
  DVec3 pa{0, 0, 0}, pb{0, 0, 0};
  for (int i = 0; i < s.n; ++i) {
    pa = pa + s.v[i].a * s.bary[i];
    pb = pb + s.v[i].b * s.bary[i];
  }
  if (core > 0) {
    const DVec3 dir = v * (1 / core);  // from b towards a
    pa = pa - dir * a.radius;
    pb = pb + dir * b.radius;
  }
  out.a = pa;
  out.b = pb;
  return out;
}

ConvexDistance proxy_distance(const Proxy& a, const Proxy& b) {
  ProxyCores ca(a), cb(b);
  ConvexDistance best;
  bool first = true;
  for (size_t i = 0; i < ca.cores.size(); ++i)
    for (size_t j = 0; j < cb.cores.size(); ++j) {
      const ConvexDistance d = gjk_distance(ca.cores[i], cb.cores[j]);
      if (first || (d.intersect && !best.intersect) || (!best.intersect && d.distance < best.distance))
        best = d;
      first = false;
    }
  return best;
}

ProxyCores::ProxyCores(const Proxy& proxy) {
  switch (proxy.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      storage.push_back({proxy.sphere.center});
      cores.push_back({storage.back(), proxy.sphere.radius});
      part.push_back(0);
      return;
    case ProxyKind::Aabb:
    case ProxyKind::Obb: {
      DVec3 c[8];
      box_corners(proxy.box, c);
      storage.emplace_back(c, c + 8);
      cores.push_back({storage.back(), 0});
      part.push_back(0);
      return;
    }
    case ProxyKind::Capsule:
      storage.push_back({proxy.capsule.a, proxy.capsule.b});
      cores.push_back({storage.back(), proxy.capsule.radius});
      part.push_back(0);
      return;
    default:
      for (size_t k = 0; k < proxy.parts.size(); ++k)
        if (!proxy.parts[k].vertices.empty()) {
          cores.push_back({proxy.parts[k].vertices, 0});
          part.push_back(k);
        }
  }
}

namespace {

// A core's face normals and edge directions (unit), for the candidate axes.
struct CoreFeatures {
  std::vector<DVec3> normals, edges;
};

CoreFeatures features_of(const Proxy& proxy, size_t part) {
  CoreFeatures f;
  auto unit = [](DVec3 v) {
    const double l = length(v);
    return l > 0 ? v * (1 / l) : DVec3{0, 0, 0};
  };
  switch (proxy.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      break;
    case ProxyKind::Aabb:
    case ProxyKind::Obb:
      for (const DVec3& axis : proxy.box.axis) f.normals.push_back(axis), f.edges.push_back(axis);
      break;
    case ProxyKind::Capsule:
      if (length(proxy.capsule.b - proxy.capsule.a) > 0)
        f.edges.push_back(unit(proxy.capsule.b - proxy.capsule.a));
      break;
    default: {
      const ConvexPolyhedron& p = proxy.parts[part];
      for (const DPlane& pl : p.planes) f.normals.push_back(pl.n);
      for (size_t t = 0; t + 2 < p.triangles.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
          const DVec3 e =
              unit(p.vertices[p.triangles[t + size_t((k + 1) % 3)]] - p.vertices[p.triangles[t + size_t(k)]]);
          if (dot(e, e) > 0) f.edges.push_back(e);
        }
    }
  }
  return f;
}

void extent(std::span<const DVec3> pts, DVec3 n, double& lo, double& hi) {
  lo = INFINITY;
  hi = -INFINITY;
  for (const DVec3& p : pts) {
    lo = std::min(lo, dot(p, n));
    hi = std::max(hi, dot(p, n));
  }
}

}  // namespace

Penetration penetration(const Proxy& a, const Proxy& b) {
  Penetration out;
  ProxyCores ca(a), cb(b);
  for (size_t i = 0; i < ca.cores.size(); ++i)
    for (size_t j = 0; j < cb.cores.size(); ++j) {
      const ConvexCore& A = ca.cores[i];
      const ConvexCore& B = cb.cores[j];
      const ConvexDistance d = gjk_distance(A, B);
      if (!d.intersect) continue;
      Penetration p;
      p.intersect = true;
      const ConvexDistance core = gjk_distance({A.points, 0}, {B.points, 0});
      if (!core.intersect) {  // the cores are apart: the radii overlap along the line between them
        p.depth = A.radius + B.radius - core.distance;
        p.direction = (core.b - core.a) * (1 / core.distance);
      } else {
        const CoreFeatures fa = features_of(a, ca.part[i]), fb = features_of(b, cb.part[j]);
        std::vector<DVec3> axes = fa.normals;
        axes.insert(axes.end(), fb.normals.begin(), fb.normals.end());
        const double pairs = double(fa.edges.size()) * double(fb.edges.size());
        if (pairs * double(A.points.size() + B.points.size()) <= 5e7) {
          for (const DVec3& ea : fa.edges)
            for (const DVec3& eb : fb.edges) {
              const DVec3 n = cross(ea, eb);
              const double l = length(n);
              if (l > 1e-9) axes.push_back(n * (1 / l));
            }
        } else {
          p.exact = false;
        }
        p.depth = INFINITY;
        for (const DVec3& n : axes) {
          double la, ha, lb, hb;
          extent(A.points, n, la, ha);
          extent(B.points, n, lb, hb);
          // Moving b along +n by (ha - lb) or along -n by (hb - la) separates the projections.
          if (ha - lb < p.depth) p.depth = ha - lb, p.direction = n;
          if (hb - la < p.depth) p.depth = hb - la, p.direction = n * -1;
        }
        if (!std::isfinite(p.depth)) p.depth = 0, p.direction = {0, 0, 1};  // point or parallel cores
        p.depth = std::max(0.0, p.depth) + A.radius + B.radius;
      }
      if (!out.intersect || p.depth > out.depth) out = p;  // a composite: its deepest part
    }
  return out;
}

}  // namespace penumbra
