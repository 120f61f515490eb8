// Tests for renderer/accel/bsp: oblique planes chosen where the SAH says they pay, the reference
// budget, the configuration, thread-independent builds, and exact agreement with brute force
// (hit/miss, t and barycentrics bit for bit) on scenes and rays made to stress the plane steps:
// triangles lying in candidate planes, rays starting on split planes or running parallel to
// them, rays with zero direction components, huge and tiny coordinates, flat scenes, shapes.
#include "renderer/accel/bsp.h"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/accel/stats.h"
#include "support/cross_check.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr float kR = 0.70710678f;  // 1 / sqrt(2)

/// Checks `accel` against brute force over all_rays(scale, seed) and `extra`: hit/miss, t, the
/// primitive and u, v exact.
void check_against_brute(const std::string& what, const Accelerator& accel,
                         std::span<const GeometryView> views, int scale, uint32_t seed,
                         const std::vector<Ray>& extra = {}) {
  const auto brute = make_accelerator("brute", views);
  const Bounds3f b = bounds_of(views);
  std::vector<Ray> rays = all_rays(*brute, views, b, lights_around(b), scale, seed);
  rays.insert(rays.end(), extra.begin(), extra.end());
  const Reference ref = reference(*brute, std::move(rays));
  const auto r = cross_check(accel, ref, views, length(b.extent()), true, 0.0f);
  INFO(summary(what, r));
  CHECK(r.failures() == 0);
  CHECK(r.hits > 0);
}

void add_triangle(Soup& s, Vec3f a, Vec3f b, Vec3f c) {
  s.add({a, b, c}, {0, 1, 2});
}

/// `n` random triangles with vertices in [-5, 5]^3 around random centres, edges up to `size`.
Soup random_soup(int n, float size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int i = 0; i < n; ++i) {
    const Vec3f c{5 * u(rng), 5 * u(rng), 5 * u(rng)};
    for (int k = 0; k < 3; ++k) {
      idx.push_back(uint32_t(pos.size()));
      pos.push_back(c + Vec3f{u(rng), u(rng), u(rng)} * (0.5f * size));
    }
  }
  Soup s;
  s.add(std::move(pos), std::move(idx));
  return s;
}

/// Rays through the box `b` along directions with zero components (axes, face and body
/// diagonals) from random origins.
std::vector<Ray> axis_rays(const Bounds3f& b, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  const Vec3f dirs[] = {{1, 0, 0},  {0, -1, 0}, {0, 0, 1},   {1, 1, 0},      {0, -1, 1},
                        {1, 0, -1}, {1, 1, 1},  {-1, 1, -1}, {-0.0f, 0, -1}, {0, 0.0f, -0.0f}};
  const Bounds3f g = grown(b, 0.1f);
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    Vec3f o;
    for (int k = 0; k < 3; ++k) o[k] = g.lo[k] + u(rng) * (g.hi[k] - g.lo[k]);
    const Vec3f d = dirs[i % 10];
    rays.push_back({o, 0, d, kInfinity});
    rays.push_back({o, 0, d * -1.0f, kInfinity});
  }
  return rays;
}

/// Rays starting on plane (n, k) (to float rounding) inside `b`: along the plane (several
/// in-plane directions), across it both ways, and at random.
std::vector<Ray> plane_rays(const BspPlane& p, const Bounds3f& b, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Ray> rays;
  const Vec3f t1 = normalize(cross(p.n, std::fabs(p.n.x) < 0.9f ? Vec3f{1, 0, 0} : Vec3f{0, 1, 0}));
  const Vec3f t2 = cross(p.n, t1);
  for (int i = 0; i < n; ++i) {
    Vec3f q;
    for (int k = 0; k < 3; ++k) q[k] = b.lo[k] + u(rng) * (b.hi[k] - b.lo[k]);
    const Vec3f o = q - p.n * (dot(p.n, q) - p.k);
    const float a = 6.2831853f * u(rng);
    const Vec3f along = t1 * std::cos(a) + t2 * std::sin(a);
    for (const Vec3f& d : {along, t1, t2, p.n, p.n * -1.0f, random_direction(rng)})
      rays.push_back({o, 0, d, kInfinity});
  }
  return rays;
}

/// Exact points of the three diagonal planes x + y = 0, x = z and x + y + z = 0 through the
/// origin: multiples of 1/16 in [-1, 1].
Soup diagonal_planes_scene() {
  Soup s;
  for (int i = -4; i < 4; ++i)
    for (int j = -4; j < 4; ++j) {
      const float a = float(i) / 4, b = float(j) / 4, h = 0.25f;
      add_triangle(s, {a, -a, b}, {a + h, -a - h, b}, {a, -a, b + h});                  // x + y = 0
      add_triangle(s, {a, b, a}, {a + h, b, a + h}, {a, b + h, a});                     // x = z
      add_triangle(s, {a, b, -a - b}, {a + h, b, -a - b - h}, {a, b + h, -a - b - h});  // x + y + z = 0
    }
  const Soup extra = random_soup(60, 0.3f, 9);
  s.add(extra.positions[0], extra.indices[0]);
  return s;
}

/// Rays starting exactly on the diagonal planes of diagonal_planes_scene(), along and across.
std::vector<Ray> diagonal_plane_rays(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> g(-64, 64);
  std::vector<Ray> rays;
  for (int i = 0; i < n; ++i) {
    const float a = float(g(rng)) / 64, b = float(g(rng)) / 64;
    const Vec3f on[3] = {{a, -a, b}, {a, b, a}, {a, b, -a - b}};
    const Vec3f along[3][3] = {{{1, -1, 0}, {0, 0, 1}, {1, -1, 3}},
                               {{1, 0, 1}, {0, 1, 0}, {1, 2, 1}},
                               {{1, -1, 0}, {0, 1, -1}, {1, 1, -2}}};
    const Vec3f across[3] = {{1, 1, 0}, {1, 0, -1}, {1, 1, 1}};
    for (int p = 0; p < 3; ++p) {
      for (const Vec3f& d : along[p]) {
        rays.push_back({on[p], 0, d, kInfinity});
        rays.push_back({on[p], 0, d * -1.0f, kInfinity});
      }
      rays.push_back({on[p], 0, across[p], kInfinity});
      rays.push_back({on[p], 0, across[p] * -1.0f, kInfinity});
    }
  }
  return rays;
}

/// A dense grid of small horizontal triangles filling the part x + y <= 9 of the square
/// [0, 10]^2 and a few triangles beyond x + y >= 11: a diagonal plane separates the two sets
/// (and cuts off the empty corner), no axis plane does.
Soup diagonal_halves_scene() {
  Soup s;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      const float x = 0.5f * float(i) + 0.1f, y = 0.5f * float(j) + 0.1f, z = 0.1f * float((i * 7 + j) % 5);
      if (x + y + 0.3f > 9) continue;
      add_triangle(s, {x, y, z}, {x + 0.3f, y, z}, {x, y + 0.3f, z});
    }
  for (const Vec3f c : {Vec3f{9.5f, 9.5f, 0}, Vec3f{6, 9.5f, 0.2f}, Vec3f{9.5f, 6, 0.4f}, Vec3f{8, 8, 0.3f}})
    add_triangle(s, c, c + Vec3f{0.3f, 0, 0}, c + Vec3f{0, 0.3f, 0});
  return s;
}

}  // namespace

TEST_CASE("bsp: oblique planes are chosen where they pay", "[accel][bsp]") {
  const Soup s = diagonal_halves_scene();
  const auto views = s.views();
  const auto bsp = make_bsp_accelerator(views);
  const auto root = bsp_root_plane(*bsp);
  REQUIRE(root);
  // The root plane is not an axis plane.
  const Vec3f n = root->n;
  CHECK(int(n.x != 0) + int(n.y != 0) + int(n.z != 0) >= 2);
  CHECK_THAT(bsp->stats().config, !Catch::Contains(", 0 oblique planes"));
  BspConfig axes;
  axes.fixed_directions = false;
  axes.triangle_planes = 0;
  const auto kd = make_bsp_accelerator(views, axes);
  const auto kd_root = bsp_root_plane(*kd);
  REQUIRE(kd_root);
  CHECK(int(kd_root->n.x != 0) + int(kd_root->n.y != 0) + int(kd_root->n.z != 0) == 1);
  CHECK_THAT(kd->stats().config, Catch::Contains(", 0 oblique planes"));
  CHECK(bsp->stats().sah_cost < kd->stats().sah_cost);
  check_against_brute("diagonal halves", *bsp, views, 1, 3);
  check_against_brute("diagonal halves, axes only", *kd, views, 1, 3);
}

TEST_CASE("bsp: a long triangle is referenced only where its clipped part reaches", "[accel][bsp]") {
  // A thin diagonal sliver across a grid of small triangles: its vertices lie on both sides of
  // most planes, but the part of it inside a node is clipped by the node's planes, so it lands
  // only in leaves along the diagonal.
  Soup s;
  add_triangle(s, {0, 0, 0}, {10, 10, 0}, {10, 10.01f, 0});
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      if (x == y) continue;
      const Vec3f o{x + 0.2f, y + 0.6f, 0.0f};
      add_triangle(s, o, o + Vec3f{0.2f, 0, 0}, o + Vec3f{0, 0.2f, 0});
    }
  const auto views = s.views();
  const auto bsp = make_bsp_accelerator(views);
  const AccelStats st = bsp->stats();
  CHECK(st.leaves > 20);
  CHECK(st.references < st.triangles + (st.leaves - st.empty_leaves) / 2);
  check_against_brute("sliver", *bsp, views, 1, 5);
}

TEST_CASE("bsp: statistics describe the tree", "[accel][bsp]") {
  const Soup s = icosphere(3, 1, {0.1f, 0.2f, 0.3f});
  const auto views = s.views();
  const AccelStats st = make_bsp_accelerator(views)->stats();
  CHECK(st.name == "bsp");
  CHECK(st.triangles == 1280);
  CHECK(st.nodes == 2 * (st.nodes - st.leaves) + 1);  // a full binary tree
  CHECK(st.references >= st.triangles);
  CHECK(st.max_leaf_prims >= 1);
  CHECK(st.max_depth >= 1);
  CHECK(st.bytes == st.nodes * 20 + st.references * 44);
  // The SAH with constants (15, 20) is K_T x the node term plus K_I x the leaf term.
  CHECK(st.sah_cost == Approx(15 * st.sah_node_area + 20 * st.sah_leaf_area));
  CHECK(st.sah_cost < 20.0 * 1280);  // better than one leaf
  CHECK_THAT(st.config, Catch::Contains("bins 8") && Catch::Contains("triangle_planes 4"));
  // An empty scene and a single triangle.
  const std::vector<GeometryView> none;
  const auto empty = make_bsp_accelerator(none);
  Hit h;
  CHECK_FALSE(empty->intersect({{0, 0, -1}, 0, {0, 0, 1}, kInfinity}, h));
  CHECK(empty->stats().nodes == 0);
  const std::vector<Vec3f> tri{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2};
  const GeometryView one{tri, idx};
  const auto single = make_bsp_accelerator(std::span(&one, 1));
  CHECK(single->stats().nodes == 1);
  REQUIRE(single->intersect({{0.25f, 0.25f, -1}, 0, {0, 0, 1}, kInfinity}, h));
  CHECK(h.t == 1);
}

TEST_CASE("bsp: answers equal brute force", "[accel][bsp]") {
  SECTION("icosphere") {
    const Soup s = icosphere(3, 1, {0.1f, 0.2f, 0.3f});
    const auto views = s.views();
    const auto bsp = make_bsp_accelerator(views);
    check_against_brute("icosphere", *bsp, views, 1, 1, axis_rays(bounds_of(views), 300, 2));
  }
  SECTION("random soup") {
    const Soup s = random_soup(500, 2, 4);
    const auto views = s.views();
    const auto bsp = make_bsp_accelerator(views);
    std::vector<Ray> extra = axis_rays(bounds_of(views), 300, 5);
    if (const auto root = bsp_root_plane(*bsp)) {
      const auto on = plane_rays(*root, bounds_of(views), 200, 6);
      extra.insert(extra.end(), on.begin(), on.end());
    }
    check_against_brute("random soup", *bsp, views, 1, 7, extra);
  }
  SECTION("triangles lying in diagonal candidate planes, rays on them and along them") {
    const Soup s = diagonal_planes_scene();
    const auto views = s.views();
    const auto bsp = make_bsp_accelerator(views);
    std::vector<Ray> extra = diagonal_plane_rays(150, 8);
    const auto ax = axis_rays(bounds_of(views), 300, 9);
    extra.insert(extra.end(), ax.begin(), ax.end());
    const auto root = bsp_root_plane(*bsp);
    REQUIRE(root);
    const auto on = plane_rays(*root, bounds_of(views), 200, 10);
    extra.insert(extra.end(), on.begin(), on.end());
    check_against_brute("diagonal planes", *bsp, views, 2, 11, extra);
  }
  SECTION("huge and tiny coordinates") {
    for (const auto& [r, c] :
         {std::pair{1e4f, Vec3f{3e6f, -1e6f, 2e6f}}, std::pair{1e-4f, Vec3f{1e-3f, 0, 0}},
          std::pair{1e-7f, Vec3f{0, 0, 0}}, std::pair{1e12f, Vec3f{0, 0, 0}}}) {
      Soup s = icosphere(2, r, c);
      const Soup soup = random_soup(100, 2, 12);
      std::vector<Vec3f> p = soup.positions[0];
      for (Vec3f& v : p) v = c + v * (r / 5);
      s.add(std::move(p), soup.indices[0]);
      const auto views = s.views();
      const auto bsp = make_bsp_accelerator(views);
      CHECK(bsp->stats().nodes > 1);
      check_against_brute("radius " + format_number(r), *bsp, views, 1, 13,
                          axis_rays(bounds_of(views), 200, 14));
    }
  }
  SECTION("rays from far away (the plane step's error grows with the origin)") {
    const Soup s = diagonal_planes_scene();
    const auto views = s.views();
    const auto bsp = make_bsp_accelerator(views);
    std::mt19937 rng(30);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<Ray> rays;
    for (int i = 0; i < 3000; ++i) {
      const float dist = std::pow(10.0f, 3 + 4 * (u(rng) + 1) / 2);  // 1e3 to 1e7
      const Vec3f target{u(rng), u(rng), u(rng)};
      // Every fourth ray runs along a diagonal plane of the scene, the others at random.
      const Vec3f along = i % 4 == 0 ? normalize(Vec3f{1, -1, u(rng)}) : random_direction(rng);
      rays.push_back({target - along * dist, 0, along, kInfinity});
    }
    // From that far, float t cannot tell nearby surfaces apart, so hits tie: the closest t
    // (and hit/miss, and occluded()) must be brute force's, bit for bit; the primitive may
    // differ only at exactly the same t.
    const auto brute = make_accelerator("brute", views);
    size_t hits = 0, wrong = 0;
    std::string first;
    for (const Ray& r : rays) {
      Hit hb, ha;
      const bool b_hit = brute->intersect(r, hb), a_hit = bsp->intersect(r, ha);
      hits += b_hit;
      const bool ok = a_hit == b_hit && bsp->occluded(r) == b_hit && (!b_hit || ha.t == hb.t);
      if (!ok && first.empty()) first = describe(r) + " -> " + describe(ha) + " vs brute " + describe(hb);
      wrong += !ok;
    }
    INFO(first);
    CHECK(wrong == 0);
    CHECK(hits > rays.size() / 10);
  }
  SECTION("flat scenes: an axis plane and an oblique plane") {
    Soup axis;
    axis.add_plane(2, 0.5f, -1, 1, 8);
    Soup oblique;
    for (int i = -8; i < 8; ++i)
      for (int j = -8; j < 8; ++j) {
        const float a = float(i) / 8, b = float(j) / 8, h = 0.125f;
        add_triangle(oblique, {a, 1 - a, b}, {a + h, 1 - a - h, b}, {a, 1 - a, b + h});  // x + y = 1
      }
    for (const Soup* s : {&axis, &oblique}) {
      const auto views = s->views();
      const auto bsp = make_bsp_accelerator(views);
      std::vector<Ray> extra = axis_rays(bounds_of(views), 300, 15);
      const BspPlane in_scene = s == &axis ? BspPlane{{0, 0, 1}, 0.5f} : BspPlane{{kR, kR, 0}, kR};
      const auto on = plane_rays(in_scene, bounds_of(views), 200, 16);
      extra.insert(extra.end(), on.begin(), on.end());
      check_against_brute(s == &axis ? "flat, axis" : "flat, oblique", *bsp, views, 1, 17, extra);
    }
  }
  SECTION("shapes among triangles") {
    Shape sphere;
    sphere.radius = 0.7f;
    Shape box;
    box.kind = ShapeKind::Box;
    box.half_size = {0.3f, 1.5f, 0.2f};
    const Soup soup = random_soup(200, 1.5f, 18);
    std::vector<GeometryView> views = soup.views();
    views.push_back({{}, {}, &sphere});
    views.push_back({{}, {}, &box});
    const auto bsp = make_bsp_accelerator(views);
    CHECK(bsp->stats().shapes == 2);
    check_against_brute("shapes", *bsp, views, 1, 19, axis_rays(bounds_of(views), 200, 20));
  }
}

TEST_CASE("bsp: other configurations give brute force's answers", "[accel][bsp]") {
  const Soup planes = diagonal_planes_scene();
  const Soup soup = random_soup(200, 3, 21);
  BspConfig base;
  base.parallel_threshold = 32;
  std::vector<std::pair<std::string, BspConfig>> configs;
  const auto add = [&](const std::string& name, auto change) {
    BspConfig c = base;
    change(c);
    configs.push_back({name, c});
  };
  add("bins 2", [](BspConfig& c) { c.bins = 2; });
  add("bins 64, 16 triangle planes", [](BspConfig& c) { c.bins = 64, c.triangle_planes = 16; });
  add("axes only", [](BspConfig& c) { c.fixed_directions = false, c.triangle_planes = 0; });
  add("triangle planes only besides the axes", [](BspConfig& c) { c.fixed_directions = false; });
  add("max_depth 3", [](BspConfig& c) { c.max_depth = 3; });
  add("costs 1, 1, no bonus",
      [](BspConfig& c) { c.traversal_cost = 1, c.intersection_cost = 1, c.empty_bonus = 0; });
  add("costs 80, 1", [](BspConfig& c) { c.traversal_cost = 80, c.intersection_cost = 1; });
  add("max_depth 64, cheap traversal", [](BspConfig& c) { c.max_depth = 64, c.traversal_cost = 0.1f; });
  for (const Soup* s : {&planes, &soup}) {
    const auto views = s->views();
    for (const auto& [name, c] : configs) {
      const auto bsp = make_bsp_accelerator(views, c);
      const AccelStats st = bsp->stats();
      if (c.max_depth > 0) CHECK(st.max_depth <= uint64_t(c.max_depth));
      CHECK(st.references <= 4 * st.triangles + st.triangles / 50);  // the reference budget
      std::vector<Ray> extra = s == &planes ? diagonal_plane_rays(40, 22) : std::vector<Ray>{};
      if (const auto root = bsp_root_plane(*bsp)) {
        const auto on = plane_rays(*root, bounds_of(views), 60, 23);
        extra.insert(extra.end(), on.begin(), on.end());
      }
      check_against_brute(name, *bsp, views, 1, 24, extra);
    }
  }
}

TEST_CASE("bsp: the reference budget bounds duplication", "[accel][bsp]") {
  // Long slivers crossing the whole box in every direction: nearly every plane cuts most of them.
  std::mt19937 rng(25);
  std::uniform_real_distribution<float> u(-1, 1);
  Soup s;
  for (int i = 0; i < 300; ++i) {
    const Vec3f a{5 * u(rng), 5 * u(rng), 5 * u(rng)};
    const Vec3f b = a * -1.0f + Vec3f{u(rng), u(rng), u(rng)};
    add_triangle(s, a, b, b + Vec3f{u(rng), u(rng), u(rng)} * 0.05f);
  }
  const Soup small = random_soup(300, 0.2f, 26);
  s.add(small.positions[0], small.indices[0]);
  const auto views = s.views();
  BspConfig c;
  c.traversal_cost = 1;  // splitting looks cheap: only the budget holds duplication back
  c.max_depth = 40;
  const auto bsp = make_bsp_accelerator(views, c);
  const AccelStats st = bsp->stats();
  CHECK(st.references > st.triangles);
  CHECK(st.references <= 4 * st.triangles + st.triangles / 50);
  check_against_brute("slivers", *bsp, views, 1, 27);
}

TEST_CASE("bsp: the build does not depend on the thread count", "[accel][bsp]") {
  Soup s = random_soup(1500, 0.6f, 28);
  const Soup sphere = icosphere(2, 2, {1, 1, 1});
  s.add(sphere.positions[0], sphere.indices[0]);
  const auto views = s.views();
  BspConfig c;
  c.parallel_threshold = 16;
  std::unique_ptr<Accelerator> a1, a2;
  tbb::task_arena(1).execute([&] { a1 = make_bsp_accelerator(views, c); });
  tbb::task_arena(2).execute([&] { a2 = make_bsp_accelerator(views, c); });
  const AccelStats s1 = a1->stats(), s2 = a2->stats();
  CHECK(s1.nodes == s2.nodes);
  CHECK(s1.leaves == s2.leaves);
  CHECK(s1.references == s2.references);
  CHECK(s1.max_depth == s2.max_depth);
  CHECK(s1.sah_cost == s2.sah_cost);
  CHECK(s1.config == s2.config);
  std::mt19937 rng(29);
  const auto rays = random_rays(bounds_of(views), 2000, rng);
  size_t same = 0;
  for (const Ray& r : rays) {
    Hit h1, h2;
    a1->intersect(r, h1);
    a2->intersect(r, h2);
    same +=
        h1.t == h2.t && h1.geom_id == h2.geom_id && h1.prim_id == h2.prim_id && h1.u == h2.u && h1.v == h2.v;
  }
  CHECK(same == rays.size());
  TraversalCost c1, c2;
  for (const Ray& r : rays) {
    Hit h;
    a1->intersect_counted(r, h, c1);
    a2->intersect_counted(r, h, c2);
  }
  CHECK(c1.nodes == c2.nodes);
  CHECK(c1.triangles == c2.triangles);
  CHECK(c1.nodes > 0);
}

TEST_CASE("bsp: configuration is validated", "[accel][bsp][quick]") {
  BspConfig c;
  c.bins = 1;
  CHECK_THROWS_WITH(validate(c), "bsp: bins must be in [2, 64], got 1");
  c = {};
  c.bins = 65;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("bins") && Catch::Contains("65"));
  c = {};
  c.triangle_planes = 17;
  CHECK_THROWS_WITH(validate(c), "bsp: triangle_planes must be in [0, 16], got 17");
  c = {};
  c.triangle_planes = -1;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("triangle_planes") && Catch::Contains("-1"));
  c = {};
  c.max_depth = 65;
  CHECK_THROWS_WITH(validate(c), "bsp: max_depth must be in [0, 64], got 65");
  c = {};
  c.empty_bonus = 1;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("empty_bonus") && Catch::Contains("got 1"));
  c = {};
  c.traversal_cost = 0;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("traversal_cost") && Catch::Contains("got 0"));
  c = {};
  c.intersection_cost = std::nanf("");
  CHECK_THROWS_WITH(validate(c), Catch::Contains("intersection_cost"));
  CHECK_THROWS_AS(make_bsp_accelerator({}, c), std::invalid_argument);
  CHECK_NOTHROW(validate(BspConfig{}));
  c = {};
  c.bins = 2, c.triangle_planes = 0, c.max_depth = 64, c.empty_bonus = 0;
  CHECK_NOTHROW(validate(c));
}
