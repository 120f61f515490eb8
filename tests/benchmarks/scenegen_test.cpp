// The seeded benchmark scene generators: sizes, determinism, the property each scene is meant
// to stress, and every acceleration structure cross-checked on small versions of each.
#include "benchmarks/scenegen.h"

#include <catch2/catch.hpp>
#include <cstring>

#include "io/gltf/gltf_writer.h"
#include "io/gltf/loader.h"
#include "renderer/integrators/scene_accel.h"
#include "support/cross_check.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

bool same_geometry(const Scene& a, const Scene& b) {
  if (a.meshes.size() != b.meshes.size() || a.instances.size() != b.instances.size()) return false;
  for (size_t i = 0; i < a.instances.size(); ++i)  // shapes: their placements and sizes
    if (std::memcmp(&a.instances[i].to_world, &b.instances[i].to_world, sizeof(Affine3f)) != 0) return false;
  if (a.shapes.size() != b.shapes.size()) return false;
  for (size_t i = 0; i < a.shapes.size(); ++i)
    if (a.shapes[i].shape.radius != b.shapes[i].shape.radius) return false;
  for (size_t i = 0; i < a.meshes.size(); ++i) {
    const Mesh &x = a.meshes[i], &y = b.meshes[i];
    if (x.indices != y.indices || x.positions.size() != y.positions.size()) return false;
    if (std::memcmp(x.positions.data(), y.positions.data(), x.positions.size() * sizeof(Vec3f)) != 0)
      return false;
  }
  return true;
}

Bounds3f mesh_bounds(const Mesh& m) {
  Bounds3f b;
  for (Vec3f p : m.positions) b = merge(b, p);
  return b;
}

double volume(const Bounds3f& b) {
  const Vec3f e = b.extent();
  return double(e.x) * e.y * e.z;
}

}  // namespace

TEST_CASE("scenegen: every generator meets its triangle count, is valid and is seeded", "[scenegen]") {
  for (const auto& g : bench::generators()) {
    INFO(g.name);
    const uint64_t target = 20000;
    const Scene s = bench::generate_scene(g.name, 7, target);
    // An analytic sphere stands for the 10,080 triangles its tessellated twin has.
    const uint64_t n = count_triangles(s) + 10080 * count_shape_instances(s);
    CHECK(double(n) >= 0.85 * double(target));
    CHECK(double(n) <= 1.15 * double(target));
    CHECK(!s.cameras.empty());
    CHECK(!s.lights.empty());
    for (const Mesh& m : s.meshes) {
      CHECK(m.indices.size() % 3 == 0);
      for (uint32_t i : m.indices) REQUIRE(i < m.positions.size());
      for (Vec3f p : m.positions) REQUIRE((std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)));
      CHECK(m.material >= 0);
      CHECK(size_t(m.material) < s.materials.size());
    }
    CHECK(same_geometry(s, bench::generate_scene(g.name, 7, target)));
    CHECK_FALSE(same_geometry(s, bench::generate_scene(g.name, 8, target)));
  }
}

TEST_CASE("scenegen: bad names and counts are rejected", "[scenegen]") {
  CHECK_THROWS_WITH(bench::generate_scene("sponza"), Catch::Contains("unknown generated scene 'sponza'"));
  CHECK_THROWS_WITH(bench::generate_scene("soup", 1, 10), Catch::Contains("outside [1000, 100000000]"));
  CHECK_THROWS_WITH(bench::generate_scene("soup", 1, 1ull << 40), Catch::Contains("outside"));
}

TEST_CASE("scenegen: each scene has the shape it is meant to stress", "[scenegen]") {
  SECTION("stadium: almost all triangles in a teapot that fills a tiny part of the room") {
    const Scene s = bench::generate_scene("stadium", 1, 50000);
    const Mesh& pot = s.meshes[0];
    CHECK(pot.name == "teapot");
    CHECK(double(pot.indices.size() / 3) >= 0.9 * double(count_triangles(s)));
    CHECK(volume(mesh_bounds(pot)) < 1e-6 * volume(compute_bounds(s)));
  }
  SECTION("slivers: every triangle is at least 60 m long along x and under 5 cm across") {
    const Scene s = bench::generate_scene("slivers", 1, 5000);
    const Mesh& m = s.meshes[0];
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      Bounds3f b;
      for (int k = 0; k < 3; ++k) b = merge(b, m.positions[m.indices[t + k]]);
      REQUIRE(b.extent().x >= 60);
      REQUIRE(b.extent().y <= 0.05f);
      REQUIRE(b.extent().z <= 0.05f);
    }
  }
  SECTION("soup: triangle centres fill the cube uniformly (each octant within 5% of 1/8)") {
    const Scene s = bench::generate_scene("soup", 1, 40000);
    const Mesh& m = s.meshes[0];
    int octant[8] = {};
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const Vec3f c =
          (m.positions[m.indices[t]] + m.positions[m.indices[t + 1]] + m.positions[m.indices[t + 2]]) / 3.0f;
      ++octant[(c.x > 0) + 2 * (c.y > 0) + 4 * (c.z > 0)];
    }
    for (int o : octant) CHECK(std::abs(o - 5000) < 250);
  }
  SECTION("terrain: a heightfield, so every vertical ray from above hits exactly once") {
    const Scene s = bench::generate_scene("terrain", 1, 20000);
    const auto views = mesh_views(s);
    const auto a = make_accelerator("bvh", views);
    const Bounds3f b = compute_bounds(s);
    int hits = 0;
    for (int i = 0; i < 50; ++i)
      for (int j = 0; j < 50; ++j) {
        const float x = b.lo.x + (b.hi.x - b.lo.x) * (i + 0.5f) / 50,
                    z = b.lo.z + (b.hi.z - b.lo.z) * (j + 0.5f) / 50;
        Hit h;
        hits += a->intersect({{x, b.hi.y + 1, z}, 0, {0, -1, 0}, kInfinity}, h);
      }
    CHECK(hits == 2500);
  }
}

TEST_CASE("scenegen: a generated scene survives the glTF round trip bit for bit", "[scenegen][gltf]") {
  const Scene s = bench::generate_scene("atrium", 3, 20000);
  const auto dir = temp_dir("scenegen-roundtrip");
  write_gltf(s, dir / "atrium.gltf");
  const LoadedScene l = load_gltf(dir / "atrium.gltf");
  CHECK(same_geometry(s, l.scene));
  CHECK(l.scene.cameras.size() == s.cameras.size());
  CHECK(l.scene.lights.size() == s.lights.size());
  std::filesystem::remove_all(dir);
}

TEST_CASE("scenegen: every structure agrees with brute force and Embree on each generated scene",
          "[scenegen][accel][crosscheck]") {
  for (const auto& g : bench::generators()) {
    const Scene s = bench::generate_scene(g.name, 5, 8000);
    const auto views = mesh_views(s);
    std::vector<Vec3f> lights;
    for (const auto& l : s.lights)
      if (l.type != LightType::Directional) lights.push_back(l.position);
    check_scene(g.name, views, lights);
  }
}
