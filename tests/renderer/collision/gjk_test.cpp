// Tests for renderer/collision/gjk: distances between proxies against closed forms (two
// spheres, sphere and box, two capsules by the segment distance, itself checked against dense
// sampling), and between convex polyhedra (hulls, boxes) against a brute-force oracle over
// every feature pair (vertex-triangle and edge-edge) for the distance and the separating-axis
// theorem for meeting or not; the closest points lie on the sets at the reported distance.
#include "renderer/collision/gjk.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

using namespace penumbra;

namespace {

double len(DVec3 v) {
  return std::sqrt(dot(v, v));
}

DVec3 random_point(std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> u(-spread, spread);
  return {u(rng), u(rng), u(rng)};
}

// The distance from p to triangle abc: its plane's if p projects inside, else its edges'.
double point_triangle(DVec3 p, DVec3 a, DVec3 b, DVec3 c) {
  const DVec3 n = cross(b - a, c - a);
  const double n2 = dot(n, n);
  DVec3 q1, q2;
  double best = std::min({segment_distance(p, p, a, b, q1, q2), segment_distance(p, p, b, c, q1, q2),
                          segment_distance(p, p, c, a, q1, q2)});
  if (n2 > 0) {
    const DVec3 q = p - n * (dot(p - a, n) / n2);
    const bool inside = dot(cross(b - a, q - a), n) >= 0 && dot(cross(c - b, q - b), n) >= 0 &&
                        dot(cross(a - c, q - c), n) >= 0;
    if (inside) best = std::min(best, len(p - q));
  }
  return best;
}

// The distance between two disjoint convex polyhedra: the least over vertex-triangle pairs
// both ways and edge-edge pairs.
double brute_distance(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  double best = INFINITY;
  auto vertex_faces = [&](const ConvexPolyhedron& p, const ConvexPolyhedron& q) {
    for (const DVec3& v : p.vertices)
      for (size_t t = 0; t < q.triangles.size(); t += 3)
        best = std::min(best, point_triangle(v, q.vertices[q.triangles[t]], q.vertices[q.triangles[t + 1]],
                                             q.vertices[q.triangles[t + 2]]));
  };
  vertex_faces(a, b);
  vertex_faces(b, a);
  DVec3 c1, c2;
  for (size_t s = 0; s < a.triangles.size(); s += 3)
    for (int i = 0; i < 3; ++i)
      for (size_t t = 0; t < b.triangles.size(); t += 3)
        for (int j = 0; j < 3; ++j)
          best = std::min(best, segment_distance(a.vertices[a.triangles[s + size_t(i)]],
                                                 a.vertices[a.triangles[s + size_t((i + 1) % 3)]],
                                                 b.vertices[b.triangles[t + size_t(j)]],
                                                 b.vertices[b.triangles[t + size_t((j + 1) % 3)]], c1, c2));
  return best;
}

// Separating-axis theorem for convex polyhedra: they are disjoint exactly when their
// projections on some face normal or cross product of edges do not overlap.
bool separated(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  std::vector<DVec3> axes;
  for (const DPlane& p : a.planes) axes.push_back(p.n);
  for (const DPlane& p : b.planes) axes.push_back(p.n);
  auto edges = [](const ConvexPolyhedron& p) {
    std::vector<DVec3> e;
    for (size_t t = 0; t < p.triangles.size(); t += 3)
      for (int i = 0; i < 3; ++i)
        e.push_back(p.vertices[p.triangles[t + size_t((i + 1) % 3)]] -
                    p.vertices[p.triangles[t + size_t(i)]]);
    return e;
  };
  for (const DVec3& ea : edges(a))
    for (const DVec3& eb : edges(b)) axes.push_back(cross(ea, eb));
  for (const DVec3& n : axes) {
    if (dot(n, n) < 1e-20) continue;
    double la, ha, lb, hb;
    polyhedron_extent(a, n, la, ha);
    polyhedron_extent(b, n, lb, hb);
    if (ha < lb - 1e-12 * len(n) || hb < la - 1e-12 * len(n)) return true;
  }
  return false;
}

ConvexPolyhedron random_hull(std::mt19937_64& rng, DVec3 centre, int points) {
  std::vector<DVec3> p;
  for (int i = 0; i < points; ++i) p.push_back(centre + random_point(rng, 1));
  return convex_hull(p);
}

}  // namespace

TEST_CASE("segment distance equals dense sampling", "[gjk]") {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 50; ++trial) {
    const DVec3 p1 = random_point(rng, 2), q1 = random_point(rng, 2), p2 = random_point(rng, 2),
                q2 = random_point(rng, 2);
    DVec3 c1, c2;
    const double d = segment_distance(p1, q1, p2, q2, c1, c2);
    double sampled = INFINITY;
    for (int i = 0; i <= 400; ++i)
      for (int j = 0; j <= 400; ++j)
        sampled = std::min(sampled, len((p1 + (q1 - p1) * (i / 400.0)) - (p2 + (q2 - p2) * (j / 400.0))));
    CHECK(d <= sampled + 1e-12);
    CHECK(d >= sampled - 0.02);
    CHECK(len(c1 - c2) == Approx(d).margin(1e-12));
  }
}

TEST_CASE("GJK: spheres, a sphere and a box, capsules against closed forms", "[gjk]") {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 200; ++trial) {
    Proxy a, b;
    a.kind = b.kind = ProxyKind::Sphere;
    a.sphere = {random_point(rng, 3), 0.2 + 0.5 * (trial % 3)};
    b.sphere = {random_point(rng, 3), 0.7};
    const double want = len(a.sphere.center - b.sphere.center) - a.sphere.radius - b.sphere.radius;
    const ConvexDistance d = proxy_distance(a, b);
    CHECK(d.intersect == (want <= 0));
    if (want > 0) {
      CHECK(d.distance == Approx(want).epsilon(1e-9));
      CHECK(len(d.a - d.b) == Approx(want).epsilon(1e-9));
    }

    // An axis-aligned box [-1, 1]^3 and a sphere: the distance from the centre to the box less r.
    Proxy box;
    box.kind = ProxyKind::Aabb;
    box.box.half = {1, 1, 1};
    const DVec3 c = b.sphere.center;
    const DVec3 q{std::clamp(c.x, -1.0, 1.0), std::clamp(c.y, -1.0, 1.0), std::clamp(c.z, -1.0, 1.0)};
    const double want_box = len(c - q) - b.sphere.radius;
    const ConvexDistance db = proxy_distance(box, b);
    CHECK(db.intersect == (want_box <= 0));
    if (want_box > 0) CHECK(db.distance == Approx(want_box).epsilon(1e-9));

    Proxy ca, cb;
    ca.kind = cb.kind = ProxyKind::Capsule;
    ca.capsule = {random_point(rng, 3), random_point(rng, 3), 0.3};
    cb.capsule = {random_point(rng, 3), random_point(rng, 3), 0.1};
    DVec3 c1, c2;
    const double want_cap =
        segment_distance(ca.capsule.a, ca.capsule.b, cb.capsule.a, cb.capsule.b, c1, c2) - 0.4;
    const ConvexDistance dc = proxy_distance(ca, cb);
    CHECK(dc.intersect == (want_cap <= 0));
    if (want_cap > 0) CHECK(dc.distance == Approx(want_cap).epsilon(1e-9));
  }
}

TEST_CASE("GJK: convex polyhedra against feature pairs and the separating-axis theorem", "[gjk]") {
  std::mt19937_64 rng(3);
  int met = 0, apart = 0;
  for (int trial = 0; trial < 120; ++trial) {
    Proxy a, b;
    a.kind = b.kind = ProxyKind::Hull;
    a.parts.push_back(random_hull(rng, {0, 0, 0}, 12));
    b.parts.push_back(random_hull(rng, random_point(rng, 2.5), 12));
    const ConvexDistance d = proxy_distance(a, b);
    const bool sat_apart = separated(a.parts[0], b.parts[0]);
    INFO("trial " << trial);
    CHECK(d.intersect == !sat_apart);
    if (sat_apart) {
      ++apart;
      const double want = brute_distance(a.parts[0], b.parts[0]);
      CHECK(d.distance == Approx(want).epsilon(1e-9).margin(1e-12));
      CHECK(polyhedron_contains(a.parts[0], d.a, 1e-9));
      CHECK(polyhedron_contains(b.parts[0], d.b, 1e-9));
    } else {
      ++met;
    }
  }
  CHECK(met > 10);  // both outcomes were exercised
  CHECK(apart > 10);
}

namespace {

Proxy moved(Proxy p, DVec3 t) {
  p.sphere.center = p.sphere.center + t;
  p.box.center = p.box.center + t;
  p.capsule.a = p.capsule.a + t;
  p.capsule.b = p.capsule.b + t;
  for (ConvexPolyhedron& part : p.parts) {
    for (DVec3& v : part.vertices) v = v + t;
    for (DPlane& pl : part.planes) pl.d += dot(pl.n, t);
  }
  return p;
}

// Fitted proxies of random clouds: one of each kind but composite.
Proxy random_proxy(std::mt19937_64& rng, int trial, DVec3 centre) {
  std::vector<DVec3> p;
  for (int i = 0; i < 10; ++i) p.push_back(centre + random_point(rng, 1));
  const ProxyKind kinds[] = {ProxyKind::Sphere,  ProxyKind::Aabb, ProxyKind::Obb,
                             ProxyKind::Capsule, ProxyKind::Hull, ProxyKind::Kdop};
  return fit_proxy(kinds[trial % 6], p);
}

}  // namespace

TEST_CASE("penetration depth: closed forms, and the least translation that separates", "[gjk]") {
  Proxy s1, s2;
  s1.kind = s2.kind = ProxyKind::Sphere;
  s1.sphere = {{0, 0, 0}, 1};
  s2.sphere = {{0.6, 0.8, 0}, 0.5};
  const Penetration ps = penetration(s1, s2);
  CHECK(ps.intersect);
  CHECK(ps.depth == Approx(0.5).epsilon(1e-12));
  CHECK(len(ps.direction - DVec3{0.6, 0.8, 0}) < 1e-12);

  Proxy b1, b2;
  b1.kind = b2.kind = ProxyKind::Aabb;
  b1.box.half = {1, 1, 1};
  b2.box.center = {1.5, 0.2, -1.7};
  b2.box.half = {1, 2, 1};
  const Penetration pb = penetration(b1, b2);
  CHECK(pb.depth == Approx(0.3).epsilon(1e-12));  // overlaps: x 0.5, y 2.8, z 0.3
  CHECK(len(pb.direction - DVec3{0, 0, -1}) < 1e-12);
  CHECK_FALSE(penetration(b1, moved(b2, {0, 0, -0.31})).intersect);

  // The origin in the plane of a simplex face (symmetric boxes sharing their y and z centre):
  // a thin wall and a cube overlapping it by 0.05 meet, with that depth.
  Proxy wall, cube;
  wall.kind = cube.kind = ProxyKind::Aabb;
  wall.box.center = {0, 0, 5};
  wall.box.half = {0.05000000074505806, 1, 1};
  cube.box.center = {0.5, 0, 5};
  cube.box.half = {0.5, 0.5, 0.5};
  CHECK(proxy_distance(wall, cube).intersect);
  CHECK(penetration(wall, cube).depth == Approx(0.05).epsilon(1e-6));

  std::mt19937_64 rng(4);
  int tested = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Proxy a = random_proxy(rng, trial, {0, 0, 0});
    const Proxy b = random_proxy(rng, trial / 6 + trial, random_point(rng, 1.2));
    const Penetration p = penetration(a, b);
    INFO("trial " << trial << ": " << proxy_kind_name(a.kind) << " and " << proxy_kind_name(b.kind));
    CHECK(p.intersect == proxy_distance(a, b).intersect);
    if (!p.intersect) continue;
    ++tested;
    CHECK(p.exact);
    CHECK(std::abs(len(p.direction) - 1) < 1e-12);
    // Moved by the depth along the direction, b touches a; a little further, it is free; a
    // little less, it still meets a.
    CHECK_FALSE(proxy_distance(a, moved(b, p.direction * (p.depth * (1 + 1e-6) + 1e-9))).intersect);
    if (p.depth > 1e-6) CHECK(proxy_distance(a, moved(b, p.direction * (p.depth * (1 - 1e-3)))).intersect);
    // No other direction separates with a shorter move: the sampled directions need at least the depth.
    for (int k = 0; k < 40; ++k) {
      DVec3 d = random_point(rng, 1);
      if (len(d) < 1e-3) continue;
      d = d * (1 / len(d));
      CHECK(proxy_distance(a, moved(b, d * (p.depth * (1 - 1e-3)))).intersect);
    }
  }
  CHECK(tested > 100);
}

TEST_CASE("GJK on boxes snapped to a grid: every degenerate contact against the closed form", "[gjk]") {
  // Coordinates on a 0.25 grid put the origin on faces, edges and corners of the simplices.
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<int> pos(-8, 8), size(1, 6);
  int met = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    Proxy a, b;
    a.kind = b.kind = ProxyKind::Aabb;
    a.box.center = {0.25 * pos(rng), 0.25 * pos(rng), 0.25 * pos(rng)};
    a.box.half = {0.125 * size(rng), 0.125 * size(rng), 0.125 * size(rng)};
    b.box.center = {0.25 * pos(rng), 0.25 * pos(rng), 0.25 * pos(rng)};
    b.box.half = {0.125 * size(rng), 0.125 * size(rng), 0.125 * size(rng)};
    double gap2 = 0, depth = INFINITY;
    const double ca[3] = {a.box.center.x, a.box.center.y, a.box.center.z},
                 cb[3] = {b.box.center.x, b.box.center.y, b.box.center.z};
    const double ha[3] = {a.box.half.x, a.box.half.y, a.box.half.z},
                 hb[3] = {b.box.half.x, b.box.half.y, b.box.half.z};
    for (int k = 0; k < 3; ++k) {
      const double gap = std::abs(ca[k] - cb[k]) - ha[k] - hb[k];
      if (gap > 0) gap2 += gap * gap;
      depth = std::min(depth, -gap);
    }
    const ConvexDistance d = proxy_distance(a, b);
    INFO("trial " << trial);
    CHECK(d.intersect == (gap2 == 0));
    if (gap2 > 0) CHECK(d.distance == Approx(std::sqrt(gap2)).epsilon(1e-9));
    if (gap2 == 0) {
      ++met;
      CHECK(penetration(a, b).depth == Approx(depth).margin(1e-12));
    }
  }
  CHECK(met > 100);
}
