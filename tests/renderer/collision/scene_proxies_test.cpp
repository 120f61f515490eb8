// Tests for renderer/collision/scene_proxies: node geometry per node and per subtree (placed
// vertices, enclosed volumes scaled by the placement), tightness closed forms (a cube's AABB:
// ratio 1, Hausdorff 0; its minimal sphere: Hausdorff sqrt(3) - 1), and every proxy kind as
// shapes whose surfaces the proxy's surface samples lie on.
#include "renderer/collision/scene_proxies.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/shapes/sdf.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

// A uniform scale by s, then a move by t.
Affine3f scale_translate(float s, Vec3f t) {
  Affine3f a;
  for (int r = 0; r < 3; ++r) {
    a.m[r][r] = s;
    a.m[r][3] = t[r];
  }
  return a;
}

// Node 0 places the cube as it is; node 1, its child, the cube scaled by 2 and moved.
Scene two_cubes() {
  Scene s;
  s.meshes.push_back(cube_mesh(1));
  s.instances.push_back(make_instance(0, Affine3f{}, 0));
  s.instances.push_back(make_instance(0, scale_translate(2, {10, 0, 0}), 1));
  return s;
}

double len(DVec3 v) {
  return std::sqrt(dot(v, v));
}

}  // namespace

TEST_CASE("node geometry: per node and per subtree, volumes placed", "[proxy]") {
  const Scene s = two_cubes();
  const std::vector<int> parents{-1, 0};
  const std::vector<NodeGeometry> nodes = node_geometry(s, parents, -1);
  REQUIRE(nodes.size() == 2);
  CHECK(nodes[0].node == 0);
  CHECK(nodes[0].points.size() == 8);
  CHECK(nodes[0].triangles.size() == 36);
  CHECK(nodes[0].enclosed_volume == Approx(8));
  CHECK(nodes[1].enclosed_volume == Approx(64));
  CHECK(nodes[1].points[7].x == Approx(12));
  const std::vector<NodeGeometry> tree = node_geometry(s, parents, 0);
  REQUIRE(tree.size() == 1);
  CHECK(tree[0].points.size() == 16);
  CHECK(tree[0].enclosed_volume == Approx(72));
  CHECK(node_geometry(s, parents, 1).at(0).points.size() == 8);

  Scene open = s;
  open.meshes[0].indices.resize(30);  // a face missing
  CHECK(std::isnan(node_geometry(open, parents, -1).at(0).enclosed_volume));
}

TEST_CASE("tightness: a cube's AABB is exact, its minimal sphere overshoots by sqrt(3) - 1", "[proxy]") {
  const Scene s = two_cubes();
  const std::vector<int> parents{-1, 0};
  const NodeGeometry g = node_geometry(s, parents, -1).at(0);
  const Proxy box = fit_proxy(ProxyKind::Aabb, g.points, g.triangles);
  const ProxyTightness tb = proxy_tightness(box, g, 4000, 2, 8);
  CHECK(tb.volume_ratio == Approx(1).epsilon(1e-12));
  CHECK(tb.hull_ratio == Approx(1).epsilon(1e-12));
  CHECK(tb.hausdorff < 1e-6);
  CHECK(tb.samples == 4000);

  const Proxy sphere = fit_proxy(ProxyKind::Sphere, g.points, g.triangles);
  const ProxyTightness ts = proxy_tightness(sphere, g, 20000, 2, 8);
  CHECK(ts.volume_ratio == Approx(4.0 / 3 * M_PI * std::pow(std::sqrt(3.0), 3) / 8).epsilon(1e-9));
  CHECK(ts.hausdorff <= std::sqrt(3.0) - 1 + 1e-5);
  CHECK(ts.hausdorff > std::sqrt(3.0) - 1 - 0.02);
  // The same result on one thread.
  CHECK(proxy_tightness(sphere, g, 20000, 1, 8).hausdorff == ts.hausdorff);

  SceneProxyConfig cfg;
  cfg.kind = ProxyKind::Hull;
  cfg.samples = 1000;
  const std::vector<NodeProxy> all = fit_scene_proxies(s, parents, cfg);
  REQUIRE(all.size() == 2);
  CHECK(all[1].tightness.volume_ratio == Approx(1).epsilon(1e-9));
  CHECK(all[1].tightness.hausdorff < 1e-5);
}

TEST_CASE("proxies as shapes: the proxy's surface is the shape's surface", "[proxy]") {
  std::vector<DVec3> pts;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  for (int i = 0; i < 400; ++i)
    pts.push_back({2 + 3 * g(rng), -1 + g(rng) + 0.5 * g(rng), 0.4 * g(rng) + 0.2 * g(rng)});
  for (int k = 0; k < kProxyKindCount; ++k) {
    const ProxyKind kind = ProxyKind(k);
    INFO(proxy_kind_name(kind));
    const Proxy proxy = fit_proxy(kind, pts);
    Scene scene;
    append_proxy_shapes(scene, proxy, -1, "proxy", -1);
    REQUIRE(scene.instances.size() == 1);
    const Instance& inst = scene.instances[0];
    REQUIRE(inst.shape >= 0);
    const Shape& shape = scene.shapes[size_t(inst.shape)].shape;
    std::vector<DVec3> surface;
    sample_proxy_surface(proxy, 200, 9, surface);
    for (const DVec3& p : surface) {
      const Vec3f o = apply_point(inst.to_object, Vec3f{float(p.x), float(p.y), float(p.z)});
      double off = 0;  // distance of the object-space point from the shape's surface
      switch (shape.kind) {
        case ShapeKind::Sphere:
          off = length(o) - shape.radius;
          break;
        case ShapeKind::Box: {
          const Vec3f q = abs(o) - shape.half_size;
          off = std::max({q.x, q.y, q.z});
          break;
        }
        case ShapeKind::Capsule: {
          const float y = std::clamp(o.y, -shape.half_height, shape.half_height);
          off = length(o - Vec3f{0, y, 0}) - shape.radius;
          break;
        }
        default:
          off = sdf_eval(shape.sdf, o);
      }
      CHECK(std::abs(off) < 2e-5 * (1 + len(p)));
    }
  }
}
