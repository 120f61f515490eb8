// Two-level instancing (renderer/accel/instances.cpp and Embree's instances): hits report the
// instance, t along the world ray and the object triangle's barycentrics (analytic answers);
// every back end over instances agrees with brute force over the flattened scene, and
// Penumbra's back ends agree exactly with the two-level brute force; instances moved by
// update_instances answer exactly as a fresh build over the new placements.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "renderer/accel/factory.h"
#include "support/cross_check.h"
#include "support/sdf_trees.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// Translation x rotation about a unit axis x scale, as an Affine3f.
Affine3f placement(Vec3f t, Vec3f axis, double angle, Vec3f s) {
  const double h = angle / 2, k = std::sin(h);
  const Transform m = translate(t.x, t.y, t.z) *
                      rotate(Quat{axis.x * k, axis.y * k, axis.z * k, std::cos(h)}) * scale(s.x, s.y, s.z);
  return to_affine(m);
}

Affine3f translation(Vec3f t) {
  return placement(t, {0, 0, 1}, 0, {1, 1, 1});
}

}  // namespace

TEST_CASE("instances: a hit names the instance, t runs along the world ray, u v are the object triangle's",
          "[accel][instances][quick]") {
  Soup s;
  s.add({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  const auto meshes = s.views();
  // Instance 0: the triangle in place (world level). Instance 1: scaled by 2, moved to z = -5.
  // Instance 2: scaled by 4 and mirrored in x, moved to z = -9 (behind instance 1).
  const std::vector<InstanceView> instances = {{0, Affine3f{}},
                                               {0, placement({0, 0, -5}, {0, 0, 1}, 0, {2, 2, 2})},
                                               {0, placement({0, 0, -9}, {0, 0, 1}, 0, {-4, 4, 4})}};
  for (const auto& name : accelerator_names()) {
    INFO(name);
    const auto a = make_accelerator(name, meshes, instances);
    // Object point (0.25, 0.25) of instance 1 is world (0.5, 0.5, -5); the direction is not unit,
    // so t = 5 / 2.
    Hit h;
    REQUIRE(a->intersect({{0.5f, 0.5f, 1e-3f}, 0.01f, {0, 0, -2}, kInfinity}, h));
    CHECK(h.geom_id == 1);
    CHECK(h.prim_id == 0);
    CHECK(h.t == Approx((5 + 1e-3) / 2).epsilon(1e-6));
    CHECK(h.u == Approx(0.25).epsilon(1e-5));
    CHECK(h.v == Approx(0.25).epsilon(1e-5));
    // x < 0 is only covered by the mirrored instance: object (0.25, 0.5) at world (-1, 2, -9).
    REQUIRE(a->intersect({{-1, 2, 1}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.geom_id == 2);
    CHECK(h.t == Approx(10).epsilon(1e-6));
    CHECK(h.u == Approx(0.25).epsilon(1e-5));
    CHECK(h.v == Approx(0.5).epsilon(1e-5));
    // Segments: ending before instance 2, and occlusion along the same rays.
    CHECK_FALSE(a->intersect({{-1, 2, 1}, 0, {0, 0, -1}, 9.9f}, h));
    CHECK_FALSE(a->occluded({{-1, 2, 1}, 0, {0, 0, -1}, 9.9f}));
    CHECK(a->occluded({{-1, 2, 1}, 0, {0, 0, -1}, 10.1f}));
    // The world-level triangle in front of everything.
    REQUIRE(a->intersect({{0.1f, 0.1f, 1}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.geom_id == 0);
    CHECK(h.t == Approx(1));
    const AccelStats st = a->stats();
    CHECK(st.instances == 2);
    CHECK(st.triangles == 2);  // the world copy and the shared object mesh
    CHECK(a->bounds().lo.x == Approx(-4).margin(1e-5));
    CHECK(a->bounds().lo.z == Approx(-9).margin(1e-5));
  }
}

TEST_CASE("instances: identity placements build one level; bad instances are refused or never hit",
          "[accel][instances][quick]") {
  const Soup s = icosphere(1, 1, {0, 0, 0});
  const auto meshes = s.views();
  for (const auto& name : accelerator_names()) {
    INFO(name);
    // Identity only: the single-level structure, one geom_id per instance (the mesh twice).
    const auto flat = make_accelerator(name, meshes, std::vector<InstanceView>{{0, {}}, {0, {}}});
    CHECK(flat->stats().instances == 0);
    Hit h;
    REQUIRE(flat->intersect({{0, 0, 5}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.geom_id <= 1);
    // A singular placement (zero scale) is left out; the other instance still answers.
    const std::vector<InstanceView> bad = {{0, placement({0, 0, 0}, {0, 0, 1}, 0, {0, 1, 1})},
                                           {0, translation({3, 0, 0})}};
    const auto a = make_accelerator(name, meshes, bad);
    CHECK_FALSE(a->intersect({{0, 0, 5}, 0, {0, 0, -1}, kInfinity}, h));
    REQUIRE(a->intersect({{3, 0, 5}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.geom_id == 1);
    CHECK(h.t == Approx(4).epsilon(1e-6));  // the icosphere has a vertex at (0, 0, 1)
    // An instance of a mesh that does not exist.
    CHECK_THROWS_AS(make_accelerator(name, meshes, std::vector<InstanceView>{{1, {}}}),
                    std::invalid_argument);
  }
}

TEST_CASE("instances: every back end agrees with brute force over the flattened scene",
          "[accel][instances][crosscheck]") {
  Soup s;
  Soup sphere = icosphere(2, 1, {0, 0, 0});
  s.add(sphere.positions[0], sphere.indices[0]);                 // mesh 0: sphere (320 triangles)
  s.add_plane(1, 0.0f, -1.0f, 1.0f, 4);                          // mesh 1: a 2 x 2 plane in y = 0
  s.add({{0, 0, 0}, {0.3f, 0, 0}, {0, 0.3f, 0.1f}}, {0, 1, 2});  // mesh 2: one small triangle
  const auto meshes = s.views();
  std::vector<InstanceView> instances = {
      {0, Affine3f{}},                                                          // in place
      {0, placement({4, 0, 0}, normalize(Vec3f{1, 2, 3}), 0.7, {1, 0.5f, 2})},  // rotated, non-uniform
      {0, placement({-4, 1, 0}, {0, 1, 0}, 0.3, {-1, 1, 1})},                   // mirrored
      {1, Affine3f{}},                                                          // the plane in place
      {1, placement({0, -2, 0}, {1, 0, 0}, 0.2, {10, 1, 10})},                  // a big floor
      {1, placement({0, 0, -3}, {1, 0, 0}, kPi / 2, {3, 1, 3})},                // a wall
  };
  // A cloud of 300 small triangles (the top level's depth), some interpenetrating.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 300; ++i)
    instances.push_back(
        {2, placement({u(rng) * 3, 2 + u(rng), u(rng) * 3}, normalize(Vec3f{u(rng), u(rng), u(rng) + 2}),
                      u(rng) * 3, {1 + u(rng) * 0.5f, 1, 1 + u(rng) * 0.5f})});
  instances.push_back({0, placement({9, 9, 9}, {0, 0, 1}, 0, {0, 0, 0})});  // singular: never hit
  check_instanced("instances", meshes, instances, {});
}

TEST_CASE("instances: update_instances moves the placements and answers as a fresh build does",
          "[accel][instances][quick]") {
  Soup s;
  Soup sphere = icosphere(2, 1, {0, 0, 0});
  s.add(sphere.positions[0], sphere.indices[0]);                 // mesh 0: sphere
  s.add_plane(1, 0.0f, -1.0f, 1.0f, 4);                          // mesh 1: a 2 x 2 plane in y = 0
  s.add({{0, 0, 0}, {0.3f, 0, 0}, {0, 0.3f, 0.1f}}, {0, 1, 2});  // mesh 2: one small triangle
  const Shape ball = analytic_shape(ShapeKind::Sphere, 0.4f);
  std::vector<GeometryView> meshes = s.views();
  meshes.push_back({{}, {}, &ball});  // view 3: a shape
  // Instances moved from frame to frame: every kind of placement, with the identity kept as
  // the identity and a singular map kept singular.
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(-1, 1);
  const auto frame = [&](int f) {
    const float k = 0.3f * float(f);
    std::vector<InstanceView> out = {
        {0, Affine3f{}},
        {0, placement({4 + k, 0, k}, normalize(Vec3f{1, 2, 3}), 0.7 + k, {1, 0.5f, 2})},
        {0, placement({-4, 1 - k, 0}, {0, 1, 0}, 0.3, {-1, 1, 1 + k})},
        {1, placement({0, -2, 0}, {1, 0, 0}, 0.2 * k, {10, 1, 10})},
        {3, placement({k, 3, -k}, {0, 0, 1}, 0, {1, 1 + k, 1})},
        {3, Affine3f{}},
        {0, placement({9, 9, 9}, {0, 0, 1}, 0, {0, 0, 0})},  // singular
    };
    for (int i = 0; i < 200; ++i)
      out.push_back({2, placement({u(rng) * 3, 2 + u(rng), u(rng) * 3}, normalize(Vec3f{u(rng), u(rng), 2}),
                                  u(rng) * 3, {1 + u(rng) * 0.5f, 1, 1})});
    return out;
  };
  const std::vector<InstanceView> first = frame(0);
  // Every back end, and Embree with its identity placements in a scene of their own.
  std::vector<std::pair<std::string, AccelConfig>> builds;
  for (const auto& name : accelerator_names()) builds.push_back({name, {}});
  builds.push_back({"embree", {}});
  builds.back().second.embree.world_apart = true;
  for (const auto& [name, config] : builds) {
    INFO(name << (config.embree.world_apart ? " (identity placements apart)" : ""));
    const auto moved = make_accelerator(name, meshes, first, config);
    for (int f = 1; f <= 3; ++f) {
      INFO("frame " << f);
      const std::vector<InstanceView> next = frame(f);
      REQUIRE(moved->update_instances(next));
      const auto fresh = make_accelerator(name, meshes, next, config);
      CHECK(moved->bounds().lo == fresh->bounds().lo);
      CHECK(moved->bounds().hi == fresh->bounds().hi);
      std::mt19937 ray_rng(100 + f);
      int hits = 0;
      for (const Ray& r : random_rays(fresh->bounds(), 4000, ray_rng)) {
        Hit a, b;
        const bool ha = moved->intersect(r, a), hb = fresh->intersect(r, b);
        INFO(describe(r) << ": moved " << describe(a) << ", fresh " << describe(b));
        REQUIRE(ha == hb);
        REQUIRE(moved->occluded(r) == fresh->occluded(r));
        if (!ha) continue;
        ++hits;
        REQUIRE(a.t == b.t);
        REQUIRE(a.geom_id == b.geom_id);
        REQUIRE(a.prim_id == b.prim_id);
        REQUIRE(a.u == b.u);
        REQUIRE(a.v == b.v);
      }
      CHECK(hits > 400);
    }
    // Another count, mesh or kind is refused and leaves the structure as it was.
    std::vector<InstanceView> other = frame(4);
    const std::vector<InstanceView> shorter(other.begin(), other.end() - 1);
    CHECK_FALSE(moved->update_instances(shorter));
    std::vector<InstanceView> remeshed = other;
    remeshed[1].mesh = 1;
    CHECK_FALSE(moved->update_instances(remeshed));
    std::vector<InstanceView> to_identity = other;
    to_identity[1].to_world = Affine3f{};
    CHECK_FALSE(moved->update_instances(to_identity));
    std::vector<InstanceView> from_identity = other;
    from_identity[0].to_world = translation({1, 0, 0});
    CHECK_FALSE(moved->update_instances(from_identity));
    std::vector<InstanceView> unsingular = other;
    unsingular[6].to_world = translation({9, 9, 9});
    CHECK_FALSE(moved->update_instances(unsingular));
  }
  // A build in one level (every placement the identity) may refuse; a rebuild is the answer.
  const std::vector<InstanceView> flat = {{0, Affine3f{}}, {1, Affine3f{}}};
  for (const auto& name : accelerator_names()) {
    INFO(name);
    const auto a = make_accelerator(name, meshes, flat);
    const std::vector<InstanceView> moved = {{0, translation({1, 0, 0})}, {1, Affine3f{}}};
    CHECK_FALSE(a->update_instances(moved));
  }
}

TEST_CASE("instances: refit_instances moves vertices and placements and answers as a fresh build does",
          "[accel][instances][refit]") {
  Soup s;
  Soup sphere = icosphere(2, 1, {0, 0, 0});
  s.add(sphere.positions[0], sphere.indices[0]);  // mesh 0: sphere, placed three times
  s.add_plane(1, 0.0f, -1.0f, 1.0f, 4);           // mesh 1: a plane, in world space
  const Shape ball = analytic_shape(ShapeKind::Sphere, 0.4f);
  const auto frame = [&](int f, Soup& moved, Shape& shape) {
    const float k = 0.25f * float(f);
    moved = s;
    for (Vec3f& p : moved.positions[0]) p = p * (1 + k * p.y);  // the sphere bulges upwards
    for (Vec3f& p : moved.positions[1]) p.y = k * p.x * p.z;    // the plane bends
    shape = analytic_shape(ShapeKind::Sphere, 0.4f + k);
    std::vector<GeometryView> meshes = moved.views();
    meshes.push_back({{}, {}, &shape});
    std::vector<InstanceView> inst = {{0, placement({k + 0.5f, 0, 0}, {0, 1, 0}, k, {1, 1, 1})},
                                      {0, placement({3, 1, -k}, {1, 0, 0}, 0.5, {0.5f, 1, 2})},
                                      {1, Affine3f{}},
                                      {2, placement({-2, k, 0}, {0, 0, 1}, 0, {1, 2, 1})}};
    return std::pair{meshes, inst};
  };
  Soup m0;
  Shape b0;
  const auto [meshes0, inst0] = frame(0, m0, b0);
  const auto bvh = make_accelerator("bvh", meshes0, inst0);
  for (int f = 1; f <= 3; ++f) {
    INFO("frame " << f);
    Soup mf;
    Shape bf;
    const auto [meshes, inst] = frame(f, mf, bf);
    REQUIRE(bvh->refit_instances(meshes, inst));
    const auto fresh = make_accelerator("brute", meshes, inst);
    CHECK(bvh->bounds().lo == fresh->bounds().lo);
    CHECK(bvh->bounds().hi == fresh->bounds().hi);
    std::mt19937 ray_rng(200 + f);
    int hits = 0;
    for (const Ray& r : random_rays(fresh->bounds(), 4000, ray_rng)) {
      Hit a, b;
      const bool ha = bvh->intersect(r, a), hb = fresh->intersect(r, b);
      INFO(describe(r) << ": refitted " << describe(a) << ", brute force " << describe(b));
      REQUIRE(ha == hb);
      REQUIRE(bvh->occluded(r) == fresh->occluded(r));
      if (!ha) continue;
      ++hits;
      REQUIRE(a.t == b.t);
      REQUIRE(a.geom_id == b.geom_id);
    }
    CHECK(hits > 400);
  }
  // Another instance layout is refused.
  Soup mf;
  Shape bf;
  auto [meshes, inst] = frame(4, mf, bf);
  inst[2].to_world = placement({0, 1, 0}, {0, 1, 0}, 0, {1, 1, 1});  // the identity became a placement
  CHECK_FALSE(bvh->refit_instances(meshes, inst));
}

TEST_CASE("refit_or_rebuild: refits the BVH while its SAH cost holds, rebuilds past the threshold",
          "[accel][instances][refit][quick]") {
  Soup s = icosphere(2, 1, {0, 0, 0});
  s.add_plane(1, -1.0f, -2.0f, 2.0f, 6);
  const std::vector<InstanceView> inst = {{0, Affine3f{}}, {1, Affine3f{}}};
  std::unique_ptr<Accelerator> accel = make_accelerator("bvh", s.views(), inst);
  double built = accel->stats().sah_cost;
  const Accelerator* first = accel.get();
  // A small motion: refitted in place.
  Soup moved = s;
  for (Vec3f& p : moved.positions[0]) p = p + Vec3f{0.1f, 0, 0};
  RefitReport r = refit_or_rebuild(accel, built, "bvh", moved.views(), inst);
  CHECK(r.refitted);
  CHECK(r.reason.empty());
  CHECK(r.growth == Approx(1).epsilon(0.05));
  CHECK(accel.get() == first);
  // Vertices scrambled among themselves: the cost explodes, the structure is built anew.
  Soup scrambled = s;
  std::mt19937 rng(3);
  std::shuffle(scrambled.positions[0].begin(), scrambled.positions[0].end(), rng);
  r = refit_or_rebuild(accel, built, "bvh", scrambled.views(), inst);
  CHECK_FALSE(r.refitted);
  CHECK(r.growth > 1.5);
  CHECK_THAT(r.reason, Catch::Contains("SAH cost grew") && Catch::Contains("bvh.refit_max_growth 1.5"));
  CHECK(built == Approx(accel->stats().sah_cost));
  // Either way the answers are brute force's.
  const auto brute = make_accelerator("brute", scrambled.views(), inst);
  std::mt19937 ray_rng(9);
  for (const Ray& ray : random_rays(brute->bounds(), 2000, ray_rng)) {
    Hit a, b;
    REQUIRE(accel->intersect(ray, a) == brute->intersect(ray, b));
    if (a.valid()) REQUIRE(a.t == b.t);
  }
  // Refitting off, another back end, another layout: built anew, saying why.
  AccelConfig off;
  off.bvh.refit_max_growth = 0;
  CHECK_THAT(refit_or_rebuild(accel, built, "bvh", s.views(), inst, off).reason,
             Catch::Contains("refitting is off"));
  std::unique_ptr<Accelerator> kd = make_accelerator("kdtree", s.views(), inst);
  double kd_sah = 0;
  r = refit_or_rebuild(kd, kd_sah, "kdtree", moved.views(), inst);
  CHECK_FALSE(r.refitted);
  CHECK_THAT(r.reason, Catch::Contains("the kdtree back end does not refit"));
  const std::vector<InstanceView> one = {{0, Affine3f{}}};
  CHECK_THAT(refit_or_rebuild(accel, built, "bvh", s.views(), one).reason, Catch::Contains("layout changed"));
  // Bad configuration values are errors.
  AccelConfig bad;
  bad.bvh.refit_max_growth = 0.5f;
  CHECK_THROWS_WITH(make_accelerator("bvh", s.views(), bad),
                    Catch::Contains("refit_max_growth must be 0 or in [1, 1000], got 0.5"));
}

TEST_CASE("instances: moving instances, every back end against the triangles placed at the ray's time",
          "[accel][instances][motion][crosscheck]") {
  // Spheres and planes, some moving (translation, a turn of up to 1.5 radians, scale), some
  // still; random rays, each at its own time. The oracle places every triangle at that time
  // (interpolate_motion) and scans them all; each back end must agree ray by ray, Embree through
  // its own quaternion motion blur. Hits that graze an edge (a barycentric within 1e-3) may
  // differ by rounding; no other answer may.
  Soup s;
  Soup sphere = icosphere(2, 1, {0, 0, 0});
  s.add(sphere.positions[0], sphere.indices[0]);
  s.add_plane(1, 0.0f, -1.0f, 1.0f, 4);
  const auto meshes = s.views();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1, 1);
  std::vector<std::vector<MotionKey>> motion;
  std::vector<InstanceView> instances;
  for (int i = 0; i < 12; ++i) {
    const Vec3f at{u(rng) * 4, u(rng) * 4, u(rng) * 4};
    instances.push_back({uint32_t(i % 2), placement(at, {0, 0, 1}, 0, {1, 1, 1})});
    if (i % 3 == 0) continue;  // still
    std::vector<Affine3f> maps;
    for (int k = 0; k < 3; ++k)
      maps.push_back(placement(at + Vec3f{u(rng), u(rng), u(rng)} * float(k),
                               normalize(Vec3f{u(rng), u(rng), 1}), 0.75 * k * u(rng),
                               {1 + 0.3f * u(rng), 1 + 0.3f * u(rng), 1}));
    motion.push_back(make_motion_keys(maps));
  }
  for (size_t i = 0, m = 0; i < instances.size(); ++i)
    if (i % 3 != 0) instances[i].motion = motion[m++];
  std::vector<NamedAccel> all;
  for (const auto& n : accelerator_names()) all.push_back({n, make_accelerator(n, meshes, instances)});
  int rays = 0, hits = 0;
  for (int r = 0; r < 1500; ++r) {
    Ray ray;
    ray.org = normalize(Vec3f{u(rng), u(rng), u(rng)}) * 12.0f;
    ray.dir = normalize(Vec3f{u(rng) * 4, u(rng) * 4, u(rng) * 4} - ray.org);
    ray.time = 0.5f * (u(rng) + 1);
    // The oracle: every instance's triangles placed at the ray's time, scanned.
    std::vector<std::vector<Vec3f>> placed;
    std::vector<GeometryView> world;
    for (const InstanceView& inst : instances) {
      const Affine3f m = inst.motion.empty() ? inst.to_world : interpolate_motion(inst.motion, ray.time);
      std::vector<Vec3f> p;
      for (const Vec3f& v : meshes[inst.mesh].positions) p.push_back(apply_point(m, v));
      placed.push_back(std::move(p));
    }
    for (size_t i = 0; i < instances.size(); ++i)
      world.push_back({placed[i], meshes[instances[i].mesh].indices});
    const auto oracle = make_accelerator("brute", world);
    Hit want;
    const bool found = oracle->intersect(ray, want);
    ++rays;
    hits += found;
    const auto grazes = [](const Hit& h) { return std::min({h.u, h.v, 1 - h.u - h.v}) < 1e-3f; };
    for (const NamedAccel& a : all) {
      Hit got;
      const bool f = a.accel->intersect(ray, got);
      if (f != found) {
        INFO(a.name << " ray " << r << " time " << ray.time);
        CHECK(grazes(f ? got : want));
        continue;
      }
      if (!found) continue;
      INFO(a.name << " ray " << r << " time " << ray.time);
      CHECK(got.t == Approx(want.t).epsilon(1e-4));
      if (got.geom_id != want.geom_id || got.prim_id != want.prim_id) CHECK((grazes(got) || grazes(want)));
      CHECK(a.accel->occluded(ray));
    }
  }
  CHECK(hits > rays / 4);  // the rays meet the moving spheres and planes often
}

TEST_CASE("instances: a moving instance's top-level box follows the ray's time",
          "[accel][instances][motion]") {
  // A sphere of radius 0.5 sliding from x = -10 to x = 10 over the shutter beside a still one at
  // y = 5: a ray at time 0 straight down onto x = 10 meets no top-level box of its time (one
  // node visited, no bottom level entered), while the same ray at time 1 hits the sphere there.
  Soup s;
  Soup sphere = icosphere(2, 0.5f, {0, 0, 0});
  s.add(sphere.positions[0], sphere.indices[0]);
  const auto meshes = s.views();
  const std::vector<MotionKey> slide =
      make_motion_keys(std::vector<Affine3f>{translation({-10, 0, 0}), translation({10, 0, 0})});
  std::vector<InstanceView> instances = {{0, translation({-10, 0, 0})}, {0, translation({0, 5, 0})}};
  instances[0].motion = slide;
  for (const auto& name : accelerator_names()) {
    const auto accel = make_accelerator(name, meshes, instances);
    if (!accel->counts_traversal()) continue;  // Embree counts no nodes
    INFO(name);
    Ray ray;
    ray.org = {10, 0, 5};
    ray.dir = {0, 0, -1};
    ray.time = 0;
    Hit hit;
    TraversalCost cost;
    CHECK_FALSE(accel->intersect_counted(ray, hit, cost));
    CHECK(cost.nodes == 1);
    ray.time = 1;
    REQUIRE(accel->intersect(ray, hit));
    CHECK(hit.geom_id == 0);
    CHECK(hit.t == Approx(4.5).epsilon(0.02));
  }
}
