// Scene helpers (renderer/scene.h): instances and their inverses, the mirrored flag and the
// front face it implies, world-space triangles and normals, bounds and triangle counts over
// instances, and the views handed to the accelerator builders.
#include "renderer/scene/scene.h"

#include <catch2/catch.hpp>

#include "renderer/integrators/scene_accel.h"
#include "support/scene_builder.h"

using namespace penumbra;
using penumbra::test::check_vec;

namespace {

Affine3f trs(Vec3f t, Quat q, Vec3f s) {
  return to_affine(compose_trs({t.x, t.y, t.z}, q, {s.x, s.y, s.z}));
}

}  // namespace

TEST_CASE("scene: make_instance inverts the placement and flags mirrors; singular maps are refused",
          "[scene][quick]") {
  const Instance moved = make_instance(0, trs({1, 2, 3}, {}, {2, 4, 8}), 5);
  CHECK_FALSE(moved.identity);
  CHECK_FALSE(moved.mirrored);
  CHECK(moved.node == 5);
  check_vec(apply_point(moved.to_object, {3, 6, 11}), {1, 1, 1});
  CHECK(make_instance(0, Affine3f{}).identity);
  CHECK(make_instance(0, trs({}, {}, {-1, 1, 1})).mirrored);
  CHECK_FALSE(make_instance(0, trs({}, {}, {-1, -1, 1})).mirrored);  // a half turn, not a mirror
  CHECK_THROWS_AS(make_instance(0, trs({}, {}, {1, 0, 1})), std::invalid_argument);
  Affine3f nan;
  nan.m[0][3] = std::nanf("");
  CHECK_THROWS_AS(make_instance(0, nan), std::invalid_argument);
}

TEST_CASE("scene: world triangles keep the object's front face under mirrors; normals follow L^-T",
          "[scene][quick]") {
  Scene s;
  test::add_quad_z(s, 0, 1, 0, 1, 0, -1);                                   // front +z
  s.instances.push_back(make_instance(0, trs({0, 0, 2}, {}, {-1, 1, 1})));  // mirrored in x
  s.instances.push_back(make_instance(0, trs({}, {}, {1, 1, 4})));          // stretched along z
  s.instances.push_back(
      make_instance(0, trs({}, {std::sqrt(0.5), 0, 0, std::sqrt(0.5)}, {1, 1, 1})));  // x 90 deg
  const WorldTriangle in_place = world_triangle(s, s.instances[0], 0);
  check_vec(in_place.ng, {0, 0, 1});
  const WorldTriangle mirrored = world_triangle(s, s.instances[1], 0);
  check_vec(mirrored.p[1], {-1, 0, 2});
  check_vec(mirrored.ng, {0, 0, 1});  // the mirror image of a +z face still faces +z
  check_vec(world_triangle(s, s.instances[3], 0).ng, {0, -1, 0});  // +z turned about x by 90 deg
  // A sheared normal: the plane x + z = 0 stretched 4x along z has normal (4, 0, 1)/|.|.
  check_vec(world_normal(s.instances[2], normalize(Vec3f{1, 0, 1})), normalize(Vec3f{4, 0, 1}));
  check_vec(world_normal(s.instances[0], {0, 0, 1}), {0, 0, 1});
}

TEST_CASE("scene: bounds and triangle counts run over instances; views list meshes and placements",
          "[scene][quick]") {
  Scene s;
  test::add_quad_z(s, -1, 1, -1, 1, 0, -1);  // mesh 0, placed by the identity
  s.instances.push_back(
      make_instance(0, trs({10, 0, 0}, {0, 0, std::sin(kPi / 8), std::cos(kPi / 8)}, {1, 1, 1})));
  CHECK(count_triangles(s) == 4);
  CHECK(count_stored_triangles(s) == 2);
  // Exact: the quad turned 45 degrees about z reaches sqrt 2 from its centre.
  const Bounds3f exact = compute_bounds(s);
  check_vec(exact.lo, {-1, -std::sqrt(2.0f), 0}, 1e-5f);
  check_vec(exact.hi, {10 + std::sqrt(2.0f), std::sqrt(2.0f), 0}, 1e-5f);
  // Conservative (limit 0): the mapped corners of the mesh's box. For a triangle (0,0)-(1,0)-(0,1)
  // turned 45 degrees about z, the exact top is sqrt(1/2) but the box's corner (1, 1) reaches sqrt 2.
  Scene t;
  Mesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.indices = {0, 1, 2};
  t.meshes.push_back(tri);
  t.instances.push_back(make_instance(0, trs({}, {0, 0, std::sin(kPi / 8), std::cos(kPi / 8)}, {1, 1, 1})));
  CHECK(compute_bounds(t).hi.y == Approx(std::sqrt(0.5)));
  CHECK(compute_bounds(t, 0).hi.y == Approx(std::sqrt(2.0)));
  CHECK(compute_bounds(t, 3).hi.y == Approx(std::sqrt(0.5)));  // 3 vertices: within the limit
  const auto meshes = mesh_views(s);
  const auto instances = instance_views(s);
  REQUIRE(meshes.size() == 1);
  REQUIRE(instances.size() == 2);
  CHECK(instances[1].mesh == 0);
  CHECK(instances[1].to_world.m[0][3] == 10);
  // Empty scene: empty bounds.
  CHECK(compute_bounds(Scene{}).empty());
}
