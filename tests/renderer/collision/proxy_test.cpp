// Tests for renderer/collision/proxy and hull: closed forms (the minimal sphere of a cube and of
// points on a sphere, the capsule of a cylinder, the OBB of a rotated box, hull and k-DOP
// volumes of a cube), the minimal sphere against a brute-force oracle over every 2-, 3- and
// 4-point support set, Welzl <= Ritter, containment of every input point by every kind, Qhull's
// own volume, OBB <= AABB under rotations of the model, nested k-DOPs, composite parts by
// connected component, surface samples on the surface, and the Jacobi eigenvectors against
// Eigen's.
#include "renderer/collision/proxy.h"

#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

using namespace penumbra;

namespace {

constexpr double kPiD = std::numbers::pi;

double len(DVec3 v) {
  return std::sqrt(dot(v, v));
}

// A random rotation (unit quaternion from 4 normal deviates) applied to every point.
struct Rotation {
  double m[3][3];
  DVec3 operator()(DVec3 p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z, m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z,
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z};
  }
};

Rotation random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  double w = n(rng), x = n(rng), y = n(rng), z = n(rng);
  const double l = std::sqrt(w * w + x * x + y * y + z * z);
  w /= l, x /= l, y /= l, z /= l;
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
           {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
           {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
}

std::vector<DVec3> cube_corners(double h, DVec3 c = {0, 0, 0}) {
  std::vector<DVec3> p;
  for (int i = 0; i < 8; ++i) p.push_back(c + DVec3{i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h});
  return p;
}

// An anisotropic Gaussian cloud, rotated and moved off the origin.
std::vector<DVec3> cloud(size_t n, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  const Rotation r = random_rotation(rng);
  std::vector<DVec3> p;
  for (size_t i = 0; i < n; ++i) p.push_back(r({3 * g(rng), 1 * g(rng), 0.3 * g(rng)}) + DVec3{5, -2, 1});
  return p;
}

// The ball through `s` (2 to 4 points) whose centre lies in their affine hull, by Eigen's
// least-squares solve of |c - s_i|^2 = |c - s_0|^2 with c = s_0 + sum_j a_j (s_j - s_0).
bool oracle_ball(const std::vector<DVec3>& s, DVec3& c, double& r) {
  const int k = int(s.size()) - 1;
  Eigen::MatrixXd a(k, k);
  Eigen::VectorXd b(k);
  for (int i = 0; i < k; ++i) {
    const DVec3 di = s[size_t(i + 1)] - s[0];
    for (int j = 0; j < k; ++j) a(i, j) = 2 * dot(di, s[size_t(j + 1)] - s[0]);
    b(i) = dot(di, di);
  }
  Eigen::FullPivLU<Eigen::MatrixXd> lu(a);
  if (lu.rank() < k) return false;
  const Eigen::VectorXd x = lu.solve(b);
  c = s[0];
  for (int j = 0; j < k; ++j) c = c + (s[size_t(j + 1)] - s[0]) * x(j);
  r = len(s[0] - c);
  return true;
}

// The smallest ball holding every point: the least radius over the balls of all 2-, 3- and
// 4-point subsets that hold every point (one of them is the minimal ball).
double brute_force_radius(const std::vector<DVec3>& p) {
  double best = INFINITY;
  const size_t n = p.size();
  auto consider = [&](const std::vector<DVec3>& s) {
    DVec3 c;
    double r;
    if (!oracle_ball(s, c, r)) return;
    for (const DVec3& q : p)
      if (len(q - c) > r * (1 + 1e-9) + 1e-12) return;
    best = std::min(best, r);
  };
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      consider({p[i], p[j]});
      for (size_t k = j + 1; k < n; ++k) {
        consider({p[i], p[j], p[k]});
        for (size_t l = k + 1; l < n; ++l) consider({p[i], p[j], p[k], p[l]});
      }
    }
  return best;
}

// A cylinder of radius r and height h along `axis` through `centre`, `sides` around: rim
// vertices and triangles (sides and caps).
void cylinder(double r, double h, int sides, DVec3 axis, DVec3 centre, std::vector<DVec3>& pts,
              std::vector<uint32_t>& tris) {
  const DVec3 t = std::abs(axis.x) < 0.9 ? DVec3{1, 0, 0} : DVec3{0, 1, 0};
  DVec3 e1 = cross(axis, t);
  e1 = e1 * (1 / len(e1));
  const DVec3 e2 = cross(axis, e1);
  const uint32_t base = uint32_t(pts.size());
  for (int end = 0; end < 2; ++end)
    for (int i = 0; i < sides; ++i) {
      const double phi = 2 * kPiD * i / sides;
      pts.push_back(centre + axis * (end ? h / 2 : -h / 2) + (e1 * std::cos(phi) + e2 * std::sin(phi)) * r);
    }
  for (int i = 0; i < sides; ++i) {
    const uint32_t a = base + uint32_t(i), b = base + uint32_t((i + 1) % sides);
    tris.insert(tris.end(), {a, b, b + uint32_t(sides), a, b + uint32_t(sides), a + uint32_t(sides)});
  }
  for (int i = 1; i + 1 < sides; ++i) {
    tris.insert(tris.end(), {base, base + uint32_t(i + 1), base + uint32_t(i)});
    const uint32_t top = base + uint32_t(sides);
    tris.insert(tris.end(), {top, top + uint32_t(i), top + uint32_t(i + 1)});
  }
}

}  // namespace

TEST_CASE("minimal sphere: closed forms for a cube and for points on a sphere", "[proxy]") {
  std::vector<DVec3> p = cube_corners(1, {2, 3, -1});
  p.push_back({2, 3, -1});  // interior points and duplicates change nothing
  p.push_back({2.5, 3, -1});
  p.push_back(p[3]);
  const BoundingSphere s = minimal_sphere(p);
  CHECK(s.radius == Approx(std::sqrt(3.0)).epsilon(1e-12));
  CHECK(len(s.center - DVec3{2, 3, -1}) < 1e-12);

  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  std::vector<DVec3> q;
  for (int i = 0; i < 5000; ++i) {
    const DVec3 d{g(rng), g(rng), g(rng)};
    q.push_back(DVec3{-1, 0, 4} + d * (2.5 / len(d)));
  }
  const BoundingSphere t = minimal_sphere(q);
  CHECK(t.radius <= 2.5 * (1 + 1e-12));
  CHECK(t.radius > 2.5 * (1 - 1e-3));  // the points nearly cover the sphere
}

TEST_CASE("minimal sphere equals the brute-force oracle over all support sets", "[proxy]") {
  for (uint64_t seed = 1; seed <= 25; ++seed) {
    std::vector<DVec3> p = cloud(9 + seed % 5, seed);
    const BoundingSphere s = minimal_sphere(p);
    INFO("seed " << seed);
    CHECK(s.radius == Approx(brute_force_radius(p)).epsilon(1e-9));
    CHECK(s.radius <= ritter_sphere(p).radius * (1 + 1e-12));
  }
}

TEST_CASE("Welzl's sphere is never larger than Ritter's", "[proxy]") {
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    const std::vector<DVec3> p = cloud(2000, seed);
    const BoundingSphere w = minimal_sphere(p), r = ritter_sphere(p);
    CHECK(w.radius <= r.radius * (1 + 1e-12));
  }
}

TEST_CASE("every proxy kind contains every input point", "[proxy]") {
  const std::vector<DVec3> p = cloud(3000, 11);
  for (int k = 0; k < kProxyKindCount; ++k) {
    const ProxyKind kind = ProxyKind(k);
    INFO(proxy_kind_name(kind));
    const Proxy proxy = fit_proxy(kind, p);
    size_t outside = 0;
    for (const DVec3& q : p) outside += proxy_contains(proxy, q, 1e-9) ? 0 : 1;
    CHECK(outside == 0);
    CHECK(proxy_volume(proxy) > 0);
    ProxyKind parsed;
    CHECK(parse_proxy_kind(proxy_kind_name(kind), parsed));
    CHECK(parsed == kind);
  }
  ProxyKind unused;
  CHECK_FALSE(parse_proxy_kind("cube", unused));
  CHECK_THROWS_AS(fit_proxy(ProxyKind::Aabb, std::vector<DVec3>{}), std::invalid_argument);
  CHECK_THROWS_AS(fit_proxy(ProxyKind::Hull, std::vector<DVec3>{{0, 0, NAN}}), std::invalid_argument);
  ProxyConfig bad;
  bad.kdop = 10;
  CHECK_THROWS_AS(fit_proxy(ProxyKind::Kdop, p, {}, bad), std::invalid_argument);
}

TEST_CASE("convex hull: a cube's faces merged, Qhull's own volume, flat input thickened", "[proxy]") {
  std::vector<DVec3> p = cube_corners(1);
  for (int i = 0; i < 50; ++i)
    p.push_back({std::sin(i) * 0.9, std::cos(3.0 * i) * 0.9, std::sin(7.0 * i) * 0.9});
  p.push_back({1, 0.5, -0.25});  // on a face: not a vertex after merging
  const ConvexPolyhedron hull = convex_hull(p);
  CHECK(hull.planes.size() == 6);
  CHECK(hull.vertices.size() >= 8);  // the point on a face may be joggled out into a vertex
  CHECK(hull.volume == Approx(8).epsilon(1e-12));
  CHECK(hull.area == Approx(24).epsilon(1e-12));
  CHECK(hull.qhull_volume == Approx(8).epsilon(1e-9));
  for (const DPlane& pl : hull.planes) CHECK(std::abs(pl.d) == Approx(1).epsilon(1e-12));

  const std::vector<DVec3> q = cloud(5000, 3);
  const ConvexPolyhedron h = convex_hull(q);
  CHECK(h.volume == Approx(h.qhull_volume).epsilon(1e-9));
  CHECK(h.planes.size() == h.triangles.size() / 3);  // random points: no two facets coplanar

  // Many cospherical and coplanar points (a 20000-sided cylinder): fast, and exact in volume.
  std::vector<DVec3> cyl;
  for (int y = 0; y < 2; ++y)
    for (int i = 0; i < 20000; ++i)
      cyl.push_back({std::cos(2 * kPiD * i / 20000), double(y), std::sin(2 * kPiD * i / 20000)});
  const ConvexPolyhedron c = convex_hull(cyl);
  int caps = 0;
  for (const DPlane& pl : c.planes) caps += std::abs(pl.n.y) > 1 - 1e-12 ? 1 : 0;
  CHECK(caps == 2);  // each cap one face
  CHECK(c.volume == Approx(0.5 * 20000 * std::sin(2 * kPiD / 20000)).epsilon(1e-8));
  for (const DVec3& v : cyl) CHECK(polyhedron_contains(c, v, 1e-9));
  CHECK_FALSE(h.thickened);
  for (const DVec3& v : q) CHECK(polyhedron_contains(h, v, 1e-9));

  std::vector<DVec3> flat;
  for (int i = 0; i < 20; ++i) flat.push_back({double(i % 5), 0.5, double(i / 5)});
  const ConvexPolyhedron slab = convex_hull(flat);
  CHECK(slab.thickened);
  CHECK(slab.volume == Approx(4 * 3 * 2 * 1e-6 * std::sqrt(4 * 4 + 3 * 3.0)).epsilon(0.05));
  for (const DVec3& v : flat) CHECK(polyhedron_contains(slab, v, 1e-9));
  const ConvexPolyhedron dot_hull = convex_hull(std::vector<DVec3>{{1, 2, 3}});
  CHECK(dot_hull.thickened);
  CHECK(polyhedron_contains(dot_hull, {1, 2, 3}, 0));
}

TEST_CASE("OBB: a rotated box exactly, never larger than the AABB under rotations", "[proxy]") {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 10; ++trial) {
    const Rotation r = random_rotation(rng);
    std::vector<DVec3> box;
    for (const DVec3& c : cube_corners(1)) box.push_back(r({c.x * 3, c.y * 1, c.z * 0.5}) + DVec3{1, 2, 3});
    const Proxy obb = fit_proxy(ProxyKind::Obb, box);
    CHECK(proxy_volume(obb) == Approx(8 * 3 * 1 * 0.5).epsilon(1e-9));
    CHECK(len(obb.box.center - DVec3{1, 2, 3}) < 1e-9);
    const DVec3* a = obb.box.axis;
    CHECK(dot(a[0], a[1]) == Approx(0).margin(1e-12));
    CHECK(dot(cross(a[0], a[1]), a[2]) == Approx(1).epsilon(1e-12));

    std::vector<DVec3> c = cloud(500, 100 + uint64_t(trial));
    for (DVec3& v : c) v = r(v);
    CHECK(proxy_volume(fit_proxy(ProxyKind::Obb, c)) <=
          proxy_volume(fit_proxy(ProxyKind::Aabb, c)) * (1 + 1e-12));
  }
}

TEST_CASE("capsule of a cylinder: the cylinder's radius and height", "[proxy]") {
  std::vector<DVec3> pts;
  std::vector<uint32_t> tris;
  DVec3 axis{1, 2, -0.5};
  axis = axis * (1 / len(axis));
  cylinder(0.5, 4, 64, axis, {2, -1, 0}, pts, tris);
  const Proxy c = fit_proxy(ProxyKind::Capsule, pts);
  CHECK(c.capsule.radius == Approx(0.5).epsilon(1e-9));
  // The segment's ends come from sqrt(r^2 - rho^2) at rim vertices, where rho = r to rounding:
  // they carry the square root of the rounding error.
  CHECK(len(c.capsule.b - c.capsule.a) == Approx(4).epsilon(1e-7));
  CHECK(std::abs(dot(c.capsule.b - c.capsule.a, axis)) == Approx(4).epsilon(1e-7));
  // A squat cylinder's capsule is no longer than the minimal sphere allows.
  const std::vector<DVec3> cube = cube_corners(1);
  const Proxy sq = fit_proxy(ProxyKind::Capsule, cube);
  for (const DVec3& v : cube) CHECK(proxy_contains(sq, v, 1e-12));
}

TEST_CASE("k-DOPs: 6-DOP = AABB, larger k nested, all above the hull", "[proxy]") {
  const std::vector<DVec3> p = cloud(2000, 21);
  auto volume = [&](int k) {
    ProxyConfig cfg;
    cfg.kdop = k;
    const Proxy proxy = fit_proxy(ProxyKind::Kdop, p, {}, cfg);
    CHECK(proxy.parts.at(0).planes.size() == size_t(k));
    return proxy_volume(proxy);
  };
  const double v6 = volume(6), v14 = volume(14), v18 = volume(18), v26 = volume(26);
  CHECK(v6 == Approx(proxy_volume(fit_proxy(ProxyKind::Aabb, p))).epsilon(1e-9));
  CHECK(v26 <= v18 * (1 + 1e-12));
  CHECK(v26 <= v14 * (1 + 1e-12));
  CHECK(v18 <= v6 * (1 + 1e-12));
  CHECK(v14 <= v6 * (1 + 1e-12));
  CHECK(proxy_volume(fit_proxy(ProxyKind::Hull, p)) <= v26 * (1 + 1e-12));
  CHECK(kdop_directions(26).size() == 13);
}

TEST_CASE("composite: one hull per connected component, seams welded", "[proxy]") {
  // Two unit cubes apart, each face with its own four vertices (split as glTF exports do).
  std::vector<DVec3> pts;
  std::vector<uint32_t> tris;
  for (double x0 : {0.0, 5.0}) {
    const std::vector<DVec3> c = cube_corners(0.5, {x0, 0, 0});
    const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
      const uint32_t base = uint32_t(pts.size());
      for (int k = 0; k < 4; ++k) pts.push_back(c[size_t(f[k])]);
      tris.insert(tris.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
  }
  const Proxy comp = fit_proxy(ProxyKind::Composite, pts, tris);
  REQUIRE(comp.parts.size() == 2);
  CHECK(comp.parts[0].volume == Approx(1).epsilon(1e-12));
  CHECK(comp.parts[1].volume == Approx(1).epsilon(1e-12));
  CHECK(proxy_volume(comp) < proxy_volume(fit_proxy(ProxyKind::Hull, pts)) / 2);
  CHECK(fit_proxy(ProxyKind::Composite, pts).parts.size() == 1);  // no triangles: one hull
  CHECK_THROWS_AS(fit_proxy(ProxyKind::Composite, pts, std::vector<uint32_t>{0, 1, 999}),
                  std::invalid_argument);
}

TEST_CASE("surface samples lie on the proxy's surface", "[proxy]") {
  const std::vector<DVec3> p = cloud(1000, 31);
  for (ProxyKind kind : {ProxyKind::Sphere, ProxyKind::Obb, ProxyKind::Capsule, ProxyKind::Hull}) {
    INFO(proxy_kind_name(kind));
    const Proxy proxy = fit_proxy(kind, p);
    std::vector<DVec3> s;
    sample_proxy_surface(proxy, 500, 1, s);
    REQUIRE(s.size() == 500);
    std::vector<DVec3> again;
    sample_proxy_surface(proxy, 500, 1, again);
    CHECK(std::memcmp(s.data(), again.data(), s.size() * sizeof(DVec3)) == 0);
    for (const DVec3& q : s) {
      CHECK(proxy_contains(proxy, q, 1e-9));
      // Moved outwards from the centroid of the proxy by 1e-6, a surface point leaves it.
      DVec3 centre = kind == ProxyKind::Sphere    ? proxy.sphere.center
                     : kind == ProxyKind::Obb     ? proxy.box.center
                     : kind == ProxyKind::Capsule ? (proxy.capsule.a + proxy.capsule.b) * 0.5
                                                  : DVec3{5, -2, 1};
      const DVec3 out = q + (q - centre) * (1e-6 / len(q - centre));
      CHECK_FALSE(proxy_contains(proxy, out, 0));
    }
  }
}

TEST_CASE("principal axes: the covariance's eigenvectors as Eigen finds them", "[proxy]") {
  const std::vector<DVec3> p = cloud(4000, 41);
  DVec3 axes[3];
  principal_axes(p, nullptr, axes);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const DVec3& q : p) mean += Eigen::Vector3d(q.x, q.y, q.z);
  mean /= double(p.size());
  for (const DVec3& q : p) {
    const Eigen::Vector3d d = Eigen::Vector3d(q.x, q.y, q.z) - mean;
    cov += d * d.transpose();
  }
  cov /= double(p.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d v = es.eigenvectors().col(2 - i);  // Eigen sorts ascending
    CHECK(std::abs(v.dot(Eigen::Vector3d(axes[i].x, axes[i].y, axes[i].z))) == Approx(1).epsilon(1e-9));
  }
  CHECK(dot(cross(axes[0], axes[1]), axes[2]) == Approx(1).epsilon(1e-12));
}
