// Proxy fitting: minimal and Ritter spheres, boxes, capsules, hulls, k-DOPs and composites.
#include "renderer/collision/proxy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace penumbra {

namespace {

constexpr double kPiD = std::numbers::pi;

DVec3 normalized(DVec3 v) {
  const double l = length(v);
  return l > 0 ? v * (1 / l) : DVec3{0, 0, 0};
}
double distance_to_segment(DVec3 p, DVec3 a, DVec3 b) {
  const DVec3 ab = b - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return length(p - (a + ab * t));
}
bool finite(DVec3 p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}
// A uniform double in [0, 1) from 53 bits.
double uniform(std::mt19937_64& rng) {
  return double(rng() >> 11) * 0x1.0p-53;
}

// ---- Minimal enclosing ball -------------------------------------------------------------------

struct Ball {
  DVec3 c{};
  double r2 = -1;  // squared radius; < 0: empty
};

Ball ball_of_two(DVec3 a, DVec3 b) {
  const DVec3 c = (a + b) * 0.5;
  return {c, dot(a - c, a - c)};
}

// The smallest ball with a, b, c on its boundary: their circumcircle's; the farthest pair's if
// they are collinear.
Ball ball_of_three(DVec3 a, DVec3 b, DVec3 c) {
  const DVec3 ab = b - a, ac = c - a;
  const DVec3 n = cross(ab, ac);
  const double n2 = dot(n, n);
  const double scale = std::max(dot(ab, ab), dot(ac, ac));
  if (!(n2 > 1e-24 * scale * scale)) {
    Ball best = ball_of_two(a, b);
    for (Ball x : {ball_of_two(a, c), ball_of_two(b, c)})
      if (x.r2 > best.r2) best = x;
    return best;
  }
  const DVec3 o = (cross(n, ab) * dot(ac, ac) + cross(ac, n) * dot(ab, ab)) * (1 / (2 * n2));
  return {a + o, dot(o, o)};
}

// The ball with four points on its boundary (their circumsphere), or when they are (nearly)
// coplanar the smallest of the balls of three of them that holds the fourth.
Ball ball_of_four(DVec3 a, DVec3 b, DVec3 c, DVec3 d) {
  const DVec3 u = b - a, v = c - a, w = d - a;
  const double det = dot(u, cross(v, w));
  const double scale = std::max({dot(u, u), dot(v, v), dot(w, w)});
  if (std::abs(det) > 1e-12 * scale * std::sqrt(scale)) {
    const DVec3 o =
        (cross(v, w) * dot(u, u) + cross(w, u) * dot(v, v) + cross(u, v) * dot(w, w)) * (1 / (2 * det));
    return {a + o, dot(o, o)};
  }
  const std::array<DVec3, 4> p{a, b, c, d};
  Ball best;
  for (int skip = 0; skip < 4; ++skip) {
    std::array<DVec3, 3> q{};
    for (int i = 0, j = 0; i < 4; ++i)
      if (i != skip) q[size_t(j++)] = p[size_t(i)];
    const Ball x = ball_of_three(q[0], q[1], q[2]);
    const DVec3 e = p[size_t(skip)] - x.c;
    if (dot(e, e) <= x.r2 * (1 + 1e-9) && (best.r2 < 0 || x.r2 < best.r2)) best = x;
  }
  if (best.r2 < 0) best = ball_of_three(a, b, c);
  return best;
}

Ball ball_of_support(const std::array<DVec3, 4>& s, int n) {
  switch (n) {
    case 0:
      return {};
    case 1:
      return {s[0], 0};
    case 2:
      return ball_of_two(s[0], s[1]);
    case 3:
      return ball_of_three(s[0], s[1], s[2]);
    default:
      return ball_of_four(s[0], s[1], s[2], s[3]);
  }
}

// Welzl's recursion in Gaertner's move-to-front form: the smallest ball holding pts[0, end)
// with the `n` support points on its boundary. Recursion depth is at most 4.
Ball mtf_ball(std::vector<DVec3>& pts, size_t end, std::array<DVec3, 4>& support, int n, double eps2) {
  Ball ball = ball_of_support(support, n);
  if (n == 4) return ball;
  for (size_t i = 0; i < end; ++i) {
    const DVec3 e = pts[i] - ball.c;
    if (ball.r2 >= 0 && dot(e, e) <= ball.r2 + eps2) continue;
    support[size_t(n)] = pts[i];
    ball = mtf_ball(pts, i, support, n + 1, eps2);
    std::rotate(pts.begin(), pts.begin() + std::ptrdiff_t(i), pts.begin() + std::ptrdiff_t(i) + 1);
  }
  return ball;
}

std::vector<DVec3> unique_points(std::span<const DVec3> points) {
  std::vector<DVec3> u(points.begin(), points.end());
  auto key = [](const DVec3& p) { return std::array<double, 3>{p.x, p.y, p.z}; };
  std::sort(u.begin(), u.end(), [&](const DVec3& a, const DVec3& b) { return key(a) < key(b); });
  u.erase(std::unique(u.begin(), u.end(), [&](const DVec3& a, const DVec3& b) { return key(a) == key(b); }),
          u.end());
  return u;
}

void check_points(std::span<const DVec3> points) {
  if (points.empty()) throw std::invalid_argument("no points to fit a proxy to");
  for (const DVec3& p : points)
    if (!finite(p)) throw std::invalid_argument("a point to fit a proxy to is not finite");
}

// ---- Principal axes ---------------------------------------------------------------------------

// ---- Boxes ------------------------------------------------------------------------------------

struct Extents {
  double lo[3], hi[3];
  double volume() const { return (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]); }
};

Extents extents_in(std::span<const DVec3> pts, const DVec3 axis[3]) {
  Extents e{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (const DVec3& p : pts)
    for (int i = 0; i < 3; ++i) {
      const double s = dot(p, axis[i]);
      e.lo[i] = std::min(e.lo[i], s);
      e.hi[i] = std::max(e.hi[i], s);
    }
  return e;
}

OrientedBox box_from(const DVec3 axis[3], const Extents& e) {
  OrientedBox b;
  b.center = DVec3{0, 0, 0};
  for (int i = 0; i < 3; ++i) {
    b.axis[i] = axis[i];
    b.center = b.center + axis[i] * (0.5 * (e.lo[i] + e.hi[i]));
  }
  b.half = {0.5 * (e.hi[0] - e.lo[0]), 0.5 * (e.hi[1] - e.lo[1]), 0.5 * (e.hi[2] - e.lo[2])};
  return b;
}

// The minimum-area rectangle around a convex polygon (corners counter-clockwise) by rotating
// calipers: one side lies on a polygon edge (Freeman & Shapira 1975), and as the edge advances
// the extreme corners along it, against it and across it advance monotonically (Toussaint,
// "Solving geometric problems with the rotating calipers", MELECON 1983). Returns the unit
// direction of that side in (dx, dy) and the area.
double min_area_rectangle(std::span<const DVec3> pts, std::span<const uint32_t> poly, double& dx,
                          double& dy) {
  const size_t h = poly.size();
  auto at = [&](size_t k) { return pts[poly[k % h]]; };
  double best = INFINITY;
  size_t right = 0, top = 0, left = 0;
  for (size_t i = 0; i < h; ++i) {
    const DVec3 a = at(i), b = at(i + 1);
    double ex = b.x - a.x, ey = b.y - a.y;
    const double l = std::sqrt(ex * ex + ey * ey);
    if (!(l > 0)) continue;
    ex /= l, ey /= l;
    auto along = [&](size_t k) { return (at(k).x - a.x) * ex + (at(k).y - a.y) * ey; };
    auto across = [&](size_t k) { return (at(k).y - a.y) * ex - (at(k).x - a.x) * ey; };  // left of the edge
    if (i == 0 || right < i + 1) right = std::max(right, i + 1);
    while (along(right + 1) >= along(right) && right + 1 < i + 1 + h) ++right;
    if (top < right) top = right;
    while (across(top + 1) >= across(top) && top + 1 < i + 1 + h) ++top;
    if (left < top) left = top;
    while (along(left + 1) <= along(left) && left + 1 < i + 1 + h) ++left;
    const double area = (along(right) - along(left)) * across(top);
    if (area < best) {
      best = area;
      dx = ex;
      dy = ey;
    }
  }
  return best;
}

// The frame (u, v, n) with n fixed and (u, v) the sides of the minimum-area rectangle around the
// hull's projection across n; its box volume in `volume`.
bool best_frame_for_normal(const ConvexPolyhedron& hull, DVec3 n, DVec3 frame[3], double& volume) {
  const DVec3 t = std::abs(n.x) < 0.9 ? DVec3{1, 0, 0} : DVec3{0, 1, 0};
  const DVec3 e1 = normalized(cross(n, t)), e2 = cross(n, e1);
  std::vector<DVec3> flat;
  flat.reserve(hull.vertices.size());
  double lo_n = INFINITY, hi_n = -INFINITY;
  for (const DVec3& p : hull.vertices) {
    flat.push_back({dot(p, e1), dot(p, e2), 0});
    lo_n = std::min(lo_n, dot(p, n));
    hi_n = std::max(hi_n, dot(p, n));
  }
  const std::vector<uint32_t> poly = convex_hull_2d(flat);
  if (poly.size() < 3) return false;
  double dx = 1, dy = 0;
  const double area = min_area_rectangle(flat, poly, dx, dy);
  if (!std::isfinite(area)) return false;
  volume = area * (hi_n - lo_n);
  frame[0] = e1 * dx + e2 * dy;
  frame[1] = cross(n, frame[0]);
  frame[2] = n;
  return true;
}

OrientedBox fit_obb(std::span<const DVec3> points, const ProxyConfig& config) {
  const ConvexPolyhedron hull = convex_hull(points, config.hull);
  const std::span<const DVec3> pts = hull.vertices;
  DVec3 best[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double best_volume = extents_in(pts, best).volume();
  auto consider = [&](const DVec3 frame[3]) {
    const double v = extents_in(pts, frame).volume();
    if (v < best_volume) {
      best_volume = v;
      std::copy(frame, frame + 3, best);
    }
  };
  DVec3 pca[3];
  principal_axes(pts, &hull, pca);
  consider(pca);
  // Candidate normals: the principal axes and the largest faces' normals.
  std::vector<double> face_area(hull.planes.size(), 0);
  for (size_t t = 0; t < hull.face_of.size(); ++t) {
    const DVec3 a = hull.vertices[hull.triangles[3 * t]];
    face_area[hull.face_of[t]] += 0.5 * length(cross(hull.vertices[hull.triangles[3 * t + 1]] - a,
                                                     hull.vertices[hull.triangles[3 * t + 2]] - a));
  }
  std::vector<uint32_t> faces(hull.planes.size());
  for (uint32_t i = 0; i < faces.size(); ++i) faces[i] = i;
  std::stable_sort(faces.begin(), faces.end(),
                   [&](uint32_t a, uint32_t b) { return face_area[a] > face_area[b]; });
  // Each candidate costs a 2-d hull of the hull's vertices: fewer candidates for huge hulls.
  const size_t budget = std::max<size_t>(8, size_t(2e7) / std::max<size_t>(1, hull.vertices.size()));
  const size_t keep = std::min(size_t(std::max(0, config.obb_face_candidates)), budget);
  if (faces.size() > keep) faces.resize(keep);
  std::vector<DVec3> normals(pca, pca + 3);
  for (uint32_t f : faces) normals.push_back(hull.planes[f].n);
  for (const DVec3& n : normals) {
    DVec3 frame[3];
    double volume;
    if (best_frame_for_normal(hull, n, frame, volume) && volume < best_volume) consider(frame);
  }
  best[2] = cross(best[0], best[1]);  // right-handed
  return box_from(best, extents_in(points, best));
}

// ---- Capsule ----------------------------------------------------------------------------------

CapsuleProxy fit_capsule(std::span<const DVec3> points, const ProxyConfig& config) {
  const ConvexPolyhedron hull = convex_hull(points, config.hull);
  DVec3 axes[3];
  principal_axes(hull.vertices, &hull, axes);
  const DVec3 d = axes[0], e1 = axes[1], e2 = axes[2];
  std::vector<DVec3> across;
  across.reserve(hull.vertices.size());
  for (const DVec3& p : hull.vertices) across.push_back({dot(p, e1), dot(p, e2), 0});
  const BoundingSphere circle = minimal_sphere(across);
  const double r = circle.radius;
  double t1 = -INFINITY, t0 = INFINITY;
  for (size_t i = 0; i < hull.vertices.size(); ++i) {
    const double t = dot(hull.vertices[i], d);
    const double dx = across[i].x - circle.center.x, dy = across[i].y - circle.center.y;
    const double s = std::sqrt(std::max(0.0, r * r - (dx * dx + dy * dy)));
    t1 = std::max(t1, t - s);
    t0 = std::min(t0, t + s);
  }
  if (t0 > t1) t0 = t1 = 0.5 * (t0 + t1);  // a sphere of radius r on the axis holds every point
  const DVec3 base = e1 * circle.center.x + e2 * circle.center.y;
  CapsuleProxy c{base + d * t0, base + d * t1, r};
  for (const DVec3& p : points) c.radius = std::max(c.radius, distance_to_segment(p, c.a, c.b));
  return c;
}

// ---- k-DOP and composite ----------------------------------------------------------------------

ConvexPolyhedron fit_kdop(std::span<const DVec3> points, int k, const ConvexHullConfig& flat) {
  std::vector<DPlane> planes;
  Bounds3f box;
  for (const DVec3& p : points) box = merge(box, Vec3f{float(p.x), float(p.y), float(p.z)});
  double diagonal = double(length(box.hi - box.lo));
  if (!(diagonal > 0)) diagonal = 1;
  const float slab = float(4 * flat.thickness * diagonal);  // room for flat slabs' thickening
  const Vec3f pad = (box.hi - box.lo) * 1e-3f + Vec3f{slab, slab, slab};
  box = {box.lo - pad, box.hi + pad};
  for (const DVec3& d : kdop_directions(k)) {
    double lo = INFINITY, hi = -INFINITY;
    for (const DVec3& p : points) {
      lo = std::min(lo, dot(d, p));
      hi = std::max(hi, dot(d, p));
    }
    if (hi - lo < 2 * flat.thickness * diagonal) {  // flat along d: a slab as thick as convex_hull's
      lo -= flat.thickness * diagonal;
      hi += flat.thickness * diagonal;
    }
    planes.push_back({d, hi});
    planes.push_back({d * -1, -lo});
  }
  return polyhedron_from_planes(planes, box);
}

std::vector<ConvexPolyhedron> fit_composite(std::span<const DVec3> points,
                                            std::span<const uint32_t> triangles, const ProxyConfig& config) {
  if (triangles.empty()) return {convex_hull(points, config.hull)};
  // Weld equal positions, then join the corners of every triangle (union-find).
  std::vector<uint32_t> weld(points.size());
  {
    std::vector<uint32_t> order(points.size());
    for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
    auto key = [&](uint32_t i) { return std::array<double, 3>{points[i].x, points[i].y, points[i].z}; };
    std::sort(order.begin(), order.end(),
              [&](uint32_t a, uint32_t b) { return key(a) < key(b) || (key(a) == key(b) && a < b); });
    for (size_t i = 0; i < order.size(); ++i)
      weld[order[i]] = i > 0 && key(order[i]) == key(order[i - 1]) ? weld[order[i - 1]] : order[i];
  }
  std::vector<uint32_t> parent(points.size());
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  auto find = [&](uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::vector<uint8_t> used(points.size(), 0);
  for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
    const uint32_t a = find(weld[triangles[t]]);
    for (int k = 0; k < 3; ++k) {
      used[triangles[t + size_t(k)]] = 1;
      const uint32_t b = find(weld[triangles[t + size_t(k)]]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::unordered_map<uint32_t, size_t> component;
  std::vector<std::vector<DVec3>> groups;
  for (uint32_t i = 0; i < points.size(); ++i) {
    if (!used[i]) continue;
    auto [it, added] = component.try_emplace(find(weld[i]), groups.size());
    if (added) groups.emplace_back();
    groups[it->second].push_back(points[i]);
  }
  std::vector<ConvexPolyhedron> parts;
  for (const auto& g : groups) parts.push_back(convex_hull(unique_points(g), config.hull));
  return parts;
}

}  // namespace

const char* proxy_kind_name(ProxyKind kind) {
  static const char* const names[kProxyKindCount] = {"sphere",  "ritter", "aabb", "obb",
                                                     "capsule", "hull",   "kdop", "composite"};
  return names[int(kind)];
}

bool parse_proxy_kind(std::string_view name, ProxyKind& kind) {
  for (int i = 0; i < kProxyKindCount; ++i)
    if (name == proxy_kind_name(ProxyKind(i))) {
      kind = ProxyKind(i);
      return true;
    }
  return false;
}

BoundingSphere minimal_sphere(std::span<const DVec3> points) {
  check_points(points);
  std::vector<DVec3> pts = unique_points(points);
  std::mt19937_64 rng(0x9e3779b97f4a7c15ull);
  std::shuffle(pts.begin(), pts.end(), rng);
  DVec3 lo = pts[0], hi = pts[0];
  for (const DVec3& p : pts) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const double scale = dot(hi - lo, hi - lo);
  std::array<DVec3, 4> support{};
  const Ball ball = mtf_ball(pts, pts.size(), support, 0, 1e-14 * scale);
  BoundingSphere s{ball.c, 0};
  for (const DVec3& p : points) s.radius = std::max(s.radius, length(p - s.center));
  return s;
}

BoundingSphere ritter_sphere(std::span<const DVec3> points) {
  check_points(points);
  auto farthest = [&](DVec3 from) {
    DVec3 best = from;
    double d2 = -1;
    for (const DVec3& p : points)
      if (dot(p - from, p - from) > d2) d2 = dot(p - from, p - from), best = p;
    return best;
  };
  const DVec3 y = farthest(points[0]), z = farthest(y);
  BoundingSphere s{(y + z) * 0.5, 0.5 * length(z - y)};
  for (const DVec3& p : points) {
    const double d = length(p - s.center);
    if (d <= s.radius) continue;
    const double r = 0.5 * (s.radius + d);
    s.center = s.center + (p - s.center) * ((r - s.radius) / d);
    s.radius = r;
  }
  for (const DVec3& p : points) s.radius = std::max(s.radius, length(p - s.center));
  return s;
}

void principal_axes(std::span<const DVec3> points, const ConvexPolyhedron* hull, DVec3 axes[3]) {
  double c[3][3] = {};
  DVec3 mean{0, 0, 0};
  double weight = 0;
  auto add_outer = [&](DVec3 p, double w) {
    const double v[3] = {p.x, p.y, p.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c[i][j] += w * v[i] * v[j];
  };
  const DVec3 o = hull && !hull->vertices.empty() ? hull->vertices[0]
                  : points.empty()                ? DVec3{0, 0, 0}
                                                  : points[0];
  if (hull && !hull->triangles.empty()) {
    // A triangle's second moment about o, as a uniform area density: A / 12 (9 m m^T + sum p p^T).
    for (size_t t = 0; t + 2 < hull->triangles.size(); t += 3) {
      const DVec3 p = hull->vertices[hull->triangles[t]] - o, q = hull->vertices[hull->triangles[t + 1]] - o,
                  r = hull->vertices[hull->triangles[t + 2]] - o;
      const double area = 0.5 * length(cross(q - p, r - p));
      const DVec3 m = (p + q + r) * (1.0 / 3);
      add_outer(m, 9 * area / 12);
      add_outer(p, area / 12);
      add_outer(q, area / 12);
      add_outer(r, area / 12);
      mean = mean + m * area;
      weight += area;
    }
  } else {
    for (const DVec3& p : points) {
      add_outer(p - o, 1);
      mean = mean + (p - o);
      weight += 1;
    }
  }
  if (weight > 0) {
    mean = mean * (1 / weight);
    const double m[3] = {mean.x, mean.y, mean.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c[i][j] = c[i][j] / weight - m[i] * m[j];
  }
  double v[3][3], values[3];
  symmetric_eigen3(c, v, values);
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int a, int b) { return values[a] > values[b]; });
  for (int i = 0; i < 2; ++i) axes[i] = normalized({v[0][order[i]], v[1][order[i]], v[2][order[i]]});
  axes[2] = cross(axes[0], axes[1]);
}

std::vector<DVec3> kdop_directions(int k) {
  if (k != 6 && k != 14 && k != 18 && k != 26)
    throw std::invalid_argument("k-DOP: k must be 6, 14, 18 or 26 (got " + std::to_string(k) + ")");
  std::vector<DVec3> d{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double s3 = 1 / std::sqrt(3.0), s2 = 1 / std::sqrt(2.0);
  if (k == 14 || k == 26)
    for (DVec3 c : {DVec3{1, 1, 1}, DVec3{1, 1, -1}, DVec3{1, -1, 1}, DVec3{-1, 1, 1}}) d.push_back(c * s3);
  if (k == 18 || k == 26)
    for (DVec3 e :
         {DVec3{1, 1, 0}, DVec3{1, -1, 0}, DVec3{1, 0, 1}, DVec3{1, 0, -1}, DVec3{0, 1, 1}, DVec3{0, 1, -1}})
      d.push_back(e * s2);
  return d;
}

Proxy fit_proxy(ProxyKind kind, std::span<const DVec3> points, std::span<const uint32_t> triangles,
                const ProxyConfig& config) {
  check_points(points);
  for (uint32_t i : triangles)
    if (i >= points.size())
      throw std::invalid_argument("triangle index " + std::to_string(i) + " out of range (" +
                                  std::to_string(points.size()) + " points)");
  Proxy proxy;
  proxy.kind = kind;
  switch (kind) {
    case ProxyKind::Sphere:
      proxy.sphere = minimal_sphere(points);
      break;
    case ProxyKind::Ritter:
      proxy.sphere = ritter_sphere(points);
      break;
    case ProxyKind::Aabb: {
      const DVec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      proxy.box = box_from(axes, extents_in(points, axes));
      break;
    }
    case ProxyKind::Obb:
      proxy.box = fit_obb(unique_points(points), config);
      break;
    case ProxyKind::Capsule:
      proxy.capsule = fit_capsule(unique_points(points), config);
      break;
    case ProxyKind::Hull:
      proxy.parts.push_back(convex_hull(unique_points(points), config.hull));
      break;
    case ProxyKind::Kdop:
      proxy.parts.push_back(fit_kdop(points, config.kdop, config.hull));
      break;
    case ProxyKind::Composite:
      proxy.parts = fit_composite(points, triangles, config);
      break;
  }
  return proxy;
}

double proxy_volume(const Proxy& proxy) {
  switch (proxy.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      return 4.0 / 3 * kPiD * std::pow(proxy.sphere.radius, 3);
    case ProxyKind::Aabb:
    case ProxyKind::Obb:
      return 8 * proxy.box.half.x * proxy.box.half.y * proxy.box.half.z;
    case ProxyKind::Capsule: {
      const double r = proxy.capsule.radius;
      return kPiD * r * r * length(proxy.capsule.b - proxy.capsule.a) + 4.0 / 3 * kPiD * r * r * r;
    }
    default: {
      double v = 0;
      for (const ConvexPolyhedron& p : proxy.parts) v += p.volume;
      return v;
    }
  }
}

bool proxy_contains(const Proxy& proxy, DVec3 p, double tolerance) {
  switch (proxy.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      return length(p - proxy.sphere.center) <= proxy.sphere.radius + tolerance;
    case ProxyKind::Aabb:
    case ProxyKind::Obb: {
      const DVec3 d = p - proxy.box.center;
      const double half[3] = {proxy.box.half.x, proxy.box.half.y, proxy.box.half.z};
      for (int i = 0; i < 3; ++i)
        if (std::abs(dot(d, proxy.box.axis[i])) > half[i] + tolerance) return false;
      return true;
    }
    case ProxyKind::Capsule:
      return distance_to_segment(p, proxy.capsule.a, proxy.capsule.b) <= proxy.capsule.radius + tolerance;
    default:
      for (const ConvexPolyhedron& part : proxy.parts)
        if (polyhedron_contains(part, p, tolerance)) return true;
      return false;
  }
}

namespace {

DVec3 sphere_direction(std::mt19937_64& rng) {
  const double z = 1 - 2 * uniform(rng), phi = 2 * kPiD * uniform(rng);
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

// A unit vector perpendicular to unit d.
DVec3 perpendicular(DVec3 d) {
  const DVec3 t = std::abs(d.x) < 0.9 ? DVec3{1, 0, 0} : DVec3{0, 1, 0};
  return normalized(cross(d, t));
}

void sample_polyhedra(const std::vector<ConvexPolyhedron>& parts, size_t count, std::mt19937_64& rng,
                      std::vector<DVec3>& out) {
  std::vector<double> cdf;
  std::vector<std::pair<size_t, size_t>> tri;  // (part, first index)
  double total = 0;
  for (size_t k = 0; k < parts.size(); ++k)
    for (size_t t = 0; t + 2 < parts[k].triangles.size(); t += 3) {
      const auto& v = parts[k].vertices;
      const auto& i = parts[k].triangles;
      total += 0.5 * length(cross(v[i[t + 1]] - v[i[t]], v[i[t + 2]] - v[i[t]]));
      cdf.push_back(total);
      tri.push_back({k, t});
    }
  if (!(total > 0)) return;
  for (size_t n = 0; n < count; ++n) {
    const double x = uniform(rng) * total;
    const size_t j =
        std::min(size_t(std::upper_bound(cdf.begin(), cdf.end(), x) - cdf.begin()), cdf.size() - 1);
    const auto& part = parts[tri[j].first];
    const size_t t = tri[j].second;
    double u = uniform(rng), v = uniform(rng);
    if (u + v > 1) u = 1 - u, v = 1 - v;
    const DVec3 a = part.vertices[part.triangles[t]];
    out.push_back(a + (part.vertices[part.triangles[t + 1]] - a) * u +
                  (part.vertices[part.triangles[t + 2]] - a) * v);
  }
}

}  // namespace

void sample_proxy_surface(const Proxy& proxy, size_t count, uint64_t seed, std::vector<DVec3>& out) {
  std::mt19937_64 rng(seed);
  switch (proxy.kind) {
    case ProxyKind::Sphere:
    case ProxyKind::Ritter:
      for (size_t n = 0; n < count; ++n)
        out.push_back(proxy.sphere.center + sphere_direction(rng) * proxy.sphere.radius);
      return;
    case ProxyKind::Aabb:
    case ProxyKind::Obb: {
      const OrientedBox& b = proxy.box;
      const double h[3] = {b.half.x, b.half.y, b.half.z};
      const double area[3] = {h[1] * h[2], h[0] * h[2], h[0] * h[1]};  // per face pair, / 4
      const double total = area[0] + area[1] + area[2];
      for (size_t n = 0; n < count; ++n) {
        const double x = uniform(rng) * total;
        const int axis = x < area[0] ? 0 : x < area[0] + area[1] ? 1 : 2;
        double s[3];
        for (int i = 0; i < 3; ++i) s[i] = (2 * uniform(rng) - 1) * h[i];
        s[axis] = uniform(rng) < 0.5 ? -h[axis] : h[axis];
        out.push_back(b.center + b.axis[0] * s[0] + b.axis[1] * s[1] + b.axis[2] * s[2]);
      }
      return;
    }
    case ProxyKind::Capsule: {
      const CapsuleProxy& c = proxy.capsule;
      const double len = length(c.b - c.a), r = c.radius;
      const DVec3 d = len > 0 ? (c.b - c.a) * (1 / len) : DVec3{0, 1, 0};
      const DVec3 e1 = perpendicular(d), e2 = cross(d, e1);
      const double side = 2 * kPiD * r * len, caps = 4 * kPiD * r * r;
      for (size_t n = 0; n < count; ++n) {
        if (uniform(rng) * (side + caps) < side) {
          const double phi = 2 * kPiD * uniform(rng), t = uniform(rng) * len;
          out.push_back(c.a + d * t + (e1 * std::cos(phi) + e2 * std::sin(phi)) * r);
        } else {
          const DVec3 w = sphere_direction(rng);
          out.push_back((dot(w, d) >= 0 ? c.b : c.a) + w * r);
        }
      }
      return;
    }
    default: {
      std::vector<DVec3> pts;
      sample_polyhedra(proxy.parts, count, rng, pts);
      // A composite's surface is its parts' union's: drop points deep inside another part.
      for (const DVec3& p : pts) {
        int inside = 0;
        if (proxy.parts.size() > 1)
          for (const ConvexPolyhedron& part : proxy.parts)
            inside += polyhedron_contains(part, p, -1e-9) ? 1 : 0;
        if (inside == 0) out.push_back(p);
      }
      return;
    }
  }
}

}  // namespace penumbra
