// Tests for renderer/accel/grid: the triangle-box overlap test on known configurations, the
// resolution rule (cells ~ lambda N), references per overlapped cell only, and exact agreement
// with brute force for other densities.
#include "renderer/accel/grid.h"

#include <catch2/catch.hpp>

#include "io/gltf/loader.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/scene.h"
#include "support/cross_check.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

TEST_CASE("grid: triangle-box overlap on known configurations", "[accel][grid][quick]") {
  const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
  // Inside, straddling a face, far away.
  CHECK(triangle_box_overlap(lo, hi, {0.2f, 0.2f, 0.5f}, {0.8f, 0.2f, 0.5f}, {0.5f, 0.8f, 0.5f}));
  CHECK(triangle_box_overlap(lo, hi, {-1, 0.5f, 0.5f}, {2, 0.5f, 0.4f}, {0.5f, 0.5f, 3}));
  CHECK_FALSE(triangle_box_overlap(lo, hi, {2, 2, 2}, {3, 2, 2}, {2, 3, 2}));
  // A big triangle whose plane cuts the box although no vertex is inside.
  CHECK(triangle_box_overlap(lo, hi, {-10, -10, 0.5f}, {10, -10, 0.5f}, {0, 10, 0.5f}));
  // Touching a face exactly counts.
  CHECK(triangle_box_overlap(lo, hi, {1, 0.2f, 0.2f}, {2, 0.2f, 0.2f}, {1, 0.8f, 0.8f}));
  // The triangle's bounding box overlaps the box but the triangle does not (plane test):
  // the plane x + y + z = 3.2 passes beyond the corner (1, 1, 1).
  CHECK_FALSE(triangle_box_overlap(lo, hi, {3.2f, 0, 0}, {0, 3.2f, 0}, {0, 0, 3.2f}));
  // Beside the edge x = y = 1, in the plane x + y = 2.1: the bounding boxes touch, the plane
  // test separates.
  CHECK_FALSE(triangle_box_overlap(lo, hi, {1.1f, 1.0f, -1}, {1.0f, 1.1f, -1}, {1.05f, 1.05f, 2}));
  // Separated only by an edge x box-axis cross product: in the plane z = 0.5 (which cuts the
  // box), bounding box overlapping the box's corner column, but entirely beyond x + y = 2.
  CHECK_FALSE(triangle_box_overlap(lo, hi, {1.5f, 0.8f, 0.5f}, {0.8f, 1.5f, 0.5f}, {1.5f, 1.5f, 0.5f}));
}

TEST_CASE("grid: about lambda cells per triangle, references only where triangles overlap", "[accel][grid]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  for (float lambda : {1.0f, 4.0f, 16.0f}) {
    GridConfig c;
    c.lambda = lambda;
    c.max_depth = 1;  // the flat uniform grid: every cell a leaf
    const AccelStats s = make_grid_accelerator(views, c)->stats();
    const double target = lambda * double(s.triangles);
    INFO("lambda " << lambda << ": " << s.nodes << " cells, " << s.config);
    CHECK(double(s.nodes) >= target / 3);
    CHECK(double(s.nodes) <= target * 3);
    CHECK(s.leaves == s.nodes);
    CHECK(s.references >= s.triangles);
    CHECK(s.empty_leaves < s.nodes);
  }
  // A single diagonal triangle across a fine grid of small ones: with the exact overlap test it
  // is listed in O(n) cells of the n x n layer it spans, not in all n^2 its bounding box covers.
  std::vector<Vec3f> pos{{0, 0, 0}, {20, 20, 0}, {20, 20.01f, 0}};
  std::vector<uint32_t> idx{0, 1, 2};
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) {
      const uint32_t b = uint32_t(pos.size());
      const Vec3f o{x + 0.1f, y + 0.1f, 0.0f};
      pos.insert(pos.end(), {o, o + Vec3f{0.1f, 0, 0}, o + Vec3f{0, 0.1f, 0}});
      idx.insert(idx.end(), {b, b + 1, b + 2});
    }
  const GeometryView view{pos, idx};
  GridConfig c;
  c.lambda = 1;
  c.max_depth = 1;
  const AccelStats s = make_grid_accelerator(std::span(&view, 1), c)->stats();
  INFO(s.config << ", " << s.references << " references for " << s.triangles << " triangles");
  CHECK(s.references < s.triangles + s.nodes / 4);
}

TEST_CASE("grid: coarse, fine and capped grids give brute force's answers", "[accel][grid]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  const auto brute = make_accelerator("brute", views);
  const Bounds3f b = compute_bounds(l.scene);
  const Reference ref = reference(*brute, all_rays(*brute, views, b, lights_around(b), 1, 11));
  for (auto [lambda, max_res] : {std::pair{0.01f, 1024u}, std::pair{32.0f, 1024u}, std::pair{4.0f, 3u}}) {
    GridConfig c;
    c.lambda = lambda;
    c.max_resolution = max_res;
    const auto grid = make_grid_accelerator(views, c);
    const auto r = cross_check(*grid, ref, views, length(b.extent()), true, 0.0f);
    INFO(summary("grid " + grid->stats().config, r));
    CHECK(r.failures() == 0);
  }
}

TEST_CASE("grid: a flat scene gets one cell across its thickness", "[accel][grid]") {
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int i = 0; i < 50; ++i) {
    const uint32_t b = uint32_t(pos.size());
    pos.insert(pos.end(), {{float(i), 0, 0}, {float(i) + 1, 0, 0}, {float(i), 0, 1}});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  const GeometryView view{pos, idx};
  const auto grid = make_grid_accelerator(std::span(&view, 1));
  CHECK_THAT(grid->stats().config, Catch::Contains("x1x"));
  Hit h;
  REQUIRE(grid->intersect({{10.25f, 1, 0.25f}, 0, {0, -1, 0}, kInfinity}, h));
  CHECK(h.t == 1);
  CHECK(h.prim_id == 10);
}

TEST_CASE("grid: configuration is validated", "[accel][grid][quick]") {
  GridConfig c;
  c.lambda = 0;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("lambda"));
  c = {};
  c.max_resolution = 0;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_resolution"));
  c = {};
  c.max_cells = 0;
  CHECK_THROWS_AS(validate(c), std::invalid_argument);
  c = {};
  c.max_depth = 0;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_depth"));
  c.max_depth = 5;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_depth"));
  c = {};
  c.split_threshold = 0;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("split_threshold"));
  CHECK_NOTHROW(validate(GridConfig{}));
}

TEST_CASE("grid: thousands of large overlapping triangles build quickly and still answer exactly",
          "[accel][grid][hostile][heavy]") {
  // 3000 triangles each spanning the whole scene: lambda N cells would give lambda N^2 candidate
  // references; the builder must coarsen instead of running for minutes.
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 3000; ++i) {
    const uint32_t b = uint32_t(pos.size());
    pos.insert(pos.end(), {{-10, u(rng), -10}, {10, u(rng), -10}, {0, u(rng), 10}});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  const GeometryView view{pos, idx};
  const auto grid = make_grid_accelerator(std::span(&view, 1));
  const AccelStats s = grid->stats();
  INFO(s.config << ", " << s.references << " references");
  CHECK(s.references <= (1ull << 26));
  const auto brute = make_accelerator("brute", std::span(&view, 1));
  const Bounds3f b = brute->bounds();
  std::mt19937 rng2(4);
  const Reference ref = reference(*brute, random_rays(b, 300, rng2));
  const auto r = cross_check(*grid, ref, std::span(&view, 1), length(b.extent()), true, 0.0f);
  INFO(summary("overlapping", r));
  CHECK(r.failures() == 0);
  // The hierarchies face the same input: the kD-tree's SAH stops splitting what cannot be
  // separated, the BVH partitions.
  for (const char* name : {"kdtree", "bvh"}) {
    const auto a = make_accelerator(name, std::span(&view, 1));
    const auto ra = cross_check(*a, ref, std::span(&view, 1), length(b.extent()), true, 0.0f);
    INFO(summary(std::string("overlapping ") + name, ra) << "; " << a->stats().references << " references");
    CHECK(ra.failures() == 0);
    CHECK(a->stats().references <= 64 * a->stats().triangles);
  }
}

namespace {

/// The grid built with `c` must answer `rays` exactly as brute force does.
void check_against_brute(const std::string& what, std::span<const GeometryView> views,
                         const std::vector<Ray>& rays, const GridConfig& c) {
  const auto brute = make_accelerator("brute", views);
  const Reference ref = reference(*brute, rays);
  const auto grid = make_grid_accelerator(views, c);
  const auto r = cross_check(*grid, ref, views, length(bounds_of(views).extent()), true, 0.0f);
  INFO(summary(what + ", grid " + grid->stats().config, r));
  CHECK(r.failures() == 0);
}

/// A dense sphere of 5120 triangles at the origin inside a room 800 m wide and 50 m high
/// (floor, ceiling and four walls of a few large quads): the "teapot in a stadium".
Soup sphere_in_stadium() {
  Soup s = icosphere(4, 1, {0, 0.5f, 0});
  s.add_plane(1, -1, -400, 400, 4);
  s.add_plane(1, 50, -400, 400, 2);
  for (int axis : {0, 2})
    for (float v : {-400.0f, 400.0f}) s.add_plane(axis, v, -400, 400, 2);
  return s;
}

/// Rays for the room as a whole and for the region around the dense object.
std::vector<Ray> stadium_rays(std::span<const GeometryView> views) {
  const auto brute = make_accelerator("brute", views);
  const Bounds3f room = bounds_of(views);
  const Bounds3f object{{-1.5f, -1, -1.5f}, {1.5f, 2, 1.5f}};
  std::vector<Ray> rays = all_rays(*brute, views, room, lights_around(room), 1, 5);
  const std::vector<Ray> near = all_rays(*brute, views, object, lights_around(object), 1, 6);
  rays.insert(rays.end(), near.begin(), near.end());
  return rays;
}

/// n slivers as in the benchmark's scene: 60-80 long along x, 5-20 thousandths wide, in a 4 x 4
/// cross-section.
Soup slivers(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int i = 0; i < n; ++i) {
    const float x0 = -50 + 20 * u(rng), len = 60 + 20 * u(rng), y = -2 + 4 * u(rng), z = -2 + 4 * u(rng);
    const float w = 0.005f + 0.015f * u(rng), a = 6.2831853f * u(rng);
    const Vec3f off{0, w * std::cos(a), w * std::sin(a)};
    const uint32_t b = uint32_t(pos.size());
    pos.insert(pos.end(), {{x0, y, z}, Vec3f{x0 + len, y, z} + off, Vec3f{x0 + len, y, z} - off});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  Soup s;
  s.add(std::move(pos), std::move(idx));
  return s;
}

}  // namespace

TEST_CASE("grid: a dense object in a huge room gets sub-grids, tests fewer triangles, and answers exactly",
          "[accel][grid][heavy]") {
  const Soup soup = sphere_in_stadium();
  const auto views = soup.views();
  const std::vector<Ray> rays = stadium_rays(views);
  GridConfig flat;
  flat.max_depth = 1;
  const auto hier = make_grid_accelerator(views);
  const auto uniform = make_grid_accelerator(views, flat);
  const AccelStats hs = hier->stats(), us = uniform->stats();
  INFO(hs.config << "; flat: " << us.config);
  CHECK_THAT(hs.config, !Catch::Contains(" 0 sub-grids"));
  CHECK(hs.max_depth >= 1);
  CHECK(hs.leaves < hs.nodes);
  CHECK_THAT(us.config, Catch::Contains(" 0 sub-grids"));
  CHECK(us.max_depth == 0);
  CHECK(us.leaves == us.nodes);
  // The sphere lies in few cells of the flat grid, so rays that reach it test most of its
  // triangles there; the sub-grids test only those near the ray.
  TraversalCost hc, uc;
  for (const Ray& r : rays) {
    Hit h;
    hier->intersect_counted(r, h, hc);
    uniform->intersect_counted(r, h, uc);
  }
  INFO("triangle tests: " << hc.triangles << " hierarchical, " << uc.triangles << " flat");
  CHECK(hc.triangles * 4 < uc.triangles);

  for (uint32_t depth : {1u, 2u, 3u, 4u})
    for (uint32_t split : {1u, 16u}) {
      GridConfig c;
      c.max_depth = depth;
      c.split_threshold = split;
      check_against_brute("stadium", views, rays, c);
    }
}

TEST_CASE("grid: long thin triangles get long cells and answer exactly", "[accel][grid]") {
  const Soup soup = slivers(3000);
  const auto views = soup.views();
  for (uint32_t depth : {1u, 3u}) {
    GridConfig c;
    c.max_depth = depth;
    const AccelStats s = make_grid_accelerator(views, c)->stats();
    INFO(s.config << ": " << s.references << " references for " << s.triangles << " triangles");
    // Cubic cells of the lambda N rule would be 0.5 wide: each sliver in over 100 cells.
    CHECK(s.references < 16 * s.triangles);
  }
  const auto brute = make_accelerator("brute", views);
  const Bounds3f b = bounds_of(views);
  const std::vector<Ray> rays = all_rays(*brute, views, b, lights_around(b), 1, 8);
  for (uint32_t depth : {1u, 2u, 3u}) {
    GridConfig c;
    c.max_depth = depth;
    check_against_brute("slivers", views, rays, c);
  }
}
