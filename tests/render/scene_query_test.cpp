// Tests for render/scene_query: picking against the id and depth AOVs of the renderer's own
// camera samples (perspective, look-at and orthographic cameras), the batches against the
// single queries for any thread count, and render_view against prepare_render.
#include "render/scene_query.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/integrators/aov.h"
#include "renderer/scene/camera.h"
#include "support/test_util.h"

namespace penumbra {
namespace {

LoadedScene default_scene() {
  return load_gltf(test::source_dir() / "scenes/default.gltf");
}

// Pixels whose 3x3 neighbourhood shows one object and one material in the id AOV: one surface
// covers each of them, so every camera sample sees what the pixel's centre sees.
std::vector<std::pair<int, int>> uniform_pixels(const DataAovs& a) {
  std::vector<std::pair<int, int>> out;
  for (int y = 1; y + 1 < a.height; ++y)
    for (int x = 1; x + 1 < a.width; ++x) {
      const size_t c = size_t(y) * size_t(a.width) + size_t(x);
      bool same = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const size_t n = size_t(y + dy) * size_t(a.width) + size_t(x + dx);
          same = same && a.object_id[n] == a.object_id[c] && a.material_id[n] == a.material_id[c];
        }
      if (same) out.push_back({x, y});
    }
  return out;
}

void check_pick_against_aovs(const Scene& scene, const Accelerator& accel, const Camera& camera,
                             const RenderConfig& config) {
  const DataAovs a = render_data_aovs(scene, accel, camera, config, IntegratorType::Whitted);
  const auto pixels = uniform_pixels(a);
  REQUIRE(pixels.size() > size_t(a.width * a.height / 4));
  int hits = 0;
  for (const auto& [x, y] : pixels) {
    const size_t i = size_t(y) * size_t(a.width) + size_t(x);
    const Pick p = pick(scene, accel, camera, a.width, a.height, x, y);
    INFO("pixel " << x << "," << y);
    REQUIRE(p.hit == (a.object_id[i] != 0));
    if (!p.hit) continue;
    ++hits;
    CHECK(float(p.owner.node + 1) == a.object_id[i]);
    CHECK(float(p.owner.material + 1) == a.material_id[i]);
    // The ray's point is the reported one, at the reported distance and depth.
    const Vec3f q = p.ray.org + p.ray.dir * p.match.distance;
    CHECK(length(q - p.match.point) <= 1e-4f * (1 + length(q)));
    CHECK(p.depth == Approx(dot(p.match.point - camera.eye, -camera.w)).margin(1e-5));
    CHECK(dot(p.normal, p.ray.dir) <= 0);
  }
  CHECK(hits > 0);
}

}  // namespace

TEST_CASE("scene query: pick sees what the id AOV sees, for every camera kind", "[scene_query]") {
  LoadedScene loaded = default_scene();
  const Scene& scene = loaded.scene;
  RenderSpec spec;
  spec.width = 64;
  spec.height = 36;
  spec.spp = 4;
  spec.accel = "bvh";
  PrepareOptions o;
  o.scene_file = "default.gltf";
  const RenderView view = render_view(scene, spec, o);
  const Structure s = build_structure(scene, view.spec, false);
  SECTION("the scene's camera") {
    check_pick_against_aovs(scene, *s.accel, view.camera, view.config);
  }
  SECTION("framed from the bounds, looking down") {
    Camera c = frame_bounds(compute_bounds(scene), 64.0f / 36.0f);
    check_pick_against_aovs(scene, *s.accel, c, view.config);
  }
  SECTION("orthographic") {
    Camera c = view.camera;
    c.projection = Projection::Orthographic;
    c.ymag = 3;
    c.xmag = 3 * 64.0f / 36.0f;
    c.znear = 0;
    check_pick_against_aovs(scene, *s.accel, c, view.config);
  }
}

TEST_CASE("scene query: render_view is prepare_render's camera and image", "[scene_query]") {
  LoadedScene loaded = default_scene();
  RenderSpec spec;
  spec.width = 50;
  PrepareOptions o;
  o.scene_file = "default.gltf";
  const RenderView v = render_view(loaded.scene, spec, o);
  PreparedRender p = prepare_render(loaded, spec, o);
  CHECK(v.config.width == p.config.width);
  CHECK(v.config.height == p.config.height);
  CHECK(v.camera_index == p.camera_index);
  CHECK(v.camera.eye == p.camera.eye);
  CHECK(v.camera.w == p.camera.w);
  CHECK(v.camera.yfov == p.camera.yfov);
  finish_render(loaded, p);
}

TEST_CASE("scene query: the batches equal the single queries for any thread count", "[scene_query]") {
  LoadedScene loaded = default_scene();
  const Scene& scene = loaded.scene;
  RenderSpec spec;
  spec.accel = "bvh";
  const Structure s = build_structure(scene, spec, false);
  const SceneGeometry g = scene_geometry(scene);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3, 3);
  std::vector<Vec3f> points(300);
  std::vector<Ray> rays(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    points[i] = {u(rng), u(rng) + 1.5f, u(rng)};
    rays[i] = {points[i], 0, normalize(Vec3f{u(rng), u(rng), u(rng)} + Vec3f{0, 0, 0.01f}), kInfinity};
  }
  for (int threads : {1, 2}) {
    INFO("threads " << threads);
    std::vector<PrimitiveMatch> flat;
    std::vector<size_t> offsets;
    REQUIRE(within_batch(*s.accel, g.view(), points, 0.75f, threads, size_t(1) << 30, flat, offsets));
    REQUIRE(offsets.size() == points.size() + 1);
    size_t total = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      std::vector<PrimitiveMatch> one;
      within(*s.accel, g.view(), points[i], 0.75f, one);
      REQUIRE(offsets[i + 1] - offsets[i] == one.size());
      for (size_t j = 0; j < one.size(); ++j) {
        CHECK(flat[offsets[i] + j].geom_id == one[j].geom_id);
        CHECK(flat[offsets[i] + j].prim_id == one[j].prim_id);
        CHECK(flat[offsets[i] + j].distance == one[j].distance);
      }
      total += one.size();
    }
    REQUIRE(total > 0);
    // Past max_matches: refused, nothing returned.
    CHECK_FALSE(within_batch(*s.accel, g.view(), points, 0.75f, threads, total - 1, flat, offsets));
    CHECK(flat.empty());
    CHECK(offsets.empty());

    std::vector<Hit> hits(rays.size());
    intersect_batch(*s.accel, rays, hits, threads);
    int hit_count = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      Hit h;
      const bool hit = s.accel->intersect(rays[i], h);
      REQUIRE(hit == (hits[i].geom_id != Hit::kInvalidId));
      if (!hit) continue;
      ++hit_count;
      CHECK(hits[i].t == h.t);
      CHECK(hits[i].geom_id == h.geom_id);
      CHECK(hits[i].prim_id == h.prim_id);
    }
    CHECK(hit_count > 0);
  }
}

}  // namespace penumbra
