// Tests for renderer/collision/shared_volume: the lens of two balls against the equal-radii closed
// form; clipped boxes and a square turned 45 degrees (the octagon) in closed form; the cell
// quadrature's bound holds the closed forms of a half ball and a half capsule; two closed meshes
// (icospheres, and concave star polyhedra, both star-shaped about their centres) against an
// exact oracle that sums the clipped volumes of every pair of their centre-to-face tetrahedra;
// and collide_scene's volumes on overlapping cubes, with an open mesh refused by name.
#include "renderer/collision/shared_volume.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "renderer/collision/scene_collide.h"
#include "support/scene_builder.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr double kPiD = std::numbers::pi;

Proxy box_proxy(DVec3 c, DVec3 half, double turn_z = 0) {
  Proxy p;
  p.kind = ProxyKind::Obb;
  p.box.center = c;
  p.box.half = half;
  p.box.axis[0] = {std::cos(turn_z), std::sin(turn_z), 0};
  p.box.axis[1] = {-std::sin(turn_z), std::cos(turn_z), 0};
  p.box.axis[2] = {0, 0, 1};
  return p;
}

// The planes (outward unit normals) of tetrahedron (o, a, b, c) with abc counter-clockwise
// seen from outside the star (o inside).
std::vector<DPlane> tetrahedron(DVec3 o, DVec3 a, DVec3 b, DVec3 c) {
  std::vector<DPlane> out;
  auto plane = [&](DVec3 p, DVec3 q, DVec3 r, DVec3 inside) {
    DVec3 n = cross(q - p, r - p);
    n = n * (1 / std::sqrt(dot(n, n)));
    double d = dot(n, p);
    if (dot(n, inside) > d) n = n * -1, d = -d;
    out.push_back({n, d});
  };
  const DVec3 centre = (o + a + b + c) * 0.25;
  plane(a, b, c, centre);
  plane(o, a, b, centre);
  plane(o, b, c, centre);
  plane(o, c, a, centre);
  return out;
}

// The volume two meshes star-shaped about their centres share: every pair of centre-to-face
// tetrahedra clipped against each other (the tetrahedra of one mesh do not overlap).
double star_oracle(const TriMesh& a, DVec3 ca, const TriMesh& b, DVec3 cb) {
  auto tets = [](const TriMesh& m, DVec3 c) {
    std::vector<std::vector<DPlane>> out;
    for (size_t t = 0; t < m.indices.size(); t += 3)
      out.push_back(tetrahedron(c, to_dvec(m.positions[m.indices[t]]), to_dvec(m.positions[m.indices[t + 1]]),
                                to_dvec(m.positions[m.indices[t + 2]])));
    return out;
  };
  const auto ta = tets(a, ca), tb = tets(b, cb);
  Bounds3f box;
  for (const TriMesh* m : {&a, &b})
    for (const Vec3f& p : m->positions) box = merge(box, p);
  box.lo = box.lo - Vec3f{1, 1, 1}, box.hi = box.hi + Vec3f{1, 1, 1};
  double v = 0;
  for (const auto& x : ta)
    for (const auto& y : tb) v += convex_intersection_volume(x, y, box);
  return v;
}

TriMesh moved(TriMesh m, Vec3f by, float scale = 1) {
  for (Vec3f& p : m.positions) p = p * scale + by;
  return m;
}

}  // namespace

TEST_CASE("ball_intersection_volume: the lens in closed form", "[shared-volume]") {
  const BoundingSphere a{{0, 0, 0}, 1};
  CHECK(ball_intersection_volume(a, {{3, 0, 0}, 1}) == 0);
  CHECK(ball_intersection_volume(a, {{0.2, 0, 0}, 0.5}) == Approx(4.0 / 3 * kPiD * 0.125));
  for (double d : {0.1, 0.7, 1.3, 1.9}) {
    // Equal radii r at distance d: pi (4r + d)(2r - d)^2 / 12.
    const double want = kPiD * (4 + d) * (2 - d) * (2 - d) / 12;
    CHECK(ball_intersection_volume(a, {{0, d, 0}, 1}) == Approx(want).epsilon(1e-12));
  }
}

TEST_CASE("convex pairs: boxes and the octagon of a turned square, exactly", "[shared-volume]") {
  const Proxy a = box_proxy({0, 0, 0}, {0.5, 0.5, 0.5});
  const VolumeEstimate shifted = proxy_intersection_volume(a, box_proxy({0.3, 0.2, 0.1}, {0.5, 0.5, 0.5}));
  CHECK(shifted.exact);
  CHECK(shifted.volume == Approx(0.7 * 0.8 * 0.9).epsilon(1e-12));
  // A unit square and the same square turned 45 degrees share a regular octagon of area
  // 2 (sqrt 2 - 1); the height is 1.
  const VolumeEstimate octagon =
      proxy_intersection_volume(a, box_proxy({0, 0, 0}, {0.5, 0.5, 0.5}, kPiD / 4));
  CHECK(octagon.volume == Approx(2 * (std::sqrt(2.0) - 1)).epsilon(1e-12));
  CHECK(proxy_intersection_volume(a, box_proxy({2, 0, 0}, {0.5, 0.5, 0.5})).volume == 0);
  // Hulls of the same boxes: the same answers.
  std::vector<DVec3> pa, pb;
  for (int i = 0; i < 8; ++i) {
    pa.push_back({i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5});
    pb.push_back(pa.back() + DVec3{0.3, 0.2, 0.1});
  }
  const VolumeEstimate hulls =
      proxy_intersection_volume(fit_proxy(ProxyKind::Hull, pa), fit_proxy(ProxyKind::Hull, pb));
  CHECK(hulls.exact);
  CHECK(hulls.volume == Approx(0.7 * 0.8 * 0.9).epsilon(1e-9));
}

TEST_CASE("a composite whose parts overlap is measured as their union", "[shared-volume]") {
  // Parts [0, 1]^3 and [0.5, 1.5] x [0, 1]^2: the union is [0, 1.5] x [0, 1]^2; a box over
  // x in [0.25, 1.25] shares 1 with it (summing the parts would give 1.5).
  auto cube = [](double x0, double x1) {
    std::vector<DVec3> p;
    for (int i = 0; i < 8; ++i) p.push_back({i & 1 ? x1 : x0, i & 2 ? 1.0 : 0.0, i & 4 ? 1.0 : 0.0});
    return fit_proxy(ProxyKind::Hull, p).parts[0];
  };
  Proxy composite;
  composite.kind = ProxyKind::Composite;
  composite.parts = {cube(0, 1), cube(0.5, 1.5)};
  const VolumeEstimate v = proxy_intersection_volume(composite, box_proxy({0.75, 0.5, 0.5}, {0.5, 0.5, 0.5}));
  CHECK_FALSE(v.exact);
  CHECK(std::abs(v.volume - 1) <= v.error);
  CHECK(v.error < 0.05);
  // Parts that only touch: exact.
  composite.parts = {cube(0, 1), cube(1, 2)};
  const VolumeEstimate w = proxy_intersection_volume(composite, box_proxy({1, 0.5, 0.5}, {0.5, 0.5, 0.5}));
  CHECK(w.exact);
  CHECK(w.volume == Approx(1).epsilon(1e-9));
}

TEST_CASE("cell quadrature: a half ball and a half capsule within the stated bound", "[shared-volume]") {
  Proxy ball;
  ball.kind = ProxyKind::Sphere;
  ball.sphere = {{0, 0, 0}, 0.5};
  const Proxy slab = box_proxy({1, 0, 0}, {1, 2, 2});  // x in [0, 2]
  const VolumeEstimate half = proxy_intersection_volume(ball, slab);
  const double want = 2.0 / 3 * kPiD * 0.125;
  CHECK_FALSE(half.exact);
  CHECK(std::abs(half.volume - want) <= half.error);
  CHECK(half.error <= 2e-2 * (4.0 / 3 * kPiD * 0.125));
  CHECK(half.cells > 1000);
  Proxy capsule;
  capsule.kind = ProxyKind::Capsule;
  capsule.capsule = {{-1, 0, 0}, {1, 0, 0}, 0.5};
  const VolumeEstimate cap = proxy_intersection_volume(capsule, slab);
  const double want_cap = kPiD * 0.25 * 1 + want;  // half the cylinder and one hemisphere
  CHECK(std::abs(cap.volume - want_cap) <= cap.error);
  // A coarse budget: a looser bound, still holding the answer.
  SharedVolumeConfig coarse;
  coarse.max_cells = 5000;
  const VolumeEstimate rough = proxy_intersection_volume(ball, slab, coarse);
  CHECK(rough.cells <= 5000);
  CHECK(rough.error > half.error);
  CHECK(std::abs(rough.volume - want) <= rough.error);
}

TEST_CASE("mesh volumes: icospheres and star polyhedra against the tetrahedra oracle", "[shared-volume]") {
  struct Case {
    TriMesh a, b;
    DVec3 ca, cb;
  };
  const TriMesh sphere = icosphere_mesh(2), star = icosphere_mesh(1, 1.8f);
  const std::vector<Case> cases = {
      {sphere, moved(sphere, {0.8f, 0.3f, 0}), {0, 0, 0}, {0.8, 0.3, 0}},
      {star, moved(star, {0.9f, 0.4f, 0.2f}), {0, 0, 0}, {0.9, 0.4, 0.2}},
      {star, moved(sphere, {1.2f, 0, 0}, 0.7f), {0, 0, 0}, {1.2, 0, 0}},
  };
  for (const Case& c : cases) {
    const SolidMesh a = build_solid_mesh(c.a.positions, c.a.indices),
                    b = build_solid_mesh(c.b.positions, c.b.indices);
    const double want = star_oracle(c.a, c.ca, c.b, c.cb);
    const VolumeEstimate got = mesh_intersection_volume({&a, 1}, {&b, 1});
    CHECK(want > 0.05);
    CHECK(std::abs(got.volume - want) <= got.error + 1e-9);
    CHECK(got.error <= 2e-2 * std::min(a.bsp.volume, b.bsp.volume));
  }
  // Apart: nothing, at once.
  const SolidMesh a = build_solid_mesh(sphere.positions, sphere.indices);
  const TriMesh far = moved(sphere, {5, 0, 0});
  const SolidMesh b = build_solid_mesh(far.positions, far.indices);
  const VolumeEstimate none = mesh_intersection_volume({&a, 1}, {&b, 1});
  CHECK(none.volume == 0);
  CHECK(none.error == 0);
}

TEST_CASE("collide_scene measures the volumes of its contacts", "[shared-volume]") {
  Scene s;
  s.meshes.push_back(cube_mesh(0.5f));
  Affine3f at;
  at.m[0][3] = 0.75f, at.m[1][3] = 0.1f;
  s.instances.push_back(make_instance(0, Affine3f{}, 0));
  s.instances.push_back(make_instance(0, at, 1));
  const std::vector<int> parents{-1, -1};
  CollideConfig config;
  config.volumes = true;
  const CollideReport meshes = collide_scene(s, {parents}, config);
  REQUIRE(meshes.contacts.size() == 1);
  const VolumeEstimate& v = meshes.contacts[0].volume;  // 0.25 x 0.9 x 1
  CHECK(std::abs(v.volume - 0.225) <= v.error + 1e-6);
  config.mesh = false;
  config.kind = ProxyKind::Aabb;
  const CollideReport boxes = collide_scene(s, {parents}, config);
  REQUIRE(boxes.contacts.size() == 1);
  CHECK(boxes.contacts[0].volume.exact);
  CHECK(boxes.contacts[0].volume.volume == Approx(0.225).epsilon(1e-6));
  // Node 1 placing two overlapping cubes, one of them mirrored (wound inwards in world space):
  // their union spans x in [0.25, 1.75], so node 0 shares 0.25 x 1 x 1 with it.
  Scene two = s;
  Affine3f mirrored = at;
  mirrored.m[0][0] = -1, mirrored.m[0][3] = 1.25f, mirrored.m[1][3] = 0;
  two.instances.push_back(make_instance(0, mirrored, 1));
  two.instances[1].to_world.m[1][3] = 0;
  two.instances[1] = make_instance(0, two.instances[1].to_world, 1);
  config.mesh = true;
  const CollideReport union_of = collide_scene(two, {parents}, config);
  REQUIRE(union_of.contacts.size() == 1);
  const VolumeEstimate& u = union_of.contacts[0].volume;
  CHECK(std::abs(u.volume - 0.25) <= u.error + 1e-6);
  CHECK(u.error < 0.05);
  // Node 1 as one cube split into two primitives (two meshes placed alike, each open alone, as
  // a glTF mesh split by material): one solid, the same 0.225 as the whole cube.
  Scene split = s;
  Mesh first = cube_mesh(0.5f), second = cube_mesh(0.5f);
  first.indices.resize(18);
  second.indices.erase(second.indices.begin(), second.indices.begin() + 18);
  split.meshes.push_back(first);
  split.meshes.push_back(second);
  split.instances[1] = make_instance(int(split.meshes.size()) - 2, at, 1);
  split.instances.push_back(make_instance(int(split.meshes.size()) - 1, at, 1));
  const CollideReport halves = collide_scene(split, {parents}, config);
  REQUIRE(halves.contacts.size() == 1);
  CHECK(std::abs(halves.contacts[0].volume.volume - 0.225) <= halves.contacts[0].volume.error + 1e-6);
  // An open mesh (a cube without its top) has no inside: refused, naming the node.
  Mesh open = cube_mesh(0.5f);
  open.indices.resize(open.indices.size() - 6);
  s.meshes.push_back(open);
  s.instances[1] = make_instance(1, at, 1);
  config.mesh = true;
  try {
    collide_scene(s, {parents}, config);
    FAIL("an open mesh was measured");
  } catch (const std::invalid_argument& e) {
    CHECK_THAT(e.what(), Catch::Contains("node 1") && Catch::Contains("not closed"));
  }
}
