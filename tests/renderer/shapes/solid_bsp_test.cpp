// Tests for renderer/shapes/solid_bsp: solid_bsp_inside against the analytic cube and against a
// brute-force ray-parity count (a vote over three random rays) on concave and convex closed
// meshes, uniform and near-surface points; the welded, flipped and degenerate inputs; each
// refused mesh's message; the node budget; and SolidMesh's BVH distances against brute force.
#include "renderer/shapes/solid_bsp.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <string>

#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

struct V3 {
  double x, y, z;
};
V3 sub(V3 a, V3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
double dot3(V3 a, V3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 cross3(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 v3(Vec3f v) {
  return {v.x, v.y, v.z};
}

// Crossings of the ray o + t d (t > 0) with the mesh's triangles (Moller-Trumbore, double).
int crossings(const TriMesh& m, V3 o, V3 d) {
  int count = 0;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const V3 a = v3(m.positions[m.indices[t]]), b = v3(m.positions[m.indices[t + 1]]),
             c = v3(m.positions[m.indices[t + 2]]);
    const V3 e1 = sub(b, a), e2 = sub(c, a), pv = cross3(d, e2);
    const double det = dot3(e1, pv);
    if (det == 0) continue;
    const V3 tv = sub(o, a);
    const double u = dot3(tv, pv) / det;
    if (u < 0 || u > 1) continue;
    const V3 qv = cross3(tv, e1);
    const double v = dot3(d, qv) / det;
    if (v < 0 || u + v > 1) continue;
    if (dot3(e2, qv) / det > 0) ++count;
  }
  return count;
}

// Inside by ray parity: the majority of three random directions (a ray through an edge or a
// vertex miscounts; three rarely all do).
bool parity_inside(const TriMesh& m, Vec3f p, std::mt19937& rng) {
  std::normal_distribution<double> g;
  int votes = 0;
  for (int k = 0; k < 3; ++k) {
    const V3 d{g(rng), g(rng), g(rng)};
    votes += crossings(m, v3(p), d) % 2;
  }
  return votes >= 2;
}

double segment_distance(V3 p, V3 a, V3 b) {
  const V3 ab = sub(b, a);
  const double t = std::clamp(dot3(sub(p, a), ab) / dot3(ab, ab), 0.0, 1.0);
  const V3 q{a.x + ab.x * t, a.y + ab.y * t, a.z + ab.z * t};
  const V3 e = sub(p, q);
  return std::sqrt(dot3(e, e));
}

// Distance from p to the mesh: per triangle, the plane distance where p projects inside it,
// else the nearest of its three edges.
double brute_distance(const TriMesh& m, Vec3f pf) {
  const V3 p = v3(pf);
  double best = 1e300;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const V3 a = v3(m.positions[m.indices[t]]), b = v3(m.positions[m.indices[t + 1]]),
             c = v3(m.positions[m.indices[t + 2]]);
    const V3 n = cross3(sub(b, a), sub(c, a));
    const double nn = dot3(n, n);
    if (nn > 0) {
      const bool inside = dot3(cross3(sub(b, a), sub(p, a)), n) >= 0 &&
                          dot3(cross3(sub(c, b), sub(p, b)), n) >= 0 &&
                          dot3(cross3(sub(a, c), sub(p, c)), n) >= 0;
      if (inside) best = std::min(best, std::abs(dot3(sub(p, a), n)) / std::sqrt(nn));
    }
    best = std::min({best, segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
  }
  return best;
}

Bounds3f bounds_of(const TriMesh& m) {
  Bounds3f b;
  for (const Vec3f& p : m.positions) b = merge(b, p);
  return b;
}

// solid_bsp_inside against ray parity on `uniform` points in the box grown by 20% and `near`
// points offset from random triangles by 1e-6 to 1e-2 of the diagonal along their normals.
// Points within 1e-6 of the diagonal of the surface are left out (and counted).
void check_against_parity(const TriMesh& m, int uniform, int near, uint32_t seed) {
  const SolidBsp bsp = build_solid_bsp(m.positions, m.indices);
  const Bounds3f b = bounds_of(m);
  const float diag = length(b.extent());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0, 1);
  std::vector<Vec3f> points;
  for (int i = 0; i < uniform; ++i) {
    const Vec3f e = b.extent() * 1.2f, lo = b.center() - e * 0.5f;
    points.push_back({lo.x + e.x * u01(rng), lo.y + e.y * u01(rng), lo.z + e.z * u01(rng)});
  }
  const size_t triangles = m.indices.size() / 3;
  for (int i = 0; i < near; ++i) {
    const size_t t = std::min(size_t(u01(rng) * float(triangles)), triangles - 1);
    const Vec3f a = m.positions[m.indices[3 * t]], bb = m.positions[m.indices[3 * t + 1]],
                c = m.positions[m.indices[3 * t + 2]];
    float s = u01(rng), r = u01(rng);
    if (s + r > 1) s = 1 - s, r = 1 - r;
    const Vec3f on = a + (bb - a) * s + (c - a) * r;
    const float offset = diag * std::pow(10.0f, -6 + 4 * u01(rng)) * (u01(rng) < 0.5f ? -1.0f : 1.0f);
    points.push_back(on + normalize(cross(bb - a, c - a)) * offset);
  }
  int disagreements = 0, skipped = 0, inside = 0;
  for (const Vec3f& p : points) {
    if (brute_distance(m, p) < 1e-6 * diag) {
      ++skipped;
      continue;
    }
    const bool expected = parity_inside(m, p, rng);
    inside += expected;
    if (solid_bsp_inside(bsp, p) != expected) {
      ++disagreements;
      if (disagreements <= 5) UNSCOPED_INFO("disagrees at " << p.x << ", " << p.y << ", " << p.z);
    }
  }
  INFO("nodes " << bsp.nodes.size() << ", depth " << bsp.stats.depth << ", splits " << bsp.stats.splits
                << ", inside " << inside << ", skipped " << skipped << " of " << points.size());
  CHECK(disagreements == 0);
  CHECK(inside > 0);
  CHECK(inside < int(points.size()) - skipped);
  CHECK(skipped < int(points.size()) / 100);
}

// What building the mesh throws (what()), or "" if it builds.
std::string error_of(const TriMesh& m, const SolidBspConfig& config = {}) {
  try {
    build_solid_bsp(m.positions, m.indices, config);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("solid_bsp: a convex cube answers the analytic inside test", "[shapes][solid_bsp][quick]") {
  const TriMesh cube = box_mesh({-1, -1, -1}, {1, 1, 1});
  const SolidBsp bsp = build_solid_bsp(cube.positions, cube.indices);
  CHECK_FALSE(bsp.flipped);
  CHECK(bsp.volume == Approx(8));
  CHECK(bsp.nodes.size() == 6);  // one node per face: its two triangles are coplanar
  CHECK(bsp.stats.splits == 0);
  CHECK(bsp.stats.triangles == 12);
  CHECK(bsp.stats.in_leaves == 1);
  CHECK(bsp.stats.out_leaves == 6);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-2, 2);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const Vec3f p{u(rng), u(rng), u(rng)};
    const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    if (std::abs(m - 1) < 1e-6f) continue;
    ++checked;
    if (solid_bsp_inside(bsp, p) != (m < 1)) FAIL("wrong at " << p.x << ", " << p.y << ", " << p.z);
  }
  CHECK(checked > 19900);
  CHECK(solid_bsp_inside(bsp, {0, 0, 0}));
  CHECK_FALSE(solid_bsp_inside(bsp, {0, 0, 1.5f}));
  CHECK_FALSE(solid_bsp_inside(SolidBsp{}, {0, 0, 0}));  // no nodes: everything outside
}

TEST_CASE("solid_bsp: inside agrees with ray parity on concave and convex closed meshes",
          "[shapes][solid_bsp][quick]") {
  SECTION("L-shaped prism (a cube with a notch)") {
    check_against_parity(l_prism_mesh(), 4000, 2000, 11);
  }
  SECTION("five-pointed star prism") {
    check_against_parity(star_prism_mesh(), 4000, 2000, 12);
  }
  SECTION("spiky icosphere (star-shaped)") {
    check_against_parity(icosphere_mesh(1, 1.8f), 4000, 2000, 13);
  }
  SECTION("torus-like ring") {
    check_against_parity(ring_mesh(1, 0.35f, 24, 12), 4000, 2000, 14);
  }
  SECTION("box with a cavity") {
    check_against_parity(hollow_box_mesh(), 4000, 2000, 15);
  }
  SECTION("icosphere (convex, curved)") {
    check_against_parity(icosphere_mesh(2), 3000, 2000, 16);
  }
  SECTION("union of a ring and a spiky sphere (two components)") {
    TriMesh m = ring_mesh(2, 0.5f, 16, 8);
    m.append(icosphere_mesh(1, 1.5f));
    check_against_parity(m, 3000, 2000, 17);
  }
}

TEST_CASE("solid_bsp: the L prism answers its analytic inside test", "[shapes][solid_bsp][quick]") {
  const TriMesh l = l_prism_mesh();
  const SolidBsp bsp = build_solid_bsp(l.positions, l.indices);
  CHECK(bsp.volume == Approx(6));
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  for (int i = 0; i < 20000; ++i) {
    const Vec3f p{u(rng), u(rng), u(rng)};
    const float box = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) - 1;
    const float notch = std::min(p.x, p.y);     // > 0 in the notch
    const float margin = std::max(box, notch);  // < 0 inside the box and outside the notch
    if (std::abs(margin) < 1e-6f) continue;
    if (solid_bsp_inside(bsp, p) != (margin < 0)) FAIL("wrong at " << p.x << ", " << p.y << ", " << p.z);
  }
}

TEST_CASE("solid_bsp: welded, inward-wound and degenerate inputs give the same solid",
          "[shapes][solid_bsp][quick]") {
  const TriMesh cube = box_mesh({-1, -1, -1}, {1, 1, 1});
  const SolidBsp reference = build_solid_bsp(cube.positions, cube.indices);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2, 2);
  const auto same_solid = [&](const SolidBsp& bsp) {
    for (int i = 0; i < 5000; ++i) {
      const Vec3f p{u(rng), u(rng), u(rng)};
      if (std::abs(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) - 1) < 1e-6f) continue;
      if (solid_bsp_inside(bsp, p) != solid_bsp_inside(reference, p)) return false;
    }
    return true;
  };
  SECTION("24 vertices, 4 per face, welded by position") {
    const TriMesh split = split_box_mesh({-1, -1, -1}, {1, 1, 1});
    REQUIRE(split.positions.size() == 24);
    const SolidBsp bsp = build_solid_bsp(split.positions, split.indices);
    CHECK(same_solid(bsp));
  }
  SECTION("wound inwards: flipped, with a positive volume") {
    const TriMesh in = cube.flipped();
    const SolidBsp bsp = build_solid_bsp(in.positions, in.indices);
    CHECK(bsp.flipped);
    CHECK(bsp.volume == Approx(8));
    CHECK(same_solid(bsp));
  }
  SECTION("a triangle with a repeated vertex is skipped") {
    TriMesh m = cube;
    m.indices.insert(m.indices.end(), {0, 0, 7});
    const SolidBsp bsp = build_solid_bsp(m.positions, m.indices);
    CHECK(bsp.stats.degenerate == 1);
    CHECK(same_solid(bsp));
  }
  SECTION("a zero-area triangle closing a T-junction is skipped") {
    // The -y face's triangle (0, 1, 5) split at the midpoint m of edge 0-1, and the sliver
    // (0, 1, m) closing the T-junction the -z face's edge 1 -> 0 leaves.
    TriMesh m = cube;
    const uint32_t mid = uint32_t(m.positions.size());
    m.positions.push_back({0, -1, -1});
    bool replaced = false;
    for (size_t t = 0; t < m.indices.size(); t += 3)
      if (m.indices[t] == 0 && m.indices[t + 1] == 1 && m.indices[t + 2] == 5) {
        m.indices[t + 1] = mid;
        replaced = true;
      }
    REQUIRE(replaced);
    m.indices.insert(m.indices.end(), {mid, 1, 5, 0, 1, mid});
    const SolidBsp bsp = build_solid_bsp(m.positions, m.indices);
    CHECK(bsp.stats.degenerate == 1);
    CHECK(bsp.stats.triangles == 13);
    CHECK(same_solid(bsp));
  }
}

TEST_CASE("solid_bsp: the build is deterministic and within its budget", "[shapes][solid_bsp][quick]") {
  const TriMesh ring = ring_mesh(1, 0.35f, 24, 12);
  const SolidBsp a = build_solid_bsp(ring.positions, ring.indices);
  const SolidBsp b = build_solid_bsp(ring.positions, ring.indices);
  REQUIRE(a.nodes.size() == b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    CHECK(a.nodes[i].nx == b.nodes[i].nx);
    CHECK(a.nodes[i].d == b.nodes[i].d);
    CHECK(a.nodes[i].front == b.nodes[i].front);
    CHECK(a.nodes[i].back == b.nodes[i].back);
  }
  // Children follow their parents; every node is reached once.
  std::vector<int> reached(a.nodes.size(), 0);
  reached[0] = 1;
  for (size_t i = 0; i < a.nodes.size(); ++i)
    for (int32_t c : {a.nodes[i].front, a.nodes[i].back})
      if (c >= 0) {
        CHECK(size_t(c) > i);
        ++reached[size_t(c)];
      }
  CHECK(std::count(reached.begin(), reached.end(), 1) == int(a.nodes.size()));
  CHECK(a.stats.in_leaves + a.stats.out_leaves == a.nodes.size() + 1);
  CHECK(a.stats.fragments == a.stats.triangles + a.stats.splits);
  CHECK(a.nodes.size() <= 8 * a.stats.triangles + 1024);
}

TEST_CASE("solid_bsp: refused meshes name the problem", "[shapes][solid_bsp][quick]") {
  const TriMesh cube = box_mesh({-1, -1, -1}, {1, 1, 1});
  const std::string prefix = "build_solid_bsp: the mesh ";
  SECTION("open: a triangle missing") {
    TriMesh open = cube;
    open.indices.erase(open.indices.begin(), open.indices.begin() + 3);  // (0, 4, 6)
    CHECK(error_of(open) == prefix + "is not closed: edge (0, 4) is used by 1 triangle");
  }
  SECTION("inconsistent winding: one triangle reversed") {
    TriMesh bad = cube;
    std::swap(bad.indices[1], bad.indices[2]);  // (0, 6, 4)
    CHECK(error_of(bad) == prefix +
                               "is not consistently oriented: edge (0, 4) is used by 2 triangles in the same "
                               "direction (4 -> 0)");
  }
  SECTION("not manifold: two boxes sharing an edge") {
    TriMesh two = box_mesh({0, 0, 0}, {1, 1, 1});
    two.append(box_mesh({1, 1, 0}, {2, 2, 1}));
    CHECK(error_of(two) ==
          prefix +
              "is not closed: edge (3, 7) is used by 4 triangles (a closed surface uses each edge "
              "twice, once each way)");
  }
  SECTION("index out of range") {
    TriMesh bad = cube;
    bad.indices[5] = 8;
    CHECK(error_of(bad) == prefix + "has index 8 at indices[5] out of range (8 vertices)");
  }
  SECTION("no triangles, or an index count not a multiple of 3") {
    CHECK(error_of(TriMesh{cube.positions, {}}) == prefix + "has no triangles");
    TriMesh bad = cube;
    bad.indices.pop_back();
    CHECK(error_of(bad) == prefix + "has 35 indices, not a multiple of 3");
  }
  SECTION("a non-finite vertex") {
    TriMesh bad = cube;
    bad.positions[3].y = std::numeric_limits<float>::quiet_NaN();
    CHECK(error_of(bad) == prefix + "has a non-finite vertex 3 (1, nan, -1)");
    // An unused vertex may be anything.
    TriMesh unused = cube;
    unused.positions.push_back({kInfinity, 0, 0});
    CHECK(error_of(unused) == "");
  }
  SECTION("no area or no volume") {
    const TriMesh sheet{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 1}};
    CHECK(error_of(sheet) == prefix + "encloses no volume (signed volume 0)");
    const TriMesh line{{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, {0, 1, 2, 0, 2, 1}};
    CHECK(error_of(line) == prefix + "has no triangles of non-zero area");
    const TriMesh point{{{0, 0, 0}}, {0, 0, 0}};
    CHECK(error_of(point) == prefix + "has no triangles of non-zero area");
  }
  SECTION("over the node budget") {
    SolidBspConfig small;
    small.max_nodes = 3;
    const TriMesh l = l_prism_mesh();
    try {
      build_solid_bsp(l.positions, l.indices, small);
      FAIL("built");
    } catch (const SolidMeshError& e) {
      CHECK(e.over_budget());
      CHECK_THAT(e.reason(),
                 Catch::Matchers::StartsWith("needs more than 3 ") &&
                     Catch::Matchers::Contains("(SolidBspConfig::max_nodes = 3, for 24 triangles)"));
    }
  }
  SECTION("over the classification budget") {
    SolidBspConfig small;
    small.max_classifications = 1000;
    const TriMesh sphere = icosphere_mesh(2);  // convex: a chain of 320 nodes, ~51000 tests
    try {
      build_solid_bsp(sphere.positions, sphere.indices, small);
      FAIL("built");
    } catch (const SolidMeshError& e) {
      CHECK(e.over_budget());
      CHECK(e.reason() ==
            "needs more than 1000 polygon-plane tests (SolidBspConfig::max_classifications = 1000, for 320 "
            "triangles)");
    }
    small.max_classifications = 1000000;
    CHECK(build_solid_bsp(sphere.positions, sphere.indices, small).stats.classifications <= 1000000);
  }
  SECTION("bad configurations") {
    SolidBspConfig c;
    c.candidates = 0;
    CHECK(error_of(cube, c) == "SolidBspConfig::candidates must be in [1, 4096] (got 0)");
    c = {};
    c.relative_epsilon = 0;
    CHECK(error_of(cube, c) == "SolidBspConfig::relative_epsilon must be in [1e-12, 0.01] (got 0)");
    c = {};
    c.split_weight = -1;
    CHECK(error_of(cube, c) == "SolidBspConfig::split_weight must be in [0, 1e6] (got -1)");
  }
}

TEST_CASE("solid_bsp: SolidMesh distances match brute force and sign by the solid",
          "[shapes][solid_bsp][quick]") {
  for (const TriMesh& m : {ring_mesh(1, 0.35f, 24, 12), icosphere_mesh(1, 1.8f), hollow_box_mesh()}) {
    const SolidMesh solid = build_solid_mesh(m.positions, m.indices);
    CHECK(solid.bvh_triangles == m.indices.size() / 3);
    CHECK(solid_mesh_bytes(solid) > 0);
    const Bounds3f b = bounds_of(m);
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u(-1.5f, 1.5f);
    int bad = 0;
    for (int i = 0; i < 3000; ++i) {
      const Vec3f p = b.center() + b.extent() * Vec3f{u(rng), u(rng), u(rng)};
      const SolidMeshClosest c = solid_mesh_closest(solid, p);
      const double d = brute_distance(m, p);
      if (std::abs(c.distance - d) > 1e-5 * (1 + d)) ++bad;
      if (std::abs(length(p - c.point) - c.distance) > 1e-5f * (1 + c.distance)) ++bad;
      const float sd = solid_mesh_signed_distance(solid, p);
      if (std::abs(sd) != c.distance || (sd < 0) != solid_bsp_inside(solid.bsp, p)) ++bad;
      // The gradient is a unit vector pointing away from the closest point outside.
      const Vec3f g = solid_mesh_gradient(solid, p);
      if (std::abs(length(g) - 1) > 1e-4f) ++bad;
      if (c.distance > 1e-3f && dot(g, p - c.point) * sd < 0) ++bad;
    }
    CHECK(bad == 0);
  }
  // A default SolidMesh is empty: infinitely far, outside.
  CHECK(solid_mesh_signed_distance(SolidMesh{}, {0, 0, 0}) == kInfinity);
}
