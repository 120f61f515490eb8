// Tests for the HitFilter queries of renderer/accel/accelerator.h: every back end, in one level
// and over instances, against brute force with the same filter and against the definition (the
// plain closest-hit query re-shot just past each rejected hit), per ray, on random triangles
// and spheres whose hits a material-free filter cuts out (a checkerboard in barycentrics, half
// of each sphere) or culls by side.
#include <catch2/catch.hpp>
#include <random>

#include "support/cross_check.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

enum class Rule { Opaque, Checker, FrontOnly };

/// The filter's world: per geom_id a rule, the world-space triangles (meshes) or the sphere's
/// centre (shapes). Decisions depend on (ray, hit) alone, as HitFilter requires.
struct FilterWorld {
  std::vector<Rule> rules;
  std::vector<std::span<const Vec3f>> positions;
  std::vector<std::span<const uint32_t>> indices;
  std::vector<bool> sphere;
  std::vector<Vec3f> centre;

  void add(Rule rule, std::span<const Vec3f> p, std::span<const uint32_t> i) {
    rules.push_back(rule), positions.push_back(p), indices.push_back(i);
    sphere.push_back(false), centre.push_back({});
  }
  void add_sphere(Rule rule, Vec3f c) {
    rules.push_back(rule), positions.emplace_back(), indices.emplace_back();
    sphere.push_back(true), centre.push_back(c);
  }

  bool accept(const Ray& ray, const Hit& hit) const {
    const Rule rule = rules[hit.geom_id];
    if (rule == Rule::Opaque) return true;
    if (sphere[hit.geom_id]) {
      const Vec3f d = ray.org + ray.dir * hit.t - centre[hit.geom_id];
      return rule == Rule::Checker ? d.y > 0 : dot(d, ray.dir) < 0;
    }
    if (rule == Rule::Checker) return (int(hit.u * 6) + int(hit.v * 6)) % 2 == 0;
    const auto& p = positions[hit.geom_id];
    const auto& i = indices[hit.geom_id];
    const size_t k = size_t(hit.prim_id) * 3;
    const Vec3f ng = cross(p[i[k + 1]] - p[i[k]], p[i[k + 2]] - p[i[k]]);
    return dot(ng, ray.dir) < 0;
  }

  static bool accept_hit(const void* context, const Ray& ray, const Hit& hit) {
    return static_cast<const FilterWorld*>(context)->accept(ray, hit);
  }
  HitFilter filter() const { return {&FilterWorld::accept_hit, this}; }
};

/// The definition of a filtered query: the closest hit re-shot just past each rejected one.
Hit reshoot(const Accelerator& accel, const Ray& ray, const FilterWorld& world) {
  Ray r = ray;
  for (int layer = 0; layer < 100000; ++layer) {
    Hit h;
    if (!accel.intersect(r, h)) return Hit{};
    if (world.accept(ray, h)) return h;
    r.tnear = std::nextafter(std::max(h.t, r.tnear), kInfinity);
  }
  FAIL("re-shooting did not end");
  return Hit{};
}

struct Disagreements {
  size_t rays = 0, hits = 0, closest = 0, occluded = 0;
};

/// `a` through the filter against `expected` per ray: hit/miss, ids and t (within kTimeEps
/// relative, or exactly when `exact`), and occluded(filter) == a hit is expected.
Disagreements compare(const Accelerator& a, const std::vector<Ray>& rays, const std::vector<Hit>& expected,
                      const FilterWorld& world, bool exact) {
  Disagreements d;
  const HitFilter filter = world.filter();
  for (size_t i = 0; i < rays.size(); ++i) {
    Hit h;
    const bool found = a.intersect(rays[i], h, filter);
    const Hit& e = expected[i];
    ++d.rays;
    d.hits += e.valid();
    bool same = found == e.valid() && h.valid() == found;
    if (same && found) {
      const float tol = exact ? 0.0f : kTimeEps * std::max(1.0f, std::fabs(e.t));
      same = h.geom_id == e.geom_id && h.prim_id == e.prim_id && std::fabs(h.t - e.t) <= tol;
    }
    if (!same) {
      ++d.closest;
      UNSCOPED_INFO("ray " << describe(rays[i]) << ": " << describe(h) << ", expected " << describe(e));
    }
    d.occluded += a.occluded(rays[i], filter) != e.valid();
  }
  return d;
}

/// Random triangles (three meshes per rule) and a unit sphere shape to place.
struct FilterScene {
  Soup soup;
  std::vector<Shape> shapes;
  std::vector<GeometryView> views;
  FilterWorld world;

  explicit FilterScene(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-3, 3), off(-1.2f, 1.2f);
    for (int m = 0; m < 9; ++m) {
      std::vector<Vec3f> p;
      std::vector<uint32_t> idx;
      for (int t = 0; t < 150; ++t) {
        const Vec3f c{pos(rng), pos(rng), pos(rng)};
        for (int k = 0; k < 3; ++k) p.push_back(c + Vec3f{off(rng), off(rng), off(rng)});
        idx.insert(idx.end(), {uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)});
      }
      soup.add(std::move(p), std::move(idx));
    }
    shapes = {sphere_shape(1)};
    views = soup.views();
    for (size_t m = 0; m < views.size(); ++m) world.add(Rule(m % 3), views[m].positions, views[m].indices);
  }
};

std::vector<Ray> filter_rays(const Bounds3f& b, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Ray> rays = random_rays(b, 6000, rng);
  const std::vector<Ray> cam = camera_rays(b, 40);
  rays.insert(rays.end(), cam.begin(), cam.end());
  return rays;
}

/// Checks every back end in `all`; returns the defined answers.
std::vector<Hit> check_filtered(const std::string& scene, const std::vector<NamedAccel>& all,
                                const Accelerator& brute, const std::vector<Ray>& rays,
                                const FilterWorld& world) {
  std::vector<Hit> defined, by_brute;
  size_t rejected = 0;
  for (const Ray& r : rays) {
    defined.push_back(reshoot(brute, r, world));
    Hit plain;
    rejected += brute.intersect(r, plain) && !(defined.back().valid() && defined.back().t == plain.t);
  }
  CHECK(rejected > rays.size() / 40);  // the filter matters for many rays
  const Disagreements db = compare(brute, rays, defined, world, true);
  INFO(scene << ": brute with the filter vs re-shooting: " << db.closest << " closest, " << db.occluded
             << " occluded of " << db.rays << " rays (" << db.hits << " hits)");
  CHECK(db.closest == 0);
  CHECK(db.occluded == 0);
  CHECK(db.hits > rays.size() / 10);
  for (const Ray& r : rays) {
    Hit h;
    brute.intersect(r, h, world.filter());
    by_brute.push_back(h);
  }
  for (const auto& a : all) {
    // Penumbra's structures run the brute-force oracle's triangle test: equal answers. Embree's
    // own test may place a hit a rounding error across a checker edge: a 1e-3 budget.
    const bool own = a.name != "embree";
    const Disagreements d = compare(*a.accel, rays, by_brute, world, own);
    INFO(scene << ": " << a.name << " with the filter vs brute with the filter: " << d.closest << " closest, "
               << d.occluded << " occluded of " << d.rays << " rays");
    const size_t budget = own ? 0 : rays.size() / 1000;
    CHECK(d.closest <= budget);
    CHECK(d.occluded <= budget);
  }
  return defined;
}

}  // namespace

TEST_CASE("accelerator: filtered queries equal re-shooting past rejected hits, every back end",
          "[accel][filter][heavy]") {
  FilterScene s(20261202u);
  s.views.push_back({{}, {}, &s.shapes[0]});  // a unit sphere at the origin, its lower half cut out
  s.world.add_sphere(Rule::Checker, {});
  const auto all = build_all(s.views);
  check_filtered("random triangles and a sphere", all, find(all, "brute"), filter_rays(bounds_of(s.views), 5),
                 s.world);
}

TEST_CASE("accelerator: filtered queries over instances see the instance index and the world ray",
          "[accel][filter][instances]") {
  FilterScene s(7u);
  const Shape implicit = sphere_shape(1, true);
  std::vector<GeometryView> meshes = s.views;
  const uint32_t sphere = uint32_t(meshes.size());
  meshes.push_back({{}, {}, &s.shapes[0]});
  meshes.push_back({{}, {}, &implicit});
  // Every mesh by the identity (the world level), meshes 0..2 placed again (rotated, scaled,
  // moved), and the two spheres placed at three points each.
  std::vector<InstanceView> instances;
  for (uint32_t m = 0; m < s.views.size(); ++m) instances.push_back({m, Affine3f{}});
  for (uint32_t m = 0; m < 3; ++m) {
    Affine3f a = translation({8.0f + 3 * float(m), 0, 0});
    a.m[0][0] = 0, a.m[0][1] = -1.5f, a.m[1][0] = 1.5f, a.m[1][1] = 0, a.m[2][2] = 1.5f;
    instances.push_back({m, a});
  }
  for (uint32_t k = 0; k < 6; ++k)
    instances.push_back({sphere + k % 2, translation({-6.0f, 3.0f * float(k) - 7.5f, float(k % 3) - 1})});
  const Flattened flat = flatten(meshes, instances);
  FilterWorld world;
  for (size_t i = 0; i < instances.size(); ++i) {
    const Rule rule = Rule(i % 3);
    if (meshes[instances[i].mesh].shape)
      world.add_sphere(rule, apply_point(instances[i].to_world, Vec3f{}));
    else
      world.add(rule, flat.views[i].positions, flat.views[i].indices);
  }
  std::vector<NamedAccel> all;
  for (const auto& n : accelerator_names()) all.push_back({n, make_accelerator(n, meshes, instances)});
  Bounds3f b = bounds_of(flat.views);
  b = merge(b, Bounds3f{{-7.5f, -9, -3}, {-4.5f, 9, 3}});
  const std::vector<Hit> defined =
      check_filtered("instances", all, find(all, "brute"), filter_rays(b, 11), world);
  size_t placed = 0, spheres = 0;
  for (const Hit& h : defined) {
    placed += h.valid() && h.geom_id >= s.views.size();
    spheres += h.valid() && world.sphere[h.geom_id];
  }
  CHECK(placed > 100);  // the placed meshes and spheres are hit, not only the world level
  CHECK(spheres > 50);
}
