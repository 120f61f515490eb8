// Tests for renderer/accel/octree: the leaf-size, depth and no-progress rules, clipping of
// triangles to child boxes, analytic statistics, its configuration, the same build for 1 and 2
// threads, and exact agreement with brute force on edge cases (surfaces and rays on the mid
// planes, zero direction components, huge and tiny coordinates, flat scenes, shapes) under
// several settings.
#include "renderer/accel/octree.h"

#include <tbb/task_arena.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <random>

#include "support/cross_check.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

OctreeConfig octree_config(int max_leaf_prims, int max_depth) {
  OctreeConfig c;
  c.max_leaf_prims = max_leaf_prims;
  c.max_depth = max_depth;
  return c;
}

/// The settings the cross-checks run under: leaves of 1 to 32 primitives, depth 1 to 14. (With
/// leaves of 1 or 2, a mesh's shared edges are followed down to max_depth, 2^depth cells each.)
const std::vector<OctreeConfig>& configs() {
  static const std::vector<OctreeConfig> all{octree_config(1, 6),  octree_config(2, 6),
                                             octree_config(8, 10), octree_config(16, 14),
                                             octree_config(32, 1), octree_config(4, 3)};
  return all;
}

std::string describe(const OctreeConfig& c) {
  return "max_leaf_prims " + std::to_string(c.max_leaf_prims) + ", max_depth " + std::to_string(c.max_depth);
}

/// Checks octrees under `settings` against brute force over the rays of
/// all_rays(scale, seed) and `extra`: hit/miss and t exact; also that intersect_counted()
/// answers as intersect() does, and that the tree obeys its limits.
void check_against_brute(const std::string& what, std::span<const GeometryView> views, int scale,
                         uint32_t seed, const std::vector<Ray>& extra = {},
                         const std::vector<OctreeConfig>& settings = configs()) {
  const auto brute = make_accelerator("brute", views);
  const Bounds3f b = bounds_of(views);
  std::vector<Ray> rays = all_rays(*brute, views, b, lights_around(b), scale, seed);
  rays.insert(rays.end(), extra.begin(), extra.end());
  const Reference ref = reference(*brute, std::move(rays));
  for (const OctreeConfig& c : settings) {
    const auto oct = make_octree_accelerator(views, c);
    const auto r = cross_check(*oct, ref, views, length(b.extent()), true, 0.0f);
    INFO(summary(what + " (" + describe(c) + ")", r));
    CHECK(r.failures() == 0);
    CHECK(r.hits > 0);
    const AccelStats s = oct->stats();
    CHECK(s.max_depth <= uint64_t(c.max_depth));
    CHECK(s.triangles == brute->stats().triangles);
    CHECK(s.shapes == brute->stats().shapes);
    size_t counted = 0;
    for (size_t i = 0; i < ref.rays.size(); i += 7) {
      Hit h1, h2;
      TraversalCost cost;
      const bool a = oct->intersect(ref.rays[i], h1), bb = oct->intersect_counted(ref.rays[i], h2, cost);
      counted += a == bb && h1.t == h2.t && h1.prim_id == h2.prim_id && h1.geom_id == h2.geom_id &&
                 (!a || cost.nodes > 0);
    }
    CHECK(counted == (ref.rays.size() + 6) / 7);
  }
}

/// Rays starting on the plane axis = value at the points of a lattice over [lo, hi]^2: along
/// the axis both ways, inside the plane (a zero component along the axis), diagonally, and
/// from a tnear past the plane.
std::vector<Ray> rays_from_plane(int axis, float value, float lo, float hi, float step) {
  std::vector<Ray> rays;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  for (float u = lo; u <= hi; u += step)
    for (float v = lo; v <= hi; v += step) {
      Vec3f o;
      o[axis] = value;
      o[a1] = u;
      o[a2] = v;
      for (float sign : {1.0f, -1.0f}) {
        Vec3f d;
        d[axis] = sign;
        rays.push_back({o, 0, d, kInfinity});  // straight off the plane
        Vec3f in;
        in[a1] = sign;
        rays.push_back({o, 0, in, kInfinity});  // inside the plane
        in[a2] = 0.5f * sign;
        rays.push_back({o, 0, normalize(in), kInfinity});  // inside the plane, diagonally
        Vec3f diag = in;
        diag[axis] = 0.7f * sign;
        rays.push_back({o, 0, normalize(diag), kInfinity});  // leaving it at an angle
        rays.push_back({o, 0.05f, normalize(diag), kInfinity});
        Vec3f grazing = in;
        grazing[axis] = 1e-7f * sign;
        rays.push_back({o, 0, grazing, kInfinity});  // almost inside it
      }
    }
  return rays;
}

/// Random triangles of sizes from 0.01 to 3 in [0, 10]^3, in one view.
struct RandomSoup {
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  RandomSoup(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0, 1);
    for (int i = 0; i < n; ++i) {
      const Vec3f a{u(rng) * 10, u(rng) * 10, u(rng) * 10};
      const float size = 0.01f + 3 * u(rng) * u(rng) * u(rng);
      const uint32_t b = uint32_t(pos.size());
      pos.insert(pos.end(), {a, a + random_direction(rng) * size, a + random_direction(rng) * size});
      idx.insert(idx.end(), {b, b + 1, b + 2});
    }
  }
  GeometryView view() const { return {pos, idx}; }
};

/// A tiny triangle (0.2 wide) with its lower corner at `o`.
void add_tiny(std::vector<Vec3f>& pos, std::vector<uint32_t>& idx, Vec3f o) {
  const uint32_t b = uint32_t(pos.size());
  pos.insert(pos.end(), {o, o + Vec3f{0.2f, 0, 0}, o + Vec3f{0, 0.2f, 0.1f}});
  idx.insert(idx.end(), {b, b + 1, b + 2});
}

bool same_hit(const Hit& a, const Hit& b) {
  return a.valid() == b.valid() && (!a.valid() || (std::memcmp(&a, &b, sizeof(Hit)) == 0));
}

}  // namespace

TEST_CASE("octree: analytic statistics of a two-triangle tree", "[accel][octree][quick]") {
  // Two small triangles in opposite corners of the unit cube: one split separates them into
  // children 0 and 7; the six other children are empty leaves.
  const std::vector<Vec3f> pos{{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}, {1, 1, 1}, {0.9f, 1, 1}, {1, 0.9f, 1}};
  const std::vector<uint32_t> idx{0, 1, 2, 3, 4, 5};
  const GeometryView view{pos, idx};
  const auto oct = make_octree_accelerator(std::span(&view, 1), octree_config(1, 10));
  const AccelStats s = oct->stats();
  CHECK(s.name == "octree");
  CHECK(s.config == "max_leaf_prims 1, max_depth 10, reference_budget 4");
  CHECK(s.triangles == 2);
  CHECK(s.shapes == 0);
  CHECK(s.nodes == 9);
  CHECK(s.leaves == 8);
  CHECK(s.empty_leaves == 6);
  CHECK(s.references == 2);
  CHECK(s.max_leaf_prims == 1);
  CHECK(s.avg_leaf_prims == 1.0);
  CHECK(s.max_depth == 1);
  // Each child's area is a quarter of the root's: K_T + 2 x 1/4 x K_I with K_T = 15, K_I = 20.
  CHECK(s.sah_cost == Approx(15 + 2 * 0.25 * 20));
  CHECK(s.sah_node_area == Approx(1));
  CHECK(s.sah_leaf_area == Approx(0.5));
  CHECK(s.bytes == 9 * 8 + 2 * 44);
  CHECK(s.build_seconds >= 0);
  CHECK(make_octree_accelerator(std::span(&view, 1))->stats().config ==
        "max_leaf_prims 8, max_depth 10, reference_budget 4");
  // Two primitives fit a leaf of 2: the root is the only node.
  const AccelStats s2 = make_octree_accelerator(std::span(&view, 1), octree_config(2, 10))->stats();
  CHECK(s2.nodes == 1);
  CHECK(s2.leaves == 1);
  CHECK(s2.max_depth == 0);
  CHECK(s2.sah_cost == Approx(2 * 20));
  // Known answers.
  Hit h;
  REQUIRE(oct->intersect({{0.02f, 0.02f, 1}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK(h.t == 1);
  CHECK(h.prim_id == 0);
  REQUIRE(oct->intersect({{0.98f, 0.98f, 0}, 0, {0, 0, 1}, kInfinity}, h));
  CHECK(h.t == 1);
  CHECK(h.prim_id == 1);
  CHECK_FALSE(oct->intersect({{0.5f, 0.5f, 2}, 0, {0, 0, -1}, kInfinity}, h));
  CHECK_FALSE(oct->occluded({{0.02f, 0.02f, 1}, 0, {0, 0, -1}, 0.5f}));
  CHECK(oct->bounds().lo == Vec3f{0, 0, 0});
  CHECK(oct->bounds().hi == Vec3f{1, 1, 1});
}

TEST_CASE("octree: subdivision stops at max_leaf_prims, and the depth limit holds", "[accel][octree]") {
  // Tiny triangles in the cells of an 8 x 8 x 8 lattice, each well inside its cell: any leaf
  // size is reachable long before depth 10.
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) add_tiny(pos, idx, {x + 0.4f, y + 0.4f, z + 0.4f});
  const GeometryView view{pos, idx};
  for (int leaf : {1, 3, 8, 64}) {
    const AccelStats s = make_octree_accelerator(std::span(&view, 1), octree_config(leaf, 10))->stats();
    INFO("max_leaf_prims " << leaf << ": " << s.nodes << " nodes, depth " << s.max_depth);
    CHECK(s.max_leaf_prims <= uint64_t(leaf));
    CHECK(s.max_depth < 10);
    CHECK(s.references >= s.triangles);
    // Every interior node has eight children: nodes = 1 + 8 x interior nodes.
    CHECK((s.nodes - 1) % 8 == 0);
    CHECK(s.leaves == s.nodes - (s.nodes - 1) / 8);
    CHECK(s.bytes == s.nodes * 8 + s.references * 44);
  }
  // A tree cut off by the depth limit: leaves larger than max_leaf_prims, no node below it.
  for (int depth : {1, 2}) {
    const AccelStats s = make_octree_accelerator(std::span(&view, 1), octree_config(1, depth))->stats();
    INFO("max_depth " << depth);
    CHECK(s.max_depth == uint64_t(depth));
    CHECK(s.max_leaf_prims > 1);
    CHECK(s.nodes == (depth == 1 ? 9u : 73u));  // complete: every node below the limit splits
  }
}

TEST_CASE("octree: slivers spanning a box make no progress: a small tree, not 8^depth nodes",
          "[accel][octree]") {
  // Long thin triangles along the four diagonals of the cube [0, 4]^3: each passes through the
  // centre, which every child's box touches, so every child would hold every sliver.
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  const Vec3f corners[4][2] = {
      {{0, 0, 0}, {4, 4, 4}}, {{4, 0, 0}, {0, 4, 4}}, {{0, 4, 0}, {4, 0, 4}}, {{0, 0, 4}, {4, 4, 0}}};
  for (int i = 0; i < 40; ++i) {
    const Vec3f a = corners[i % 4][0], b = corners[i % 4][1];
    const float w = 0.01f * float(i / 4 + 1);
    Vec3f c = b;
    c[i % 3] += c[i % 3] > 0 ? -w : w;  // inside the cube
    const uint32_t base = uint32_t(pos.size());
    pos.insert(pos.end(), {a, b, c});
    idx.insert(idx.end(), {base, base + 1, base + 2});
  }
  const GeometryView view{pos, idx};
  const auto oct = make_octree_accelerator(std::span(&view, 1), octree_config(1, 20));
  const AccelStats s = oct->stats();
  CHECK(s.nodes == 1);
  CHECK(s.references == 40);
  check_against_brute("diagonal slivers", std::span(&view, 1), 1, 9);

  // Copies of one sliver along the edge y = z = 0.7 of the box [0, 4] x [0.7, 4]^2 (a tiny
  // triangle sets its far corner): each of the root's children 0 and 1 holds all of them, and
  // below each, the two children the line runs through hold them all again (and the others
  // none), so both are leaves. Subdividing until every child holds all would follow the line
  // down to max_depth.
  std::vector<Vec3f> line_pos{{3.8f, 3.8f, 3.9f}, {4, 3.8f, 4}, {3.8f, 4, 4}};
  std::vector<uint32_t> line_idx{0, 1, 2};
  for (int i = 0; i < 30; ++i) {
    const uint32_t base = uint32_t(line_pos.size());
    line_pos.insert(line_pos.end(), {{0, 0.7f, 0.7f}, {4, 0.7f, 0.7f}, {4, 0.72f, 0.7f}});
    line_idx.insert(line_idx.end(), {base, base + 1, base + 2});
  }
  const GeometryView line{line_pos, line_idx};
  const AccelStats s2 = make_octree_accelerator(std::span(&line, 1), octree_config(1, 20))->stats();
  CHECK(s2.nodes == 9);
  CHECK(s2.max_depth == 1);
  CHECK(s2.references == 61);
  std::vector<Ray> onto;  // down onto the slivers, 0.005 x wide at x
  for (float x = 0.25f; x < 4; x += 0.25f)
    onto.push_back({{x, 0.7f + 0.004f * x, 2}, 0, {0, 0, -1}, kInfinity});
  check_against_brute("slivers along a line", std::span(&line, 1), 1, 10, onto);
}

TEST_CASE("octree: the reference budget bounds the copies of crossing slivers", "[accel][octree]") {
  // Slivers in random directions across the box: each crosses many cells at every depth, and
  // partial overlaps let the no-progress rule subdivide on. The budget caps the references.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0, 10);
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int i = 0; i < 2000; ++i) {
    const Vec3f a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    idx.insert(idx.end(), {uint32_t(pos.size()), uint32_t(pos.size() + 1), uint32_t(pos.size() + 2)});
    pos.insert(pos.end(), {a, b, b + Vec3f{0.01f, 0, 0.01f}});
  }
  const GeometryView view{pos, idx};
  for (float budget : {0.0f, 1.0f, 4.0f}) {
    OctreeConfig c;
    c.reference_budget = budget;
    const AccelStats s = make_octree_accelerator(std::span(&view, 1), c)->stats();
    INFO("budget " << budget << ": " << s.references << " references");
    CHECK(double(s.references) <= (1 + double(budget)) * 2000 * 1.0001);
    if (budget == 0) CHECK(s.references == 2000);  // a split that copies anything is refused
  }
  OctreeConfig open;
  open.reference_budget = 64;
  const AccelStats wide = make_octree_accelerator(std::span(&view, 1), open)->stats();
  CHECK(wide.references > 5 * 2000);  // without the default budget the copies do multiply
  OctreeConfig tight;
  tight.reference_budget = 1;
  check_against_brute("crossing slivers, budget 1", std::span(&view, 1), 1, 12, {}, {tight});
}

TEST_CASE("octree: a long diagonal sliver is clipped to the children it crosses", "[accel][octree]") {
  // A sliver along the diagonal of [-4, 4]^3 among tiny triangles in the cells of an 8^3
  // lattice off the diagonal. Its bounding box is the whole scene: a box-overlap test would put
  // it in every leaf, which is what a box-shaped shape with the same bounds gets.
  std::vector<Vec3f> pos{{-4, -4, -4}, {4, 4, 4}, {4, 4, 3.9f}};
  std::vector<uint32_t> idx{0, 1, 2};
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x)
        if (x != y || y != z) add_tiny(pos, idx, {x - 3.9f, y - 3.9f, z - 3.9f});
  const uint64_t tiny = idx.size() / 3 - 1;
  const GeometryView sliver{pos, idx};
  const AccelStats clipped = make_octree_accelerator(std::span(&sliver, 1))->stats();

  const std::vector<uint32_t> tiny_idx(idx.begin() + 3, idx.end());
  const Shape box = analytic_shape(ShapeKind::Box, 1, {4, 4, 4});
  const std::vector<GeometryView> boxed{{pos, tiny_idx}, {{}, {}, &box}};
  const AccelStats overlap = make_octree_accelerator(boxed)->stats();
  CHECK(overlap.empty_leaves == 0);  // the box is in every leaf

  // No tiny triangle straddles a mid plane above depth 5 (planes at multiples of 1/2), so each
  // has one reference; the sliver crosses the root's children 0 and 7 at least.
  REQUIRE(clipped.max_depth < 5);
  const uint64_t sliver_refs = clipped.references - tiny;
  INFO("sliver in " << sliver_refs << " leaves; the box in " << overlap.leaves << " leaves");
  CHECK(sliver_refs >= 2);
  CHECK(sliver_refs * 4 < overlap.leaves);
  check_against_brute("sliver among tiny triangles", std::span(&sliver, 1), 1, 5);
}

TEST_CASE("octree: an icosphere and a random soup answer like brute force", "[accel][octree]") {
  const Soup sphere = icosphere(3, 2.0f, {5, 5, 5});
  const RandomSoup soup(600, 17);
  std::vector<GeometryView> views = sphere.views();
  views.push_back(soup.view());
  check_against_brute("icosphere and soup", views, 1, 3);

  // Filtered queries: odd triangles rejected, as brute force rejects them (the same t).
  const HitFilter even{[](const void*, const Ray&, const Hit& h) { return h.prim_id % 2 == 0; }, nullptr};
  const auto brute = make_accelerator("brute", views);
  const auto oct = make_octree_accelerator(views);
  std::mt19937 rng(4);
  const std::vector<Ray> rays = random_rays(bounds_of(views), 2000, rng);
  size_t same = 0, hits = 0;
  for (const Ray& r : rays) {
    Hit ha, hb;
    const bool a = oct->intersect(r, ha, even), b = brute->intersect(r, hb, even);
    hits += b;
    same += a == b && (!a || (ha.t == hb.t && ha.prim_id % 2 == 0)) && oct->occluded(r, even) == b;
  }
  CHECK(hits > 0);
  CHECK(same == rays.size());
}

TEST_CASE("octree: walls on the mid planes, rays along, through and starting on them", "[accel][octree]") {
  // A 4^3 lattice of cubes over [0, 4]^3: its walls lie on the mid planes of the root (2) and
  // of the nodes below it (1, 3, then 0.5, 1.5, ...).
  Soup s;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i <= 4; ++i) s.add_plane(axis, float(i), 0.0f, 4.0f, 4);
  std::vector<Ray> extra = lattice_rays(0.0f, 4.0f, 0.25f);
  for (int axis = 0; axis < 3; ++axis)
    for (float v : {2.0f, 1.0f, 3.0f, 0.5f, 1.25f})
      for (const Ray& r : rays_from_plane(axis, v, 0.0f, 4.0f, v == 2 ? 0.5f : 1.0f)) extra.push_back(r);
  // Rays with one or two zero direction components, off and on the planes.
  for (float a : {0.0f, 0.75f, 1.0f, 2.0f, 2.6f, 4.0f})
    for (float b : {0.3f, 2.0f, 3.0f}) {
      extra.push_back({{a, b, 1.7f}, 0, normalize(Vec3f{1, 1, 0}), kInfinity});
      extra.push_back({{a, b, 1.7f}, 0, normalize(Vec3f{0, -1, 1}), kInfinity});
      extra.push_back({{a, 1.7f, b}, 0, {0, 0, -1}, kInfinity});
      extra.push_back({{-1, a, b}, 0, normalize(Vec3f{1, 0, 1e-3f}), kInfinity});
    }
  // Rays starting one float outside the box's faces, running along them (the scene box must be
  // widened by the rounding band for these).
  for (int axis = 0; axis < 3; ++axis)
    for (float face : {0.0f, 4.0f})
      for (float a = 0; a <= 4; a += 0.5f)
        for (float b = 0.25f; b <= 4; b += 0.5f) {
          Vec3f o;
          o[axis] = std::nextafter(face, face > 0 ? kInfinity : -kInfinity);
          o[(axis + 1) % 3] = a;
          o[(axis + 2) % 3] = b;
          Vec3f along;
          along[(axis + 2) % 3] = 1;
          extra.push_back({o, 0, along, kInfinity});
          for (float in : {1e-7f, 0.8f}) {  // crossing the face at once, at a shallow or steep angle
            Vec3f inward;
            inward[(axis + 1) % 3] = 0.5f;
            inward[axis] = face > 0 ? -in : in;
            extra.push_back({o, 0, normalize(inward), kInfinity});
          }
          if (a != 0 && a != 4) continue;
          // From an edge of the box, leaving through the face o lies on while crossing the other.
          Vec3f corner;
          corner[axis] = face > 0 ? -0.8f : 0.8f;
          corner[(axis + 1) % 3] = a > 0 ? 1e-7f : -1e-7f;
          corner[(axis + 2) % 3] = 0.3f;
          extra.push_back({o, 0, normalize(corner), kInfinity});
        }
  const auto views = s.views();
  check_against_brute("walls on mid planes", views, 1, 11, extra);
}

TEST_CASE("octree: huge and tiny coordinates", "[accel][octree]") {
  struct Variant {
    float scale;
    Vec3f offset;
  };
  for (const Variant& v :
       {Variant{1e-6f, {0, 0, 0}}, Variant{1e-6f, {1e-6f, 2e-6f, 0}}, Variant{1, {1e3f, -1e3f, 1e3f}},
        Variant{1, {1e6f, 0, 1e6f}}, Variant{1e6f, {1e6f, 1e6f, 1e6f}}, Variant{1e12f, {0, 0, 0}},
        Variant{1e-9f, {1e-9f, 0, 0}}}) {
    const Soup s = icosphere(2, v.scale, v.offset);
    char name[96];
    std::snprintf(name, sizeof name, "sphere scale %g offset (%g, %g, %g)", v.scale, v.offset.x, v.offset.y,
                  v.offset.z);
    const auto views = s.views();
    check_against_brute(name, views, 1, 21, {},
                        {octree_config(1, 5), octree_config(8, 10), octree_config(16, 14)});
  }
}

TEST_CASE("octree: a flat scene, rays in its plane and starting on it", "[accel][octree]") {
  // A tessellated plane y = 0 and small triangles lying in it: the y axis is never split.
  Soup s;
  s.add_plane(1, 0.0f, -4.0f, 4.0f, 8);
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx;
  for (int i = 0; i < 50; ++i) {
    const float x = -4 + 0.16f * float(i), z = -3.9f + 0.15f * float(i % 7);
    const uint32_t b = uint32_t(pos.size());
    pos.insert(pos.end(), {{x, 0, z}, {x + 0.1f, 0, z}, {x, 0, z + 0.1f}});
    idx.insert(idx.end(), {b, b + 1, b + 2});
  }
  s.add(std::move(pos), std::move(idx));
  std::vector<Ray> extra = rays_from_plane(1, 0.0f, -4.0f, 4.0f, 0.5f);
  for (float z = -4; z <= 4; z += 0.5f) {
    extra.push_back({{-5, 0, z}, 0, {1, 0, 0}, kInfinity});  // in the plane
    extra.push_back({{z, 1, 0.3f}, 0, {0, -1, 0}, kInfinity});
  }
  const auto views = s.views();
  // The y axis is never split: four of each interior node's children are empty leaves.
  const AccelStats st = make_octree_accelerator(views)->stats();
  CHECK(st.nodes > 1);
  CHECK(st.empty_leaves >= (st.nodes - 1) / 2);
  check_against_brute("flat scene", views, 1, 13, extra);
}

TEST_CASE("octree: shapes are referenced by their boxes and answer like brute force", "[accel][octree]") {
  Soup s = icosphere(2, 0.8f, {0, 0, 3});
  s.add_plane(1, -1.5f, -5.0f, 5.0f, 6);
  const std::vector<Shape> shapes{
      analytic_shape(ShapeKind::Sphere, 0.5f), analytic_shape(ShapeKind::Box, 1, {1, 0.3f, 0.7f}),
      analytic_shape(ShapeKind::Capsule, 0.25f, {}, 1.2f), analytic_shape(ShapeKind::Disk, 1.5f)};
  std::vector<GeometryView> views = s.views();
  for (const Shape& sh : shapes) views.push_back({{}, {}, &sh});
  std::vector<Ray> extra;
  for (float x : {-0.6f, 0.0f, 0.6f})
    for (float y : {-0.3f, 0.0f, 0.3f}) {
      extra.push_back({{x, y, -6}, 0, {0, 0, 1}, kInfinity});
      extra.push_back({{x, 6, y}, 0, {0, -1, 0}, kInfinity});
    }
  extra.push_back({{-6, 0, 0}, 0, {1, 0, 0}, kInfinity});  // in the disk's plane
  const auto oct = make_octree_accelerator(views);
  CHECK(oct->stats().shapes == 4);
  check_against_brute("shapes", views, 1, 23, extra);
}

TEST_CASE("octree: empty scenes have empty bounds and miss", "[accel][octree][quick]") {
  const std::vector<Vec3f> nan_pos{{std::nanf(""), 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2};
  const std::vector<GeometryView> nothing;
  const std::vector<GeometryView> dropped{{nan_pos, idx}, {{}, {}}};
  for (const auto& views : {nothing, dropped}) {
    const auto oct = make_octree_accelerator(views);
    CHECK(oct->bounds().empty());
    Hit h;
    CHECK_FALSE(oct->intersect({{0, 0, -1}, 0, {0, 0, 1}, kInfinity}, h));
    CHECK_FALSE(h.valid());
    CHECK_FALSE(oct->occluded({{0, 0, -1}, 0, {0, 0, 1}, kInfinity}));
    const AccelStats s = oct->stats();
    CHECK(s.nodes == 0);
    CHECK(s.references == 0);
    CHECK(s.bytes == 0);
  }
}

TEST_CASE("octree: the same tree and answers for 1 and 2 threads", "[accel][octree]") {
  const Soup sphere = icosphere(3, 2.0f, {5, 5, 5});
  const RandomSoup soup(3000, 29);
  std::vector<GeometryView> views = sphere.views();
  views.push_back(soup.view());
  OctreeConfig c;
  c.max_leaf_prims = 2;
  c.parallel_threshold = 16;
  std::unique_ptr<Accelerator> a1, a2;
  tbb::task_arena(1).execute([&] { a1 = make_octree_accelerator(views, c); });
  tbb::task_arena(2).execute([&] { a2 = make_octree_accelerator(views, c); });
  const AccelStats s1 = a1->stats(), s2 = a2->stats();
  CHECK(s1.nodes == s2.nodes);
  CHECK(s1.leaves == s2.leaves);
  CHECK(s1.empty_leaves == s2.empty_leaves);
  CHECK(s1.references == s2.references);
  CHECK(s1.max_leaf_prims == s2.max_leaf_prims);
  CHECK(s1.max_depth == s2.max_depth);
  CHECK(s1.sah_cost == s2.sah_cost);
  CHECK(s1.bytes == s2.bytes);
  const Bounds3f b = bounds_of(views);
  std::mt19937 rng(31);
  const std::vector<Ray> rays = random_rays(b, 3000, rng);
  size_t same = 0;
  for (const Ray& r : rays) {
    Hit h1, h2;
    a1->intersect(r, h1);
    a2->intersect(r, h2);
    same += same_hit(h1, h2) && a1->occluded(r) == a2->occluded(r);
  }
  CHECK(same == rays.size());
}

TEST_CASE("octree: configuration is validated", "[accel][octree][quick]") {
  OctreeConfig c;
  c.max_leaf_prims = 0;
  CHECK_THROWS_WITH(validate(c), "octree: max_leaf_prims must be in [1, 1024], got 0");
  c.max_leaf_prims = 1025;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_leaf_prims") && Catch::Contains("1025"));
  OctreeConfig b;
  b.reference_budget = -1;
  CHECK_THROWS_WITH(validate(b), Catch::Contains("octree: reference_budget must be in [0, 64], got -1"));
  c = {};
  c.max_depth = 0;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_depth") && Catch::Contains("got 0"));
  c.max_depth = 21;
  CHECK_THROWS_WITH(validate(c), Catch::Contains("max_depth") && Catch::Contains("21"));
  CHECK_THROWS_AS(make_octree_accelerator({}, c), std::invalid_argument);
  for (auto [leaf, depth] : {std::pair{1, 1}, std::pair{1024, 20}, std::pair{8, 10}})
    CHECK_NOTHROW(validate(octree_config(leaf, depth)));
}
