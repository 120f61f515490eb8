// Tests for renderer/accel/query: closest points on triangles and shapes against closed forms,
// and nearest / within / overlap answered by every back end (every BVH width, spatial splits,
// kD-tree, grid, octree, BSP, Embree's point query) equal, bit for bit and in the same order,
// to an oracle that measures every primitive of the scene, on triangles, degenerate triangles,
// analytic and implicit shapes and two-level instances; the batch entry point equals the single
// queries for any thread count.
#include "renderer/accel/query.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "benchmarks/point_kdtree.h"
#include "renderer/accel/factory.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/shape_distance.h"
#include "support/cross_check.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

Affine3f translated(Affine3f a, Vec3f t) {
  a.m[0][3] += t.x;
  a.m[1][3] += t.y;
  a.m[2][3] += t.z;
  return a;
}

// Every primitive of the scene measured from p (the oracle), in query order.
std::vector<PrimitiveMatch> measure_all(const QueryScene& scene, Vec3f p) {
  std::vector<PrimitiveMatch> out;
  const size_t n = scene.instances.empty() ? scene.meshes.size() : scene.instances.size();
  for (uint32_t g = 0; g < n; ++g) {
    const GeometryView& view = scene.meshes[scene.instances.empty() ? g : scene.instances[g].mesh];
    const uint32_t prims = view.shape ? 1 : uint32_t(view.indices.size() / 3);
    for (uint32_t i = 0; i < prims; ++i) {
      PrimitiveMatch m;
      if (measure_primitive(scene, g, i, p, m)) out.push_back(m);
    }
  }
  std::sort(out.begin(), out.end(), [](const PrimitiveMatch& a, const PrimitiveMatch& b) {
    return a.distance != b.distance
               ? a.distance < b.distance
               : (a.geom_id != b.geom_id ? a.geom_id < b.geom_id : a.prim_id < b.prim_id);
  });
  return out;
}

bool same(const PrimitiveMatch& a, const PrimitiveMatch& b) {
  return a.geom_id == b.geom_id && a.prim_id == b.prim_id && std::memcmp(&a.distance, &b.distance, 4) == 0 &&
         std::memcmp(&a.point, &b.point, sizeof(Vec3f)) == 0;
}

std::string describe(const std::vector<PrimitiveMatch>& v) {
  std::string s;
  for (size_t i = 0; i < std::min<size_t>(v.size(), 6); ++i)
    s += "(" + std::to_string(v[i].geom_id) + "," + std::to_string(v[i].prim_id) + " " +
         std::to_string(v[i].distance) + ") ";
  return s + (v.size() > 6 ? "... " : "") + "[" + std::to_string(v.size()) + "]";
}

// Query points: random in and around the bounds, on the surfaces (vertices, edge midpoints,
// shape surface points) and far away.
std::vector<Vec3f> query_points(const QueryScene& scene, const Bounds3f& b, std::mt19937& rng, int n) {
  std::vector<Vec3f> pts;
  std::uniform_real_distribution<float> u(0, 1);
  const Vec3f lo = b.lo - b.extent() * 0.3f, ext = b.extent() * 1.6f;
  for (int i = 0; i < n; ++i) pts.push_back(lo + Vec3f{u(rng) * ext.x, u(rng) * ext.y, u(rng) * ext.z});
  for (const GeometryView& g : scene.meshes)
    for (size_t i = 0; i + 2 < g.indices.size() && i < 30; i += 9) {
      pts.push_back(g.positions[g.indices[i]]);
      pts.push_back((g.positions[g.indices[i]] + g.positions[g.indices[i + 1]]) * 0.5f);
    }
  pts.push_back(b.hi + b.extent() * 40.0f);
  pts.push_back(b.center());
  return pts;
}

void check_queries(const std::string& what, const QueryScene& scene, const std::vector<NamedAccel>& all,
                   int points, uint32_t seed) {
  Bounds3f b;
  for (const auto& a : all) b = merge(b, a.accel->bounds());
  REQUIRE_FALSE(b.empty());
  std::mt19937 rng(seed);
  const std::vector<Vec3f> pts = query_points(scene, b, rng, points);
  const float diag = length(b.extent());
  std::vector<PrimitiveMatch> got(64), list;
  int mismatches = 0;
  for (const Vec3f& p : pts) {
    const std::vector<PrimitiveMatch> oracle = measure_all(scene, p);
    for (const auto& a : all) {
      for (int k : {1, 7, 40}) {
        const float max_d = k == 7 ? 0.1f * diag : kInfinity;
        const size_t n = nearest(*a.accel, scene, p, k, max_d, got);
        std::vector<PrimitiveMatch> want;
        for (const auto& m : oracle)
          if (want.size() < size_t(k) && m.distance <= max_d) want.push_back(m);
        bool ok = n == want.size();
        for (size_t i = 0; ok && i < n; ++i) ok = same(got[i], want[i]);
        if (!ok && ++mismatches <= 5)
          FAIL_CHECK(what << " " << a.name << " nearest k=" << k << " at (" << p.x << "," << p.y << "," << p.z
                          << "): got " << describe({got.begin(), got.begin() + std::ptrdiff_t(n)}) << " want "
                          << describe(want));
      }
      const float r = 0.05f * diag;
      within(*a.accel, scene, p, r, list);
      std::vector<PrimitiveMatch> want;
      for (const auto& m : oracle)
        if (m.distance <= r) want.push_back(m);
      bool ok = list.size() == want.size();
      for (size_t i = 0; ok && i < list.size(); ++i) ok = same(list[i], want[i]);
      if (!ok && ++mismatches <= 5)
        FAIL_CHECK(what << " " << a.name << " within " << r << ": got " << describe(list) << " want "
                        << describe(want));
      const Vec3f h{0.04f * diag, 0.03f * diag, 0.05f * diag};
      const Bounds3f box{p - h, p + h};
      overlap(*a.accel, scene, box, list);
      size_t expected = 0;
      bool ids_ok = true;
      std::vector<std::pair<uint32_t, uint32_t>> ids;
      for (const auto& m : oracle)
        if (primitive_meets_box(scene, m.geom_id, m.prim_id, box)) ids.push_back({m.geom_id, m.prim_id});
      std::sort(ids.begin(), ids.end());
      expected = ids.size();
      ids_ok = list.size() == expected;
      for (size_t i = 0; ids_ok && i < list.size(); ++i)
        ids_ok = list[i].geom_id == ids[i].first && list[i].prim_id == ids[i].second;
      if (!ids_ok && ++mismatches <= 5)
        FAIL_CHECK(what << " " << a.name << " overlap: got " << describe(list) << ", want " << expected);
    }
  }
  CHECK(mismatches == 0);
}

}  // namespace

TEST_CASE("query: the closest point on a triangle in every Voronoi region, and on degenerate ones",
          "[query][quick]") {
  const Vec3f a{0, 0, 0}, b{2, 0, 0}, c{0, 2, 0};
  float u, v;
  CHECK(length(closest_point_on_triangle({0.5f, 0.5f, 3}, a, b, c, u, v) - Vec3f{0.5f, 0.5f, 0}) < 1e-6f);
  CHECK(u == Approx(0.25f));
  CHECK(v == Approx(0.25f));
  CHECK(length(closest_point_on_triangle({-1, -1, 1}, a, b, c, u, v) - a) == 0);  // vertex a
  CHECK((u == 0 && v == 0));
  CHECK(length(closest_point_on_triangle({3, -1, 0}, a, b, c, u, v) - b) == 0);                  // vertex b
  CHECK(length(closest_point_on_triangle({1, -1, 0}, a, b, c, u, v) - Vec3f{1, 0, 0}) < 1e-6f);  // edge ab
  CHECK(length(closest_point_on_triangle({-1, 1, 2}, a, b, c, u, v) - Vec3f{0, 1, 0}) < 1e-6f);  // edge ac
  CHECK(length(closest_point_on_triangle({2, 2, 0}, a, b, c, u, v) - Vec3f{1, 1, 0}) < 1e-6f);   // edge bc
  CHECK(u == Approx(0.5f));
  // Degenerate: a segment (two equal vertices) and a point.
  CHECK(length(closest_point_on_triangle({1, 1, 0}, a, b, b, u, v) - Vec3f{1, 0, 0}) < 1e-6f);
  CHECK(length(closest_point_on_triangle({1, 1, 0}, c, c, c, u, v) - c) == 0);
}

TEST_CASE("query: closest points on analytic and implicit shapes equal closed forms", "[query][quick]") {
  const Shape sphere = analytic_shape(ShapeKind::Sphere, 2);
  CHECK(length(closest_point_on_shape(sphere, {0, 0, 5}) - Vec3f{0, 0, 2}) < 1e-6f);
  CHECK(length(closest_point_on_shape(sphere, {0, 0.5f, 0}) - Vec3f{0, 2, 0}) < 1e-6f);  // from inside
  const Shape box = analytic_shape(ShapeKind::Box, 1, {1, 2, 3});
  CHECK(length(closest_point_on_shape(box, {5, 1, 1}) - Vec3f{1, 1, 1}) == 0);
  CHECK(length(closest_point_on_shape(box, {0.2f, 1.5f, 0}) - Vec3f{0.2f, 2, 0}) ==
        0);  // inside: nearest face
  const Shape capsule = analytic_shape(ShapeKind::Capsule, 0.5f, {}, 1);
  CHECK(length(closest_point_on_shape(capsule, {2, 0.3f, 0}) - Vec3f{0.5f, 0.3f, 0}) < 1e-6f);
  CHECK(length(closest_point_on_shape(capsule, {0, 4, 0}) - Vec3f{0, 1.5f, 0}) < 1e-6f);
  const Shape disk = analytic_shape(ShapeKind::Disk, 1);
  CHECK(length(closest_point_on_shape(disk, {3, 2, 0}) - Vec3f{1, 0, 0}) < 1e-6f);
  const Shape plane = analytic_shape(ShapeKind::Plane, 1, {1, 0, 2});
  CHECK(length(closest_point_on_shape(plane, {3, -2, 1}) - Vec3f{1, 0, 1}) == 0);
  // An implicit sphere of radius 1.5 (a Euclidean distance): projection lands on the closest point.
  const Shape implicit = make_implicit_shape(single_shape(sdf_primitive(SdfKind::Sphere, {1.5f, 0, 0})));
  const Vec3f q = closest_point_on_shape(implicit, {3, 4, 0});
  CHECK(length(q - Vec3f{0.9f, 1.2f, 0}) < 1e-5f);
}

TEST_CASE("query: every back end answers nearest, within and overlap as the oracle does",
          "[query][accel][crosscheck]") {
  Soup s = icosphere(2, 0.8f, {0, 0, 3});
  s.add_plane(1, -1.5f, -5.0f, 5.0f, 6);
  s.add({{0, 0, 0}, {1, 0, 0}, {2, 2, 2}, {3, 3, 3}}, {2, 2, 2, 2, 3, 3, 0, 1, 1});  // degenerate ones
  const std::vector<Shape> shapes{analytic_shape(ShapeKind::Sphere, 0.5f),
                                  analytic_shape(ShapeKind::Box, 1, {1, 0.3f, 0.7f}),
                                  analytic_shape(ShapeKind::Capsule, 0.25f, {}, 1.2f),
                                  analytic_shape(ShapeKind::Disk, 1.5f),
                                  analytic_shape(ShapeKind::Plane, 1, {2.5f, 0, 0.4f}),
                                  make_implicit_shape(csg_part())};
  std::vector<GeometryView> views = s.views();
  for (const Shape& sh : shapes) views.push_back({{}, {}, &sh});
  const QueryScene scene{views, {}};
  check_queries("mixed", scene, build_all(views), 40, 1);
}

TEST_CASE("query: every back end answers under two-level instancing", "[query][accel][crosscheck]") {
  const Soup s = icosphere(1, 0.5f, {0, 0, 0});
  const std::vector<Shape> shapes{analytic_shape(ShapeKind::Sphere, 0.5f),
                                  analytic_shape(ShapeKind::Box, 1, {0.4f, 0.3f, 0.2f}),
                                  make_implicit_shape(csg_part())};
  std::vector<GeometryView> views = s.views();
  for (const Shape& sh : shapes) views.push_back({{}, {}, &sh});
  std::vector<InstanceView> instances;
  for (uint32_t g = 0; g < views.size(); ++g) {
    const float x = -2.5f + 1.5f * float(g);
    instances.push_back({g, translated(Affine3f{}, {x, 0, 0})});
    Affine3f m;  // rotated about y and scaled by 1.3 (a similarity), or squashed (mesh only)
    const float c = std::cos(0.7f + 0.3f * float(g)), sn = std::sin(0.7f + 0.3f * float(g));
    const float squash = views[g].shape ? 1.3f : 0.6f;
    m.m[0][0] = 1.3f * c, m.m[0][2] = 1.3f * sn;
    m.m[1][1] = squash;
    m.m[2][0] = -1.3f * sn, m.m[2][2] = 1.3f * c;
    instances.push_back({g, translated(m, {x, 1.5f, 0.5f})});
  }
  instances.push_back({0, Affine3f{}});  // an identity placement too
  const QueryScene scene{views, instances};
  std::vector<NamedAccel> all;
  for (const auto& n : accelerator_names()) all.push_back({n, make_accelerator(n, views, instances)});
  check_queries("instances", scene, all, 30, 2);
}

TEST_CASE("query: the batch entry point equals the single queries for any thread count", "[query][accel]") {
  const Soup s = icosphere(2, 1.0f, {0, 0, 0});
  const std::vector<GeometryView> views = s.views();
  const QueryScene scene{views, {}};
  const auto accel = make_accelerator("bvh", views);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2, 2);
  std::vector<Vec3f> pts(500);
  for (auto& p : pts) p = {u(rng), u(rng), u(rng)};
  std::vector<PrimitiveMatch> one, two, single(4);
  std::vector<uint32_t> c1, c2;
  nearest_batch(*accel, scene, pts, 4, kInfinity, 1, one, c1);
  nearest_batch(*accel, scene, pts, 4, kInfinity, 2, two, c2);
  REQUIRE(c1 == c2);
  for (size_t i = 0; i < pts.size(); ++i) {
    REQUIRE(c1[i] == 4);
    REQUIRE(nearest(*accel, scene, pts[i], 4, kInfinity, single) == 4);
    for (size_t j = 0; j < 4; ++j) {
      CHECK(same(one[i * 4 + j], two[i * 4 + j]));
      CHECK(same(one[i * 4 + j], single[j]));
    }
  }
  // Bad arguments answer nothing.
  CHECK(nearest(*accel, scene, {NAN, 0, 0}, 1, kInfinity, single) == 0);
  CHECK(nearest(*accel, scene, {0, 0, 0}, 0, kInfinity, single) == 0);
  CHECK(nearest(*accel, scene, {0, 0, 0}, 1, -1.0f, single) == 0);
}

TEST_CASE("query: the structures prune: a nearest query reaches a small part of a large mesh",
          "[query][accel]") {
  // A 100 x 100 quad grid (20000 triangles): k = 1 and k = 8 nearest from points above it.
  Soup s;
  s.add_plane(1, 0.0f, -10.0f, 10.0f, 100);
  const std::vector<GeometryView> views = s.views();
  struct Counter final : RegionVisitor {
    size_t offered = 0;
    void visit(uint32_t, uint32_t, QueryRegion& region) override {
      ++offered;
      region.radius2 = std::min(region.radius2, 0.25f);  // as a search that found something 0.5 away
    }
  };
  for (const auto& a : build_all(views)) {
    Counter c;
    QueryRegion r;
    r.centre = {1.03f, 0.5f, -2.71f};
    a.accel->visit_region(r, c, nullptr);
    INFO(a.name << " offered " << c.offered << " of 20000");
    CHECK(c.offered > 0);
    CHECK(c.offered < 1000);
  }
}

namespace {

// Points in a unit cube and a dense cluster, all distinct.
std::vector<Vec3f> cloud(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::normal_distribution<float> g(0, 0.05f);
  std::vector<Vec3f> p;
  for (int i = 0; i < n; ++i)
    p.push_back(i % 3 ? Vec3f{u(rng), u(rng), u(rng)} : Vec3f{0.3f + g(rng), -0.2f + g(rng), 0.1f + g(rng)});
  return p;
}

}  // namespace

TEST_CASE("query: point sets: every structure finds the k nearest points as the oracle and nanoflann do",
          "[query][accel][crosscheck][heavy]") {
  const Mesh m = make_point_set(cloud(3000, 11), "cloud");
  const std::vector<GeometryView> views{{m.positions, m.indices}};
  const QueryScene scene{views, {}};
  const std::vector<NamedAccel> all = build_all(views);
  check_queries("points", scene, all, 25, 4);
  // Placed twice under a top level.
  const std::vector<InstanceView> instances{{0, Affine3f{}}, {0, translated(Affine3f{}, {1.5f, 0, 0})}};
  std::vector<NamedAccel> placed;
  for (const auto& n : accelerator_names()) placed.push_back({n, make_accelerator(n, views, instances)});
  check_queries("placed points", {views, instances}, placed, 15, 5);
  // No ray hits a point, even one aimed straight at it.
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(-1, 1);
  for (const auto& a : all)
    for (size_t i = 0; i < m.positions.size(); i += 7) {
      const Vec3f from{u(rng) * 3, u(rng) * 3, 4};
      Hit h;
      CHECK_FALSE(a.accel->intersect({from, 0, normalize(m.positions[i] - from), kInfinity}, h));
    }
#ifdef PENUMBRA_HAVE_NANOFLANN
  bench::PointAdaptor adaptor{m.positions};
  bench::PointTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));  // builds the index
  std::vector<PrimitiveMatch> got(8);
  int compared = 0;
  for (const Vec3f& p : cloud(200, 12)) {
    uint32_t ids[8];
    float d2[8];
    const size_t n = tree.knnSearch(&p.x, 8, ids, d2);
    REQUIRE(n == 8);
    for (const auto& a : all) {
      REQUIRE(nearest(*a.accel, scene, p, 8, kInfinity, got) == 8);
      for (size_t j = 0; j < 8; ++j) {
        INFO(a.name << " neighbour " << j);
        CHECK(got[j].distance == Approx(std::sqrt(d2[j])).epsilon(1e-5).margin(1e-6));
        // The same point where no other lies at nearly the same distance.
        const bool tied =
            (j > 0 && d2[j] - d2[j - 1] < 1e-6f * d2[j]) || (j < 7 && d2[j + 1] - d2[j] < 1e-6f * d2[j]);
        if (!tied) CHECK(got[j].prim_id == ids[j]);
      }
      ++compared;
    }
  }
  CHECK(compared == 200 * int(all.size()));
#else
  WARN("SKIP: nanoflann is not installed (libnanoflann-dev): the oracle comparison stands alone");
#endif
}
