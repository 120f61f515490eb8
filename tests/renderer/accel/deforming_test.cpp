// Deformation motion blur in every structure (renderer/accel/deforming.cpp under the own back
// ends, Embree's multi-step triangle geometry): a triangle moving between steps is hit where
// linear interpolation puts it at the ray's time (analytic); a deforming sphere beside a still
// plane, alone, placed by a map and carried by a moving instance, agrees ray by ray with brute
// force over the triangles interpolated at each ray's time; bad arrays are refused.
#include "renderer/accel/deforming.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/accel/factory.h"
#include "support/cross_check.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// Translation x rotation about a unit axis, as an Affine3f.
Affine3f placement(Vec3f t, Vec3f axis, double angle) {
  const double h = angle / 2, k = std::sin(h);
  return to_affine(translate(t.x, t.y, t.z) * rotate(Quat{axis.x * k, axis.y * k, axis.z * k, std::cos(h)}));
}

/// The positions of a deforming view at `time` (interpolate_vertex), mapped by `m`.
std::vector<Vec3f> posed(const GeometryView& v, float time, const Affine3f& m) {
  std::vector<Vec3f> p;
  for (size_t i = 0; i < v.positions.size(); ++i) {
    const Vec3f q = v.deforms() ? interpolate_vertex(v.motion_positions.data(), v.positions.size(),
                                                     v.motion_steps, i, time)
                                : v.positions[i];
    p.push_back(apply_point(m, q));
  }
  return p;
}

bool grazes(const Hit& h) {
  return std::min({h.u, h.v, 1 - h.u - h.v}) < 1e-3f;
}

}  // namespace

TEST_CASE("deforming meshes: a triangle is hit where its steps put it at the ray's time",
          "[accel][motion][deforming]") {
  // Three steps: z = 0 at time 0, z = 2 at time 0.5, z = 1 at time 1. A ray down -Z from z = 10
  // meets it at 10 - z(time), z piecewise linear between the steps.
  const std::vector<Vec3f> frame{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  std::vector<Vec3f> keys;
  for (const float z : {0.0f, 2.0f, 1.0f})
    for (const Vec3f& p : frame) keys.push_back({p.x, p.y, z});
  const std::vector<uint32_t> idx{0, 1, 2};
  GeometryView view{frame, idx};
  view.motion_positions = keys;
  view.motion_steps = 3;
  const std::vector<GeometryView> views{view};
  for (const auto& name : accelerator_names()) {
    INFO(name);
    const auto accel = make_accelerator(name, views);
    for (const auto& [time, z] :
         {std::pair{0.0f, 0.0f}, {0.25f, 1.0f}, {0.5f, 2.0f}, {0.75f, 1.5f}, {1.0f, 1.0f}}) {
      INFO("time " << time);
      Ray ray{{0.1f, -0.2f, 10}, 0, {0, 0, -1}, kInfinity};
      ray.time = time;
      Hit hit;
      REQUIRE(accel->intersect(ray, hit));
      CHECK(hit.t == Approx(10 - z).epsilon(1e-6));
      CHECK(hit.prim_id == 0);
      CHECK(hit.geom_id == 0);
      ray.tfar = 9.9f - z;  // just short of it
      CHECK_FALSE(accel->occluded(ray));
    }
    // Bounds over the whole shutter.
    CHECK(accel->bounds().lo.z <= 0.0f);
    CHECK(accel->bounds().hi.z >= 2.0f);
  }
}

TEST_CASE("deforming meshes: every back end against the triangles interpolated at the ray's time",
          "[accel][motion][deforming][crosscheck]") {
  // A sphere whose vertices wander at each of 4 steps, a still plane and a rising one; all in one
  // level, the sphere placed by a map, and the sphere carried by a moving instance. The oracle interpolates
  // every vertex at the ray's time, places it, and scans. One level: Penumbra's back ends test the same
  // floats, so they agree exactly; under maps, and for Embree, hits may differ by rounding on edges only.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  Soup s;
  Soup sphere = icosphere(2, 1, {0, 0, 0});
  s.add(sphere.positions[0], sphere.indices[0]);
  s.add_plane(1, -1.5f, -3.0f, 3.0f, 4);
  std::vector<Vec3f> keys;
  const uint32_t steps = 4;
  for (uint32_t k = 0; k < steps; ++k)
    for (const Vec3f& p : s.positions[0])
      keys.push_back(p + Vec3f{0.6f * float(k), 0, 0} + Vec3f{u(rng), u(rng), u(rng)} * 0.15f);
  // A second deforming mesh, a copy of the plane rising step by step, so that one structure
  // holds two (its hits name each).
  s.add(s.positions[1], s.indices[1]);
  std::vector<Vec3f> plane_keys;
  for (uint32_t k = 0; k < steps; ++k)
    for (const Vec3f& p : s.positions[2]) plane_keys.push_back(p + Vec3f{0, 0.3f * float(k), 2.0f});
  auto views = s.views();
  views[0].motion_positions = keys;
  views[0].motion_steps = steps;
  views[2].motion_positions = plane_keys;
  views[2].motion_steps = steps;
  std::vector<MotionKey> carried = make_motion_keys(
      std::vector<Affine3f>{placement({-1, 0, 0}, {0, 0, 1}, 0), placement({1, 0.5f, 0}, {0, 0, 1}, 0.8)});

  struct Setup {
    const char* name;
    std::vector<InstanceView> instances;  // empty: one level over the views
  };
  std::vector<Setup> setups{
      {"one level", {}},
      {"placed", {{0, placement({0.5f, 0.2f, -0.3f}, normalize(Vec3f{1, 1, 0}), 0.7)}, {1, {}}, {2, {}}}},
      {"carried", {{0, {}, carried}, {1, {}}, {2, {}}}}};
  for (const Setup& setup : setups) {
    std::vector<NamedAccel> all;
    for (const auto& n : accelerator_names())
      all.push_back({n, setup.instances.empty() ? make_accelerator(n, views)
                                                : make_accelerator(n, views, setup.instances)});
    int hits = 0, rays = 0;
    for (int r = 0; r < 1200; ++r) {
      Ray ray;
      ray.org = normalize(Vec3f{u(rng), u(rng), u(rng)}) * 10.0f;
      ray.dir = normalize(Vec3f{u(rng) * 2, u(rng) * 2, u(rng) * 2} - ray.org);
      ray.time = 0.5f * (u(rng) + 1);
      std::vector<std::vector<Vec3f>> placed;
      std::vector<GeometryView> world;
      if (setup.instances.empty()) {
        for (const GeometryView& v : views) placed.push_back(posed(v, ray.time, Affine3f{}));
        for (size_t i = 0; i < views.size(); ++i) world.push_back({placed[i], views[i].indices});
      } else {
        for (const InstanceView& inst : setup.instances) {
          const Affine3f m = inst.motion.empty() ? inst.to_world : interpolate_motion(inst.motion, ray.time);
          placed.push_back(posed(views[inst.mesh], ray.time, m));
        }
        for (size_t i = 0; i < setup.instances.size(); ++i)
          world.push_back({placed[i], views[setup.instances[i].mesh].indices});
      }
      const auto oracle = make_accelerator("brute", world);
      Hit want;
      const bool found = oracle->intersect(ray, want);
      ++rays;
      hits += found && want.geom_id == 0;
      const bool exact = setup.instances.empty();
      for (const NamedAccel& a : all) {
        INFO(setup.name << ": " << a.name << " ray " << r << " time " << ray.time);
        Hit got;
        const bool f = a.accel->intersect(ray, got);
        if (exact && a.name != "embree") {
          REQUIRE(f == found);
          if (found) CHECK((got.t == want.t && got.geom_id == want.geom_id && got.prim_id == want.prim_id));
          CHECK(a.accel->occluded(ray) == found);
          continue;
        }
        if (f != found) {
          CHECK(grazes(f ? got : want));
          continue;
        }
        if (!found) continue;
        CHECK(got.t == Approx(want.t).epsilon(1e-4));
        if (got.geom_id != want.geom_id || got.prim_id != want.prim_id) CHECK((grazes(got) || grazes(want)));
        CHECK(a.accel->occluded(ray));
      }
    }
    INFO(setup.name);
    CHECK(hits > rays / 10);  // the rays meet the deforming sphere often
  }
}

TEST_CASE("deforming meshes: steps that disagree with the vertices are refused",
          "[accel][motion][deforming][quick]") {
  const std::vector<Vec3f> frame{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Vec3f> short_keys(5), keys(6), three_steps(9);
  const std::vector<uint32_t> idx{0, 1, 2}, bad_idx{0, 1, 7};
  GeometryView view{frame, idx};
  const auto one = [&] { return std::span<const GeometryView>(&view, 1); };
  view.motion_positions = short_keys;
  view.motion_steps = 2;
  CHECK_THROWS_WITH(make_deforming_accelerator(one()),
                    Catch::Contains("mesh 0: 5 motion positions for 2 steps of 3 vertices"));
  view.motion_positions = keys;
  view.indices = bad_idx;
  CHECK_THROWS_WITH(make_deforming_accelerator(one()), Catch::Contains("mesh 0: index 7 out of range"));
  view.indices = idx;
  GeometryView other = view;
  other.motion_positions = three_steps;
  other.motion_steps = 3;
  const std::vector<GeometryView> mixed{view, other};
  CHECK_THROWS_WITH(make_deforming_accelerator(mixed), Catch::Contains("mesh 1 has 3 motion steps, not 2"));
  view.motion_steps = 0;
  CHECK_THROWS_WITH(make_deforming_accelerator(one()), Catch::Contains("mesh 0 has no motion steps"));
}

TEST_CASE("deforming meshes: Embree refuses steps that disagree with the vertices",
          "[accel][motion][deforming][quick]") {
  const std::vector<Vec3f> frame{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Vec3f> short_keys(5), keys(6);
  const std::vector<uint32_t> idx{0, 1, 2};
  GeometryView view{frame, idx};
  view.motion_steps = 2;
  view.motion_positions = short_keys;
  CHECK_THROWS_WITH(make_accelerator("embree", std::span<const GeometryView>(&view, 1)),
                    Catch::Contains("motion steps of all its vertices"));
  view.motion_positions = keys;
  CHECK_NOTHROW(make_accelerator("embree", std::span<const GeometryView>(&view, 1)));
}

TEST_CASE("deforming meshes: a new pose is built anew, never refitted", "[accel][motion][deforming][quick]") {
  // A triangle deforming from z = 0 to z = 1; its next pose moves it to z = 4 to 5. A refit would
  // keep the first pose's linear bounds; the rebuild must find the triangle where it now is.
  const std::vector<Vec3f> frame{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> idx{0, 1, 2};
  std::vector<Vec3f> keys;
  for (float z : {0.0f, 1.0f})
    for (const Vec3f& p : frame) keys.push_back(p + Vec3f{0, 0, z});
  GeometryView view{frame, idx};
  view.motion_steps = 2;
  view.motion_positions = keys;
  const std::vector<InstanceView> inst{{0, Affine3f{}}};
  AccelConfig config;
  std::unique_ptr<Accelerator> accel =
      make_accelerator("bvh", std::span<const GeometryView>(&view, 1), inst, config);
  double sah = accel->stats().sah_cost;
  std::vector<Vec3f> moved;
  for (const Vec3f& p : keys) moved.push_back(p + Vec3f{0, 0, 4});
  view.motion_positions = moved;
  const RefitReport r =
      refit_or_rebuild(accel, sah, "bvh", std::span<const GeometryView>(&view, 1), inst, config);
  CHECK_FALSE(r.refitted);
  CHECK(r.reason == "deforming meshes are rebuilt");
  Ray ray{{0.25f, 0.25f, 10}, 0, {0, 0, -1}, kInfinity};
  ray.time = 0.5f;
  Hit hit;
  REQUIRE(accel->intersect(ray, hit));
  CHECK(hit.t == Approx(10 - 4.5f).margin(1e-4));
}
