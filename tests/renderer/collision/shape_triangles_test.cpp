// Tests for renderer/collision/shape_triangles: every kind's triangles against its true surface
// (points of the triangles and points of the surface, each within the stated bound of the
// other, by brute force), outward winding (positive signed volume) and closedness, the counts
// for budgets; and shapes in node_geometry, proxies and collisions against closed forms.
#include "renderer/collision/shape_triangles.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/accel/polytope.h"
#include "renderer/collision/scene_collide.h"
#include "renderer/collision/scene_proxies.h"
#include "renderer/scene/volume.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

DVec3 d3(Vec3f v) {
  return {v.x, v.y, v.z};
}

// The distance from p to the true surface of an analytic shape (flat shapes: the region).
double surface_distance(const Shape& s, DVec3 p) {
  switch (s.kind) {
    case ShapeKind::Sphere:
      return std::abs(length(p) - s.radius);
    case ShapeKind::Capsule: {
      const double y = std::clamp(p.y, -double(s.half_height), double(s.half_height));
      return std::abs(length(p - DVec3{0, y, 0}) - s.radius);
    }
    case ShapeKind::Disk: {
      const double r = std::sqrt(p.x * p.x + p.z * p.z);
      return std::sqrt(p.y * p.y + std::pow(std::max(0.0, r - s.radius), 2));
    }
    default:
      return 0;
  }
}

// A random point of the true surface.
DVec3 surface_point(const Shape& s, std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  std::uniform_real_distribution<double> u(0, 1);
  DVec3 dir{n(rng), n(rng), n(rng)};
  dir = dir * (1 / length(dir));
  if (s.kind == ShapeKind::Sphere) return dir * s.radius;
  if (s.kind == ShapeKind::Capsule) {
    const double y = (2 * u(rng) - 1) * s.half_height;
    if (u(rng) < 0.5) return DVec3{0, dir.y > 0 ? s.half_height : -s.half_height, 0} + dir * s.radius;
    const double a = 2 * 3.14159265358979 * u(rng);
    return {s.radius * std::cos(a), y, s.radius * std::sin(a)};
  }
  const double a = 2 * 3.14159265358979 * u(rng), r = s.radius * std::sqrt(u(rng));
  return {r * std::cos(a), 0, r * std::sin(a)};  // disk
}

double mesh_distance(const ShapeTriangles& t, DVec3 p) {
  double best = INFINITY;
  for (size_t i = 0; i < t.indices.size(); i += 3) {
    const DVec3 q = closest_on_triangle(p, d3(t.positions[t.indices[i]]), d3(t.positions[t.indices[i + 1]]),
                                        d3(t.positions[t.indices[i + 2]]));
    best = std::min(best, length(q - p));
  }
  return best;
}

}  // namespace

TEST_CASE("shape triangles lie within their bound of spheres, capsules and disks, both ways",
          "[shape-triangles]") {
  Shape sphere, capsule, disk;
  sphere.kind = ShapeKind::Sphere, sphere.radius = 1.5f;
  capsule.kind = ShapeKind::Capsule, capsule.radius = 0.4f, capsule.half_height = 1.2f;
  disk.kind = ShapeKind::Disk, disk.radius = 2;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  for (const Shape& s : {sphere, capsule, disk}) {
    CAPTURE(shape_kind_name(s.kind));
    const ShapeTriangles t = shape_triangles(s);
    CHECK(t.error > 0);
    CHECK(t.error < 0.02 * s.radius);  // sphere 0.3 %, capsule 1.3 %, disk 0.12 % of the radius
    const ShapeTrianglesCount n = shape_triangles_count(s);
    CHECK(n.vertices == t.positions.size());
    CHECK(n.triangles == t.indices.size() / 3);
    const MeshVolume v = mesh_volume(t.positions, t.indices);
    CHECK(v.closed == t.closed);
    CHECK(t.closed == (s.kind != ShapeKind::Disk));
    if (t.closed) {
      const double exact = s.kind == ShapeKind::Sphere ? 4.0 / 3 * 3.14159265358979 * std::pow(s.radius, 3)
                                                       : 3.14159265358979 * s.radius * s.radius *
                                                             (4.0 / 3 * s.radius + 2 * s.half_height);
      CHECK(v.signed_volume > 0);  // outward
      CHECK(v.signed_volume <= exact);
      CHECK(v.signed_volume >= exact * 0.98);
    }
    // Points of the triangles lie within the bound of the surface, and the bound is tight.
    double worst = 0;
    for (size_t i = 0; i < t.indices.size(); i += 3)
      for (int k = 0; k < 20; ++k) {
        double a = u(rng), b = u(rng);
        if (a + b > 1) a = 1 - a, b = 1 - b;
        const DVec3 p = d3(t.positions[t.indices[i]]) * (1 - a - b) + d3(t.positions[t.indices[i + 1]]) * a +
                        d3(t.positions[t.indices[i + 2]]) * b;
        worst = std::max(worst, surface_distance(s, p));
      }
    CHECK(worst <= t.error);
    if (t.closed) CHECK(worst >= 0.5 * t.error);  // a disk's fan lies in the disk
    // Points of the true surface lie within the bound of the triangles.
    for (int k = 0; k < 300; ++k) CHECK(mesh_distance(t, surface_point(s, rng)) <= t.error);
  }
}

TEST_CASE("shape triangles: boxes and planes exactly, implicit spheres within a cell", "[shape-triangles]") {
  Shape box;
  box.kind = ShapeKind::Box, box.half_size = {1, 2, 3};
  const ShapeTriangles b = shape_triangles(box);
  CHECK(b.error == 0);
  CHECK(mesh_volume(b.positions, b.indices).signed_volume == Approx(48));
  Shape plane;
  plane.kind = ShapeKind::Plane, plane.half_size = {2, 1, 3};
  const ShapeTriangles p = shape_triangles(plane);
  CHECK_FALSE(p.closed);
  // Facing +Y: the first triangle's normal.
  const DVec3 e1 = d3(p.positions[p.indices[1]] - p.positions[p.indices[0]]),
              e2 = d3(p.positions[p.indices[2]] - p.positions[p.indices[0]]);
  CHECK(e1.z * e2.x - e1.x * e2.z > 0);
  const Shape ball = make_implicit_shape(single_shape(sdf_primitive(SdfKind::Sphere, {1, 0, 0})));
  ShapeTrianglesConfig coarse;
  coarse.implicit_resolution = 24;
  const ShapeTriangles i = shape_triangles(ball, coarse);
  REQUIRE(!i.positions.empty());
  for (const Vec3f& q : i.positions) CHECK(std::abs(length(d3(q)) - 1) <= i.error);
  CHECK(mesh_volume(i.positions, i.indices).closed);
  CHECK(shape_triangles_count(ball, coarse).vertices >= i.positions.size());
  ShapeTrianglesConfig bad;
  bad.subdivisions = 7;
  CHECK_THROWS_AS(shape_triangles(ball, bad), std::invalid_argument);
}

TEST_CASE("shapes in node geometry, proxies and collisions", "[shape-triangles]") {
  // Node 0: a sphere of radius 1 at the origin, scaled by 2 (radius 2); node 1: a box of half
  // size 1 at x = 2.5 (overlapping the sphere by 0.5 along x); node 2: a capsule far away.
  Scene s;
  Shape sphere, box, capsule;
  sphere.kind = ShapeKind::Sphere, sphere.radius = 1;
  box.kind = ShapeKind::Box, box.half_size = {1, 1, 1};
  capsule.kind = ShapeKind::Capsule, capsule.radius = 0.5f, capsule.half_height = 1;
  s.shapes.push_back({"ball", sphere, -1, 0});
  s.shapes.push_back({"crate", box, -1, 1});
  s.shapes.push_back({"pill", capsule, -1, 2});
  Affine3f scaled, moved_box, far;
  scaled.m[0][0] = scaled.m[1][1] = scaled.m[2][2] = 2;
  moved_box.m[0][3] = 2.5f;
  far.m[0][3] = 20;
  s.instances.push_back(make_shape_instance(0, scaled, 0));
  s.instances.push_back(make_shape_instance(1, moved_box, 1));
  s.instances.push_back(make_shape_instance(2, far, 2));
  const std::vector<int> parents{-1, -1, -1};
  const std::vector<NodeGeometry> g = node_geometry(s, parents, -1);
  REQUIRE(g.size() == 3);
  CHECK(g[0].shapes == 1);
  // The sphere's error scales with its placement (bounded by the Frobenius norm, 2 sqrt 3).
  const double unit_error = shape_triangles(sphere).error;
  CHECK(g[0].shape_error == Approx(unit_error * 2 * std::sqrt(3.0)).epsilon(1e-6));
  CHECK(g[1].shape_error == 0);
  CHECK(g[1].enclosed_volume == Approx(8));
  CHECK(g[0].enclosed_volume <= 4.0 / 3 * 3.14159265358979 * 8);
  CHECK(g[0].enclosed_volume >= 4.0 / 3 * 3.14159265358979 * 8 * 0.98);
  CHECK(placed_geometry_count(s).vertices == g[0].points.size() + g[1].points.size() + g[2].points.size());

  // The minimal sphere of the ball is the ball, to the tessellation's error.
  SceneProxyConfig fit;
  fit.kind = ProxyKind::Sphere;
  fit.samples = 0;
  const std::vector<NodeProxy> proxies = fit_scene_proxies(s, parents, fit);
  REQUIRE(proxies.size() == 3);
  CHECK(proxies[0].proxy.sphere.radius == Approx(2).margin(1e-5));  // corners lie on the sphere
  CHECK(proxies[2].proxy.sphere.radius == Approx(1.5).margin(1e-5));

  // The ball and the crate overlap by 0.5 along x: the deepest point is the crate's face
  // centre (2 - 1.5 = 0.5 inside the ball's surface along x) or the ball's pole in the crate.
  const CollideReport r = collide_scene(s, {parents}, CollideConfig{});
  REQUIRE(r.contacts.size() == 1);
  const NodeContact& c = r.contacts[0];
  CHECK((c.a == 0 && c.b == 1));
  CHECK(c.depth <= 0.5 + g[0].shape_error);
  CHECK(c.depth >= 0.5 - c.depth_error - g[0].shape_error);
  CHECK(c.depth_error <= 0.05);
  CHECK(c.shape_error == g[0].shape_error);
}
