// Tests for renderer/accel: Embree and brute force answer every ray alike (per-ray cross-check),
// bad rays miss, empty scenes work. The full suite of structures comes with the reference
// accelerators; this checks the two back ends the renderer has today.
#include "renderer/accel/accelerator.h"

#include <catch2/catch.hpp>
#include <random>

#include "io/gltf_loader.h"
#include "renderer/camera.h"
#include "test_util.h"

using namespace penumbra;

namespace {

struct Mismatch {
  int hit_miss = 0, t = 0, prim = 0, occlusion = 0;
};

Mismatch cross_check(const Accelerator& a, const Accelerator& b, const std::vector<Ray>& rays) {
  Mismatch m;
  for (const Ray& r : rays) {
    Hit ha, hb;
    const bool a_hit = a.intersect(r, ha), b_hit = b.intersect(r, hb);
    if (a_hit != b_hit) {
      ++m.hit_miss;
      continue;
    }
    if (a_hit) {
      const float eps = 1e-5f * std::max(1.0f, std::max(ha.t, hb.t));
      if (std::fabs(ha.t - hb.t) > eps) ++m.t;
      else if ((ha.geom_id != hb.geom_id || ha.prim_id != hb.prim_id) && std::fabs(ha.t - hb.t) > 1e-7f * ha.t) ++m.prim;
    }
    if (a.occluded(r) != a_hit) ++m.occlusion;
    if (b.occluded(r) != b_hit) ++m.occlusion;
  }
  return m;
}

}  // namespace

TEST_CASE("embree and brute force agree per ray on the default scene", "[accel]") {
  const LoadedScene loaded = load_gltf(test::source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(loaded.scene);
  const auto embree = make_accelerator("embree", views);
  const auto brute = make_accelerator("brute", views);
  CHECK(embree->stats().triangles == brute->stats().triangles);

  std::vector<Ray> rays;
  const Camera& cam = loaded.scene.cameras.at(0);
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < 64; ++x) rays.push_back(generate_camera_ray(cam, 64, 36, x + 0.5f, y + 0.5f));
  std::mt19937 rng(1234);
  std::uniform_real_distribution<float> u(-3.2f, 3.6f), d(-1, 1);
  for (int i = 0; i < 2000; ++i) {
    Ray r{{u(rng), std::fabs(u(rng)), u(rng)}, 0, normalize(Vec3f{d(rng), d(rng), d(rng)}), kInfinity};
    if (i % 4 == 0) r.tfar = 0.5f;  // bounded segments, as shadow rays are
    rays.push_back(r);
  }
  const Mismatch m = cross_check(*embree, *brute, rays);
  CHECK(m.hit_miss == 0);
  CHECK(m.t == 0);
  CHECK(m.prim == 0);
  CHECK(m.occlusion == 0);

  // Bounds agree and enclose the room (6 x 3.5 x 6).
  const Bounds3f be = embree->bounds(), bb = brute->bounds();
  CHECK(be.lo.x == Approx(bb.lo.x));
  CHECK(be.hi.y == Approx(bb.hi.y));
  CHECK(bb.hi.y == Approx(3.5f));
}

TEST_CASE("NaN, infinite and zero-direction rays miss in every back end", "[accel][quick]") {
  const std::vector<Vec3f> pos{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2};
  const TriangleMeshView view{pos, idx};
  for (const auto& name : accelerator_names()) {
    const auto accel = make_accelerator(name, std::span(&view, 1));
    const float nan = std::nanf("");
    for (const Ray& r : {Ray{{0, 0, 1}, 0, {nan, 0, -1}, kInfinity}, Ray{{nan, 0, 1}, 0, {0, 0, -1}, kInfinity},
                         Ray{{0, 0, 1}, 0, {0, 0, 0}, kInfinity}, Ray{{0, 0, 1}, 0, {kInfinity, 0, -1}, kInfinity},
                         Ray{{0, 0, 1}, nan, {0, 0, -1}, kInfinity}}) {
      Hit h;
      CHECK_FALSE(accel->intersect(r, h));
      CHECK_FALSE(accel->occluded(r));
    }
    Hit h;  // and a sane ray still hits at t = 1
    REQUIRE(accel->intersect({{0, 0, 1}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.t == Approx(1));
    CHECK(h.prim_id == 0);
    CHECK(h.geom_id == 0);
  }
}

TEST_CASE("empty scenes build and miss", "[accel][quick]") {
  for (const auto& name : accelerator_names()) {
    const auto accel = make_accelerator(name, {});
    Hit h;
    CHECK_FALSE(accel->intersect({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}, h));
    CHECK_FALSE(accel->occluded({{0, 0, 0}, 0, {0, 0, 1}, kInfinity}));
    CHECK(accel->stats().triangles == 0);
  }
  CHECK_THROWS_AS(make_accelerator("octree-of-dreams", {}), std::invalid_argument);
}
