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
  const CollideReport r = collide_scene(s, parents, mesh);
  CHECK(r.nodes == 4);
  CHECK(r.broad_pairs == 3);  // (0, 1), (0, 3), (1, 3)
  CHECK(r.family_pairs == 1);
  REQUIRE(r.contacts.size() == 2);
  CHECK((r.contacts[0].a == 0 && r.contacts[0].b == 1));
  CHECK((r.contacts[1].a == 1 && r.contacts[1].b == 3));
  for (const NodeContact& c : r.contacts) {
    CHECK(std::isnan(c.depth));
    CHECK(c.triangle_pairs > 0);
    CHECK(c.point.x >= 0.25 - 1e-6);  // in cube 1, which spans x in [0.25, 1.25]
    CHECK(c.point.x <= 0.5 + 1e-6);   // and in cubes 0 and 3
  }
  mesh.include_children = true;
  CHECK(collide_scene(s, parents, mesh).contacts.size() == 3);

  CollideConfig boxes;
  boxes.mesh = false;
  boxes.kind = ProxyKind::Aabb;
  const CollideReport b = collide_scene(s, parents, boxes);
  REQUIRE(b.contacts.size() == 2);
  CHECK(b.contacts[0].depth == Approx(0.25).epsilon(1e-6));  // x overlap 0.25 < y overlap 0.9
  CHECK(b.contacts[1].depth == Approx(0.25).epsilon(1e-6));  // x 0.25, y 0.8
}
