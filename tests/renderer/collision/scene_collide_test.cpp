// Tests for renderer/collision/scene_collide: sweep and prune against every pair of random
// boxes; the hierarchy test on chains and cycles; a scene of two overlapping cubes and a third
// apart, with meshes and with proxies (the penetration depth of boxes in closed form).
#include "renderer/collision/scene_collide.h"

#include <catch2/catch.hpp>
#include <random>

#include "renderer/collision/scene_proxies.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

Affine3f moved(float x, float y, float z) {
  Affine3f a;
  a.m[0][3] = x, a.m[1][3] = y, a.m[2][3] = z;
  return a;
}

// A rotation (unit quaternion from 4 normal deviates) and a move.
Affine3f rotated_moved(std::mt19937_64& rng, float x, float y, float z) {
  std::normal_distribution<double> n;
  double w = n(rng), i = n(rng), j = n(rng), k = n(rng);
  const double l = std::sqrt(w * w + i * i + j * j + k * k);
  w /= l, i /= l, j /= l, k /= l;
  const double r[3][3] = {{1 - 2 * (j * j + k * k), 2 * (i * j - w * k), 2 * (i * k + w * j)},
                          {2 * (i * j + w * k), 1 - 2 * (i * i + k * k), 2 * (j * k - w * i)},
                          {2 * (i * k - w * j), 2 * (j * k + w * i), 1 - 2 * (i * i + j * j)}};
  Affine3f a = moved(x, y, z);
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) a.m[row][col] = float(r[row][col]);
  return a;
}

}  // namespace

TEST_CASE("sweep and prune finds every overlapping pair of boxes", "[collide]") {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<float> u(-10, 10), s(0, 1.5f);
  std::vector<Bounds3f> boxes;
  for (int i = 0; i < 600; ++i) {
    const Vec3f c{u(rng), u(rng), u(rng)}, h{s(rng), s(rng), s(rng)};
    boxes.push_back({c - h, c + h});
  }
  boxes.push_back(boxes[3]);  // an exact copy, and a box touching another at a face
  boxes.push_back({{boxes[5].hi.x, boxes[5].lo.y, boxes[5].lo.z}, boxes[5].hi + Vec3f{1, 0, 0}});
  std::vector<std::pair<uint32_t, uint32_t>> want;
  for (uint32_t i = 0; i < boxes.size(); ++i)
    for (uint32_t j = i + 1; j < boxes.size(); ++j) {
      const Bounds3f &a = boxes[i], &b = boxes[j];
      if (a.lo.x <= b.hi.x && b.lo.x <= a.hi.x && a.lo.y <= b.hi.y && b.lo.y <= a.hi.y && a.lo.z <= b.hi.z &&
          b.lo.z <= a.hi.z)
        want.push_back({i, j});
    }
  CHECK(sweep_and_prune(boxes) == want);
  CHECK(want.size() > 50);
}

TEST_CASE("node_in_subtree follows parents and ends on cycles", "[collide]") {
  const std::vector<int> chain{-1, 0, 1, 2};
  CHECK(node_in_subtree(3, 0, chain));
  CHECK(node_in_subtree(2, 2, chain));
  CHECK_FALSE(node_in_subtree(0, 3, chain));
  const std::vector<int> cycle{1, 0};  // malformed: each the other's parent
  CHECK_FALSE(node_in_subtree(0, 5, cycle));
}

TEST_CASE("collide_scene: two overlapping cubes, a third apart, a child", "[collide]") {
  Scene s;
  s.meshes.push_back(cube_mesh(0.5f));
  s.instances.push_back(make_instance(0, moved(0, 0, 0), 0));
  s.instances.push_back(make_instance(0, moved(0.75f, 0.1f, 0), 1));
  s.instances.push_back(make_instance(0, moved(5, 0, 0), 2));
  s.instances.push_back(make_instance(0, moved(0, 0.3f, 0), 3));  // node 3 is node 0's child
  const std::vector<int> parents{-1, -1, -1, 0};
  CollideConfig mesh;
  const CollideReport r = collide_scene(s, {parents}, mesh);
  CHECK(r.nodes == 4);
  CHECK(r.broad_pairs == 3);  // (0, 1), (0, 3), (1, 3)
  CHECK(r.family_pairs == 1);
  REQUIRE(r.contacts.size() == 2);
  CHECK((r.contacts[0].a == 0 && r.contacts[0].b == 1));
  CHECK((r.contacts[1].a == 1 && r.contacts[1].b == 3));
  for (const NodeContact& c : r.contacts) {
    // Closed cubes: the deepest surface point inside the other lies 0.25 deep (the x overlap,
    // which is also the distance that separates them).
    CHECK(c.depth <= 0.25 + 1e-6);
    CHECK(c.depth >= 0.25 - c.depth_error);
    CHECK(c.depth_error <= 1.5 / 64 * (1 + 1e-6));  // the overlap box's largest side / 64, grown once
    CHECK(c.triangle_pairs > 0);
    CHECK(c.point.x >= 0.25 - 1e-6);  // in cube 1, which spans x in [0.25, 1.25]
    CHECK(c.point.x <= 0.5 + 1e-6);   // and in cubes 0 and 3
  }
  mesh.include_children = true;
  CHECK(collide_scene(s, {parents}, mesh).contacts.size() == 3);

  CollideConfig boxes;
  boxes.mesh = false;
  boxes.kind = ProxyKind::Aabb;
  const CollideReport b = collide_scene(s, {parents}, boxes);
  REQUIRE(b.contacts.size() == 2);
  CHECK(b.contacts[0].depth == Approx(0.25).epsilon(1e-6));  // x overlap 0.25 < y overlap 0.9
  CHECK(b.contacts[1].depth == Approx(0.25).epsilon(1e-6));  // x 0.25, y 0.8
}

TEST_CASE("nodes_joined: the hierarchy and skins", "[collide]") {
  // 0 body (skinned to joints 1 and 2), 1 root bone -> 2 hand bone -> 3 sword; 4 cloth
  // (skinned to joint 2), 5 a prop, 6 a second character skinned to its own bone 7.
  const std::vector<int> parents{-1, -1, 1, 2, -1, -1, -1, -1};
  const std::vector<std::vector<int>> skins{{1, 2}, {}, {}, {}, {2}, {}, {7}, {}};
  const NodeLinks links{parents, skins};
  CHECK(nodes_joined(0, 3, links));  // the sword below the hand bone
  CHECK(nodes_joined(3, 0, links));
  CHECK(nodes_joined(0, 1, links));  // a joint itself
  CHECK(nodes_joined(0, 4, links));  // skins sharing joint 2
  CHECK(nodes_joined(4, 3, links));  // the cloth's joint carries the sword too
  CHECK(nodes_joined(1, 3, links));  // the hierarchy
  CHECK_FALSE(nodes_joined(0, 5, links));
  CHECK_FALSE(nodes_joined(0, 6, links));
  CHECK_FALSE(nodes_joined(3, 6, links));
  CHECK_FALSE(nodes_joined(0, 3, NodeLinks{parents, {}}));  // without the skins
}

TEST_CASE("collide_scene: a skinned node and a node its joint carries are left out", "[collide]") {
  Scene s;
  s.meshes.push_back(cube_mesh(0.5f));
  s.instances.push_back(make_instance(0, moved(0, 0, 0), 0));     // the skinned body
  s.instances.push_back(make_instance(0, moved(0.8f, 0, 0), 2));  // the sword below bone 1
  const std::vector<int> parents{-1, -1, 1};
  const std::vector<std::vector<int>> skins{{1}, {}, {}};
  const CollideReport r = collide_scene(s, {parents, skins}, CollideConfig{});
  CHECK(r.broad_pairs == 1);
  CHECK(r.family_pairs == 1);
  CHECK(r.contacts.empty());
  CHECK(collide_scene(s, {parents}, CollideConfig{}).contacts.size() == 1);
  CollideConfig all;
  all.include_children = true;
  CHECK(collide_scene(s, {parents, skins}, all).contacts.size() == 1);
}

TEST_CASE("collide_scene: meshes' depth of a box sunk into a floor and of a box inside another",
          "[collide]") {
  Scene s;
  s.meshes.push_back(cube_mesh(0.5f));
  // The floor: a 10 x 1 x 10 slab whose top is y = 0.
  Affine3f floor = moved(0, -0.5f, 0);
  floor.m[0][0] = 10, floor.m[1][1] = 1, floor.m[2][2] = 10;
  s.instances.push_back(make_instance(0, floor, 0));
  // A unit cube turned 30 degrees about z, its lowest edge 0.1 below the floor's top: the
  // deepest point is that edge, 0.1 deep, and lifting the cube 0.1 separates them.
  Affine3f tilted;
  const float c = std::cos(0.5235987756f), sn = std::sin(0.5235987756f);
  tilted.m[0][0] = c, tilted.m[0][1] = -sn, tilted.m[1][0] = sn, tilted.m[1][1] = c;
  tilted.m[1][3] = 0.5f * (c + sn) - 0.1f;
  s.instances.push_back(make_instance(0, tilted, 1));
  // A cube of side 0.4 centred at (0.3, 0, 0) inside a cube of side 2 at (0, 0, 10): no surface
  // meets, the small one's face x = 0.1 (relative) lies 0.9 deep at its centre.
  Affine3f big = moved(0, 0, 10), small = moved(0.3f, 0, 10);
  big.m[0][0] = big.m[1][1] = big.m[2][2] = 2;
  small.m[0][0] = small.m[1][1] = small.m[2][2] = 0.4f;
  s.instances.push_back(make_instance(0, big, 2));
  s.instances.push_back(make_instance(0, small, 3));
  const std::vector<int> parents{-1, -1, -1, -1};
  const CollideReport r = collide_scene(s, {parents}, CollideConfig{});
  REQUIRE(r.contacts.size() == 2);
  const NodeContact& sunk = r.contacts[0];
  CHECK((sunk.a == 0 && sunk.b == 1));
  CHECK(sunk.depth == Approx(0.1).margin(1e-5));  // a vertex is a sample: exact to rounding
  CHECK(sunk.direction.y == Approx(1).margin(1e-4));
  CHECK(sunk.depth_error <= 0.05);
  const NodeContact& held = r.contacts[1];
  CHECK((held.a == 2 && held.b == 3));
  CHECK(held.triangle_pairs == 0);
  CHECK(held.depth <= 0.9 + 1e-5);
  CHECK(held.depth >= 0.9 - held.depth_error);
  CHECK(held.depth_error <= 0.02);
  CHECK(held.point.z >= 9.8 - 1e-5);  // a point of the small cube
  CHECK(held.point.z <= 10.2 + 1e-5);
  CHECK(std::abs(held.point.x - 0.3) <= 0.2 + 1e-5);
  // Moving the small cube by depth along direction takes its deepest point to the surface.
  CHECK(held.direction.x == Approx(1).margin(1e-4));  // toward the big one's nearer face, x = 1
  // Proxies agree on the sunk box (a box's hull is exact).
  CollideConfig hulls;
  hulls.mesh = false;
  const CollideReport h = collide_scene(s, {parents}, hulls);
  REQUIRE(h.contacts.size() == 2);
  CHECK(h.contacts[0].depth == Approx(0.1).margin(1e-5));
}

TEST_CASE("collide_scene: meshes' depth is at most the convex penetration depth", "[collide]") {
  // For two convex solids the translation that separates them (GJK/EPA on the hulls) moves
  // every point of one out of the other, so no surface point lies deeper than it; where a
  // vertex goes deepest they are equal.
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<float> u(-0.7f, 0.7f);
  Scene s;
  s.meshes.push_back(cube_mesh(0.5f));
  const std::vector<int> parents{-1, -1};
  int compared = 0, equal = 0;
  for (int trial = 0; trial < 40; ++trial) {
    s.instances.clear();
    s.instances.push_back(make_instance(0, rotated_moved(rng, 0, 0, 0), 0));
    s.instances.push_back(make_instance(0, rotated_moved(rng, u(rng), u(rng), u(rng)), 1));
    CollideConfig meshes;
    meshes.depth_samples = 1 << 14;
    const CollideReport m = collide_scene(s, {parents}, meshes);
    CollideConfig hulls;
    hulls.mesh = false;
    const CollideReport h = collide_scene(s, {parents}, hulls);
    if (m.contacts.empty() || h.contacts.empty()) {
      CHECK(m.contacts.size() == h.contacts.size());
      continue;
    }
    ++compared;
    const double mesh_depth = m.contacts[0].depth, convex = h.contacts[0].depth;
    CHECK(mesh_depth <= convex + 1e-5);
    CHECK(mesh_depth >= 0);
    if (mesh_depth >= convex - m.contacts[0].depth_error - 1e-5) ++equal;
  }
  CHECK(compared >= 30);
  CHECK(equal >= 1);
}

TEST_CASE("collide_scene: meshes' depth far from the origin and over many triangles", "[collide]") {
  // The two overlapping cubes of the first case, 10^5 away from the origin: the outward
  // orientation and the depth do not depend on where they are.
  Scene far;
  far.meshes.push_back(cube_mesh(0.5f));
  far.instances.push_back(make_instance(0, moved(1e5f, 1e5f, 0), 0));
  far.instances.push_back(make_instance(0, moved(1e5f + 0.75f, 1e5f + 0.1f, 0), 1));
  const std::vector<int> parents{-1, -1};
  const CollideReport r = collide_scene(far, {parents}, CollideConfig{});
  REQUIRE(r.contacts.size() == 1);
  CHECK(r.contacts[0].depth <= 0.25 + 1e-6);
  CHECK(r.contacts[0].depth >= 0.25 - r.contacts[0].depth_error);
  CHECK(r.contacts[0].depth_error <= 0.03);

  // Two spheres of 20480 triangles each (radius 1, centres 1.5 apart) with a budget of 1000
  // samples: more triangles meet the common box than the budget holds, so their corners are the
  // samples, and the spacing is their longest edge.
  Scene balls;
  Shape sphere;
  sphere.kind = ShapeKind::Sphere, sphere.radius = 1;
  balls.shapes.push_back({"a", sphere, -1, 0});
  balls.shapes.push_back({"b", sphere, -1, 1});
  balls.instances.push_back(make_shape_instance(0, moved(0, 0, 0), 0));
  balls.instances.push_back(make_shape_instance(1, moved(1.5f, 0, 0), 1));
  CollideConfig small;
  small.depth_samples = 1000;
  small.shapes.subdivisions = 5;
  const CollideReport b = collide_scene(balls, {parents}, small);
  REQUIRE(b.contacts.size() == 1);
  const NodeContact& c = b.contacts[0];
  CHECK(c.shape_error > 0);
  CHECK(c.depth <= 0.5 + c.shape_error);
  CHECK(c.depth >= 0.5 - c.depth_error - c.shape_error);
  CHECK(c.depth_error < 0.1);  // an icosphere edge of 20480 faces: about 0.04
  // No depth asked: the contact is still found, without one.
  small.depth_samples = 0;
  const CollideReport none = collide_scene(balls, {parents}, small);
  REQUIRE(none.contacts.size() == 1);
  CHECK(std::isnan(none.contacts[0].depth));
}
