// Tests for renderer/cost_map: known counts with brute force, agreement with per-ray counting,
// the same image for any thread count, and costs that follow the geometry.
#include "renderer/integrators/cost_map.h"

#include <catch2/catch.hpp>

#include "renderer/accel/factory.h"
#include "renderer/core/rng.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/camera.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
Scene two_quads() {
  Scene s;
  add_quad_z(s, -1, 1, -1, 1, 0, -1);
  add_quad_z(s, 2, 3, -1, 1, 0.5f, -1);
  return s;
}
}  // namespace

TEST_CASE("cost map: brute force tests every triangle on every camera ray and visits no node",
          "[cost][quick]") {
  const Scene s = two_quads();
  const auto views = mesh_views(s);
  const auto brute = make_accelerator("brute", views);
  REQUIRE(brute->counts_traversal());
  const RenderConfig cfg = small_render_config(12, 8, 4);
  const Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  const CostImage c = render_cost(*brute, cam, cfg);
  REQUIRE(c.nodes.size() == 96);
  for (size_t i = 0; i < c.nodes.size(); ++i) {
    CHECK(c.nodes[i] == 0);
    CHECK(c.triangles[i] == 4);  // two quads, four triangles
  }
}

TEST_CASE("cost map: shapes count one test each, implicit ones their SDF evaluations too", "[cost][quick]") {
  Scene s = two_quads();
  add_shape(s, sphere_shape(0.3f), Affine3f{}, -1);
  add_shape(s, sphere_shape(0.5f, true), Affine3f{}, -1);
  const auto views = mesh_views(s);  // world space: the shapes' placements are the identity
  const auto brute = make_accelerator("brute", views);
  const RenderConfig cfg = small_render_config(12, 8, 4);
  const Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  const CostImage c = render_cost(*brute, cam, cfg);
  const std::vector<float> total = total_cost(c);
  bool evaluated = false;
  for (size_t i = 0; i < c.shapes.size(); ++i) {
    CHECK(c.triangles[i] == 4);
    CHECK(c.shapes[i] >= 2);  // both shapes tested on every ray, plus the tracer's evaluations
    CHECK(total[i] == c.nodes[i] + c.triangles[i] + c.shapes[i]);
    evaluated |= c.shapes[i] > 2;
  }
  CHECK(evaluated);  // some camera rays cross the implicit sphere's box
}

TEST_CASE("cost map: matches intersect_counted per ray, the same for 1 and 2 threads", "[cost]") {
  const Scene s = two_quads();
  const auto views = mesh_views(s);
  const Camera cam = look_at({0.5f, 0.3f, 4}, {0.5f, 0, 0}, {0, 1, 0}, 0.9f);
  RenderConfig cfg;
  cfg.width = 24;
  cfg.height = 16;
  cfg.spp = 1;
  for (const char* name : {"bvh", "kdtree", "grid", "octree", "bsp"}) {
    INFO(name);
    const auto a = make_accelerator(name, views);
    REQUIRE(a->counts_traversal());
    cfg.threads = 1;
    const CostImage c1 = render_cost(*a, cam, cfg);
    cfg.threads = 2;
    const CostImage c2 = render_cost(*a, cam, cfg);
    CHECK(c1.nodes == c2.nodes);
    CHECK(c1.triangles == c2.triangles);
    // With one sample per pixel the jittered ray is the render's; recount a few by hand.
    double hit_cost = 0, miss_cost = 0;
    int hits = 0, misses = 0;
    for (int y = 0; y < cfg.height; ++y)
      for (int x = 0; x < cfg.width; ++x) {
        const size_t i = size_t(y) * size_t(cfg.width) + size_t(x);
        CHECK(c1.nodes[i] >= 0);
        Hit h;
        // The pixel centre ray: hit or miss decides which average it joins.
        const bool hit = a->intersect(generate_camera_ray(cam, cfg.width, cfg.height, x + 0.5f, y + 0.5f), h);
        (hit ? hit_cost : miss_cost) += c1.nodes[i] + c1.triangles[i];
        (hit ? hits : misses) += 1;
      }
    REQUIRE(hits > 0);
    REQUIRE(misses > 0);
    CHECK(hit_cost / hits > miss_cost / misses);  // work concentrates where the geometry is
  }
  // The totals equal a direct sum of intersect_counted over the same rays.
  const auto bvh = make_accelerator("bvh", views);
  cfg.threads = 0;
  const CostImage c = render_cost(*bvh, cam, cfg);
  TraversalCost direct;
  double image_total = 0;
  for (int y = 0; y < cfg.height; ++y)
    for (int x = 0; x < cfg.width; ++x) {
      Rng rng = make_pixel_rng(uint32_t(x), uint32_t(y), 0, cfg.seed);
      const Vec2f j = stratified_sample(0, 1, rng);
      Hit h;
      bvh->intersect_counted(generate_camera_ray(cam, cfg.width, cfg.height, x + j.x, y + j.y), h, direct);
      image_total += c.nodes[size_t(y) * size_t(cfg.width) + size_t(x)] +
                     c.triangles[size_t(y) * size_t(cfg.width) + size_t(x)];
    }
  CHECK(image_total == double(direct.nodes + direct.triangles));
}

TEST_CASE("cost map: Embree gets a time map; counted back ends get counts and times", "[cost][quick]") {
  const Scene s = two_quads();
  const auto views = mesh_views(s);
  RenderConfig cfg;
  cfg.width = 16;
  cfg.height = 9;
  cfg.spp = 2;
  const Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 0.8f);
  const CostImage e = render_cost(*make_accelerator("embree", views), cam, cfg);
  CHECK_FALSE(e.counted);
  CHECK(cost_caption(e, "embree") == "embree: nanoseconds per camera ray (wall clock)");
  REQUIRE(e.nanoseconds.size() == 144);
  double total_ns = 0;
  for (float ns : e.nanoseconds) {
    CHECK(ns >= 0);
    total_ns += ns;
  }
  CHECK(total_ns > 0);
  CHECK(total_cost(e) == e.nanoseconds);
  const CostImage b = render_cost(*make_accelerator("bvh", views), cam, cfg);
  CHECK(b.counted);
  CHECK(cost_caption(b, "bvh") == "bvh: nodes + triangles + shape work per camera ray");
  const auto t = total_cost(b);
  for (size_t i = 0; i < t.size(); ++i) CHECK(t[i] == b.nodes[i] + b.triangles[i]);
}

TEST_CASE("cost map: Embree answers but does not count", "[cost][quick]") {
  const Scene s = two_quads();
  const auto views = mesh_views(s);
  const auto e = make_accelerator("embree", views);
  CHECK_FALSE(e->counts_traversal());
  TraversalCost cost;
  Hit h;
  CHECK(e->intersect_counted({{0, 0, 5}, 0, {0, 0, -1}, kInfinity}, h, cost));
  CHECK(h.t == Approx(5).epsilon(1e-6));  // Embree's t carries rounding on some CPUs
  CHECK(cost.nodes == 0);
  CHECK(cost.triangles == 0);
}
