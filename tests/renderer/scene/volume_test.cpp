// Tests for renderer/scene/volume: a box mesh's volume exact (split per face, reversed, opened,
// with a doubled face), the analytic shapes' closed forms, implicit shapes (sphere, torus, a
// disjoint pair) whose closed forms lie within the reported bound, and instances scaled and
// mirrored.
#include "renderer/scene/volume.h"

#include <catch2/catch.hpp>
#include <numbers>

#include "support/scene_builder.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

constexpr double kPiD = std::numbers::pi;

// The box [0, sx] x [0, sy] x [0, sz] with 4 vertices per face (as glTF exports split normals),
// triangles facing outwards.
Mesh box_mesh(float sx, float sy, float sz) {
  Mesh m;
  m.name = "box";
  const Vec3f c[8] = {{0, 0, 0},  {sx, 0, 0},  {sx, sy, 0},  {0, sy, 0},
                      {0, 0, sz}, {sx, 0, sz}, {sx, sy, sz}, {0, sy, sz}};
  // Each face's corners counter-clockwise seen from outside.
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
  for (const auto& f : faces) {
    const uint32_t base = uint32_t(m.positions.size());
    for (int k = 0; k < 4; ++k) m.positions.push_back(c[f[k]]);
    for (uint32_t t : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + t);
  }
  return m;
}

void check_bound(const ShapeVolume& v, double exact, double max_relative_error) {
  INFO("volume " << v.volume << " +- " << v.error << ", exact " << exact);
  CHECK(v.closed);
  CHECK(std::fabs(v.volume - exact) <= v.error);
  CHECK(v.error <= max_relative_error * exact);
  CHECK(std::fabs(v.volume - exact) <= 0.002 * exact);
}

}  // namespace

TEST_CASE("volume: a closed box mesh is exact, split per face, either way round", "[volume]") {
  Mesh m = box_mesh(1, 2, 3);
  MeshVolume v = mesh_volume(m.positions, m.indices);
  CHECK(v.closed);
  CHECK(v.open_edges == 0);
  CHECK(v.signed_volume == 6.0);
  for (size_t t = 0; t < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
  v = mesh_volume(m.positions, m.indices);
  CHECK(v.closed);
  CHECK(v.signed_volume == -6.0);
}

TEST_CASE("volume: open and non-manifold meshes are not closed", "[volume]") {
  Mesh m = box_mesh(1, 1, 1);
  Mesh open = m;
  open.indices.resize(open.indices.size() - 3);
  MeshVolume v = mesh_volume(open.positions, open.indices);
  CHECK_FALSE(v.closed);
  CHECK(v.open_edges == 3);
  Mesh doubled = m;
  doubled.indices.insert(doubled.indices.end(), m.indices.begin(), m.indices.begin() + 3);
  v = mesh_volume(doubled.positions, doubled.indices);
  CHECK_FALSE(v.closed);
  CHECK(v.bad_edges == 3);
  // One face turned the other way: its edges run the same way as their neighbours'.
  Mesh flipped = m;
  for (size_t t = 0; t < 6; t += 3) std::swap(flipped.indices[t + 1], flipped.indices[t + 2]);
  CHECK_FALSE(mesh_volume(flipped.positions, flipped.indices).closed);
  CHECK_FALSE(mesh_volume({}, {}).closed);
}

TEST_CASE("volume: analytic shapes have their closed forms", "[volume]") {
  ShapeVolume v = shape_volume(analytic_shape(ShapeKind::Sphere, 0.7f));
  CHECK(v.closed);
  CHECK(v.volume == Approx(4.0 / 3.0 * kPiD * 0.7 * 0.7 * 0.7).epsilon(1e-6));
  CHECK(v.error == 0);
  v = shape_volume(analytic_shape(ShapeKind::Box, 1, {4, 2, 0.05f}));
  CHECK(v.volume == Approx(8 * 4 * 2 * 0.05).epsilon(1e-6));
  v = shape_volume(analytic_shape(ShapeKind::Capsule, 0.3f, {1, 1, 1}, 0.6f));
  CHECK(v.volume == Approx(kPiD * 0.09 * 1.2 + 4.0 / 3.0 * kPiD * 0.027).epsilon(1e-6));
  CHECK_FALSE(shape_volume(analytic_shape(ShapeKind::Plane)).closed);
  CHECK_FALSE(shape_volume(analytic_shape(ShapeKind::Disk)).closed);
}

TEST_CASE("volume: implicit shapes hold their closed forms within the reported bound", "[volume][heavy]") {
  check_bound(shape_volume(sphere_shape(1, true)), 4.0 / 3.0 * kPiD, 0.02);
  const Shape torus = make_implicit_shape(single_shape(sdf_primitive(SdfKind::Torus, {0.8f, 0, 0}, 0.28f)));
  check_bound(shape_volume(torus), 2 * kPiD * kPiD * 0.8 * 0.28 * 0.28, 0.05);
  const Shape pair = make_implicit_shape(sphere_pair(0.5f, 1));
  check_bound(shape_volume(pair), 2 * 4.0 / 3.0 * kPiD * 0.125, 0.03);
  // The same answer every time (parallel classification).
  const ShapeVolume a = shape_volume(torus), b = shape_volume(torus);
  CHECK(a.volume == b.volume);
  CHECK(a.error == b.error);
  // Fewer levels: a wider bound that still holds.
  VolumeConfig coarse;
  coarse.refine_levels = 1;
  const ShapeVolume c = shape_volume(torus, coarse);
  CHECK(c.error > a.error);
  CHECK(std::fabs(c.volume - 2 * kPiD * kPiD * 0.8 * 0.28 * 0.28) <= c.error);
}

TEST_CASE("volume: instances scale their object's volume by |det|", "[volume]") {
  Scene s;
  s.meshes.push_back(box_mesh(1, 2, 3));
  Affine3f twice;
  twice.m[0][0] = twice.m[1][1] = twice.m[2][2] = 2;
  Affine3f mirror;
  mirror.m[0][0] = -1;
  s.instances.push_back(make_instance(0, twice));
  s.instances.push_back(make_instance(0, mirror));
  add_shape(s, analytic_shape(ShapeKind::Sphere, 1), twice, -1);
  add_shape(s, analytic_shape(ShapeKind::Plane), Affine3f{}, -1);
  const std::vector<InstanceVolume> v = instance_volumes(s);
  REQUIRE(v.size() == 4);
  CHECK(v[0].closed);
  CHECK(v[0].volume == 48.0);
  CHECK(v[1].volume == 6.0);
  CHECK_FALSE(v[1].inward);
  CHECK(v[2].volume == Approx(8 * 4.0 / 3.0 * kPiD).epsilon(1e-6));
  CHECK_FALSE(v[3].closed);
  CHECK(v[3].volume == 0);
}
