// Tests for renderer/scene/shape_mesh: implicit shapes placed by instances (moved, scaled,
// mirrored) become closed outward world-space meshes with their materials and object frames; the node filter,
// analytic shapes, and the memory budget refused before meshing.
#include "renderer/scene/shape_mesh.h"

#include <catch2/catch.hpp>
#include <stdexcept>

#include "renderer/integrators/aov.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/camera.h"
#include "support/mesh_checks.h"
#include "support/scene_builder.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

Affine3f scale_and_move(Vec3f s, Vec3f d) {
  Affine3f a;
  a.m[0][0] = s.x, a.m[1][1] = s.y, a.m[2][2] = s.z;
  a.m[0][3] = d.x, a.m[1][3] = d.y, a.m[2][3] = d.z;
  return a;
}

// A unit implicit sphere (material 1) placed three times: by node 4 moved and scaled by 2, by
// node 5 mirrored in x, by node 6 unchanged; an analytic sphere on node 7.
Scene sphere_scene() {
  Scene s;
  s.materials.resize(2);
  s.materials[1].name = "red";
  SceneShape implicit{"ball", make_implicit_shape(single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0}))), 1,
                      4};
  s.shapes.push_back(implicit);
  SceneShape analytic;
  analytic.name = "analytic";
  s.shapes.push_back(analytic);
  s.instances.push_back(make_shape_instance(0, scale_and_move({2, 2, 2}, {10, 0, 0}), 4));
  s.instances.push_back(make_shape_instance(0, scale_and_move({-1, 1, 1}, {0, 5, 0}), 5));
  s.instances.push_back(make_shape_instance(0, Affine3f{}, 6));
  s.instances.push_back(make_shape_instance(1, Affine3f{}, 7));
  return s;
}

}  // namespace

TEST_CASE("shape meshes: placed implicit shapes become closed outward world meshes", "[shapes][mc][quick]") {
  const Scene scene = sphere_scene();
  ShapeMeshConfig config;
  config.resolution = 32;
  const ShapeMeshes out = mesh_implicit_shapes(scene, config);
  CHECK(out.skipped_analytic == 1);
  REQUIRE(out.scene.meshes.size() == 3);
  REQUIRE(out.scene.instances.size() == 3);
  CHECK(out.scene.materials.size() == 2);
  const float cell = marching_cubes_grid(scene.shapes[0].shape.sdf_bounds, 32, {}).cell;
  const Vec3f centres[3] = {{10, 0, 0}, {0, 5, 0}, {0, 0, 0}};
  const float radii[3] = {2, 1, 1};
  for (size_t i = 0; i < 3; ++i) {
    INFO("instance " << i);
    const Mesh& m = out.scene.meshes[i];
    CHECK(m.material == 1);
    CHECK(m.name == "ball");
    CHECK(m.node == scene.instances[i].node);
    CHECK(out.scene.instances[i].identity);
    const MeshTopology t = mesh_topology(m.positions.size(), m.indices);
    CHECK(t.closed_manifold());
    CHECK(t.euler == 2);
    // Outward faces: the volume about the centre is positive and near the ball's.
    std::vector<Vec3f> local;
    for (const Vec3f& p : m.positions) local.push_back(p - centres[i]);
    const double r = radii[i];
    CHECK(mesh_volume(local, m.indices) == Approx(4 * 3.14159265 / 3 * r * r * r).epsilon(0.03));
    // Bounds of the sphere within a (scaled) cell; normals unit and outward.
    Bounds3f b;
    for (const Vec3f& p : m.positions) b = merge(b, p);
    for (int a = 0; a < 3; ++a) {
      CHECK(b.lo[a] == Approx(centres[i][a] - radii[i]).margin(radii[i] * cell));
      CHECK(b.hi[a] == Approx(centres[i][a] + radii[i]).margin(radii[i] * cell));
    }
    for (size_t v = 0; v < m.positions.size(); ++v) {
      CHECK(std::abs(length(m.normals[v]) - 1) < 1e-4f);
      CHECK(dot(m.normals[v], local[v]) > 0);
    }
    // The mesh keeps the shape's frame for object-space textures: its vertices map back onto
    // the unit sphere.
    for (size_t v = 0; v < m.positions.size(); v += 7)
      CHECK(length(apply_point(m.object_from_world, m.positions[v])) == Approx(1).margin(cell));
  }
}

TEST_CASE("shape meshes: one node, and budgets refused before meshing", "[shapes][mc][quick]") {
  const Scene scene = sphere_scene();
  ShapeMeshConfig config;
  config.resolution = 16;
  config.node = 5;
  const ShapeMeshes one = mesh_implicit_shapes(scene, config);
  REQUIRE(one.scene.meshes.size() == 1);
  CHECK(one.scene.meshes[0].node == 5);
  config.node = 7;  // the analytic sphere only
  CHECK(mesh_implicit_shapes(scene, config).scene.meshes.empty());

  config.node = -1;
  config.resolution = 4096;
  config.max_bytes = uint64_t(1) << 30;
  CHECK_THROWS_WITH(mesh_implicit_shapes(scene, config),
                    Catch::Contains("ball: meshing at resolution 4096 needs") && Catch::Contains("bytes"));
  config.resolution = 0;
  config.max_bytes = UINT64_MAX;
  CHECK_THROWS_AS(mesh_implicit_shapes(scene, config), std::invalid_argument);
  // A budget that holds the grids but not every mesh: refused when the meshes would not fit.
  config.resolution = 32;
  const uint64_t one_shape = marching_cubes_bytes(scene.shapes[0].shape.sdf_bounds, 32, {});
  config.max_bytes = one_shape + one_shape / 4;
  CHECK_THROWS_WITH(mesh_implicit_shapes(scene, config), Catch::Contains("ball: "));
}

TEST_CASE("shape_mesh: the marched mesh and the sphere-traced shape give the same depth AOV",
          "[mc][shapes]") {
  // The CSG part and a smooth blob, rotated and moved by their instances, rendered with the
  // depth AOV twice: sphere traced, and as the meshes marching cubes makes of them at 128 cells.
  // Away from silhouettes and creases (where a pixel's footprint straddles two surfaces) the
  // depths agree within one cell.
  Scene s;
  s.materials.resize(1);
  Affine3f turn;  // 30 degrees about Y, then moved
  const float c = std::cos(0.52f), sn = std::sin(0.52f);
  turn.m[0][0] = c, turn.m[0][2] = sn, turn.m[2][0] = -sn, turn.m[2][2] = c;
  turn.m[0][3] = -1.2f;
  s.shapes.push_back({"part", make_implicit_shape(csg_part()), 0, 0});
  s.instances.push_back(make_shape_instance(0, turn, 0));
  s.shapes.push_back({"blob", make_implicit_shape(sphere_pair(0.6f, 0.5f, 0.4f)), 0, 1});
  s.instances.push_back(make_shape_instance(1, scale_and_move({1, 1, 1}, {1.6f, 0, 0}), 1));
  ShapeMeshConfig mc;
  mc.resolution = 128;
  const ShapeMeshes meshed = mesh_implicit_shapes(s, mc);
  REQUIRE(meshed.scene.meshes.size() == 2);
  Camera cam = look_at({0.3f, 1.5f, 6}, {0.2f, 0, 0}, {0, 1, 0}, 0.7f);
  RenderConfig cfg = small_render_config(192, 128, 1);
  const auto traced_accel = make_scene_accelerator("bvh", s);
  const auto mesh_accel = make_scene_accelerator("bvh", meshed.scene);
  const DataAovs traced = render_data_aovs(s, *traced_accel, cam, cfg, IntegratorType::Whitted);
  const DataAovs mesh = render_data_aovs(meshed.scene, *mesh_accel, cam, cfg, IntegratorType::Whitted);
  // The coarser of the two shapes' cells: the part's box is 2 wide, the blob's 2.2.
  const float cell = 2.2f / 128;
  int compared = 0;
  for (int y = 1; y + 1 < 128; ++y)
    for (int x = 1; x + 1 < 192; ++x) {
      // Smooth neighbourhood: every neighbour hits in both renders with a depth near this one's.
      const float z = traced.depth[size_t(y * 192 + x)];
      bool smooth = std::isfinite(z);
      for (int dy = -1; dy <= 1 && smooth; ++dy)
        for (int dx = -1; dx <= 1 && smooth; ++dx) {
          const size_t j = size_t((y + dy) * 192 + x + dx);
          smooth = std::isfinite(traced.depth[j]) && std::isfinite(mesh.depth[j]) &&
                   std::fabs(traced.depth[j] - z) < 0.05f;
        }
      if (!smooth) continue;
      ++compared;
      INFO("pixel (" << x << ", " << y << ")");
      CHECK(std::fabs(mesh.depth[size_t(y * 192 + x)] - z) <= cell);
    }
  CHECK(compared > 1000);
}
