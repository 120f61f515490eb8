// The accelerator cross-check: every back end against the brute-force oracle and
// against Embree, per ray, on synthetic edge cases, the project's default scene and every valid
// corpus model; watertightness from inside a closed sphere; and the default scene rendered with
// every back end. The [.slow] variants run many more rays outside CI:
//   renderer_tests "[slow]"
#include "support/cross_check.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <filesystem>
#include <map>

#include "io/gltf/loader.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/scene.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

std::vector<Vec3f> light_positions(const Scene& s) {
  std::vector<Vec3f> out;
  for (const auto& l : s.lights)
    if (l.type != LightType::Directional) out.push_back(l.position);
  return out;
}

/// Axis-parallel rays on the lines x, y in {lo, lo + step, ...} along +z and -z (and the other
/// two axes): they run through vertices, along edges and inside the planes of walls.
std::vector<Ray> lattice_rays(float lo, float hi, float step) {
  std::vector<Ray> rays;
  for (int axis = 0; axis < 3; ++axis)
    for (float a = lo; a <= hi; a += step)
      for (float b = lo; b <= hi; b += step)
        for (float sign : {1.0f, -1.0f}) {
          Vec3f o, d;
          o[axis] = sign > 0 ? lo - 1 : hi + 1;
          o[(axis + 1) % 3] = a;
          o[(axis + 2) % 3] = b;
          d[axis] = sign;
          rays.push_back({o, 0, d, kInfinity});
        }
  return rays;
}

}  // namespace

// ---- Synthetic scenes ---------------------------------------------------------------------------

TEST_CASE("cross-check: empty scene", "[accel][crosscheck]") {
  Soup s;
  s.add({}, {});  // one empty mesh, and no meshes at all
  check_scene("empty mesh", s.views(), {});
  check_scene("no meshes", {}, {});
}

TEST_CASE("cross-check: one triangle, hit in the middle, on edges and on vertices", "[accel][crosscheck]") {
  Soup s;
  s.add({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  std::vector<Ray> extra;
  for (Vec3f target : {Vec3f{0.25f, 0.25f, 0}, Vec3f{0.5f, 0, 0}, Vec3f{0, 0.5f, 0}, Vec3f{0.5f, 0.5f, 0},
                       Vec3f{0, 0, 0}, Vec3f{1, 0, 0}, Vec3f{0, 1, 0}})
    for (Vec3f from : {Vec3f{0, 0, 1}, Vec3f{0, 0, -1}, Vec3f{0.3f, -0.2f, 1}})
      extra.push_back({target + from, 0, normalize(-from), kInfinity});
  check_scene("one triangle", s.views(), {}, 1, extra);
  // Known answers: t = 1 straight down onto the interior, u, v the barycentrics of b, c.
  for (const auto& a : build_all(s.views())) {
    Hit h;
    REQUIRE(a.accel->intersect({{0.25f, 0.5f, 1}, 0, {0, 0, -1}, kInfinity}, h));
    CHECK(h.t == Approx(1).epsilon(1e-6));
    CHECK(h.u == Approx(0.25f).epsilon(1e-5));
    CHECK(h.v == Approx(0.5f).epsilon(1e-5));
    CHECK_FALSE(a.accel->intersect({{0.25f, 0.5f, 1}, 0, {0, 0, -1}, 0.999f}, h));    // segment stops short
    CHECK_FALSE(a.accel->intersect({{0.25f, 0.5f, 1}, 0, {0, 0, 1}, kInfinity}, h));  // facing away
  }
}

TEST_CASE("cross-check: degenerate and zero-area triangles", "[accel][crosscheck]") {
  Soup s;
  s.add({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, 2}, {3, 3, 3}, {0.5f, 0.5f, 0.5f}, {0, 0, 1}, {1, 0, 1}},
        {3, 3, 3,    // a point
         3, 4, 4,    // two equal vertices
         0, 3, 4,    // collinear (0,0,0)-(2,2,2)-(3,3,3)
         0, 1, 2,    // a real triangle
         5, 5, 3,    // another point-segment
         6, 7, 6,    // a segment in z = 1
         0, 1, 2});  // the real one again (a tie)
  check_scene("degenerate", s.views(), {});
}

TEST_CASE("cross-check: coplanar, overlapping and interpenetrating triangles", "[accel][crosscheck]") {
  Soup s;
  for (int i = 0; i < 4; ++i) s.add_plane(2, 0.0f, 0.0f, 1.0f, 3);  // identical stacked planes
  s.add_plane(2, 0.0f, 0.5f, 1.5f, 4);                              // overlapping, offset
  s.add({{0.2f, 0.2f, -0.5f}, {0.8f, 0.8f, 0.5f}, {0.2f, 0.8f, 0.5f}}, {0, 1, 2});  // through the plane
  s.add({{0.2f, 0.2f, 0.5f}, {0.8f, 0.8f, -0.5f}, {0.8f, 0.2f, -0.5f}}, {0, 1, 2});
  check_scene("coplanar", s.views(), {}, 1, lattice_rays(-0.5f, 1.5f, 0.25f));
}

TEST_CASE("cross-check: axis-aligned walls on split planes, axis-parallel rays through edges and vertices",
          "[accel][crosscheck]") {
  Soup s;
  for (int axis = 0; axis < 3; ++axis)
    for (int i = 0; i <= 4; ++i) s.add_plane(axis, float(i), 0.0f, 4.0f, 4);  // a 4^3 lattice of cubes
  std::vector<Ray> extra = lattice_rays(0.0f, 4.0f, 0.5f);
  // Diagonals through lattice vertices.
  for (Vec3f o : {Vec3f{-1, -1, -1}, Vec3f{5, -1, -1}, Vec3f{0.5f, -1, 0.5f}})
    extra.push_back({o, 0, normalize(Vec3f{2, 2, 2} - o), kInfinity});
  // Rays from inside cells towards walls, ending exactly on them.
  extra.push_back({{0.5f, 0.5f, 0.5f}, 0, {1, 0, 0}, 0.5f});
  extra.push_back({{0.5f, 0.5f, 0.5f}, 0, {0, -1, 0}, 0.5f});
  check_scene("walls", s.views(), {}, 1, extra);
}

TEST_CASE("cross-check: a tessellated plane, rays through vertices, along edges and starting on it",
          "[accel][crosscheck]") {
  Soup s;
  s.add_plane(1, 0.0f, -4.0f, 4.0f, 8);
  std::vector<Ray> extra;
  for (float x = -4; x <= 4; x += 0.5f)
    for (float z = -4; z <= 4; z += 0.5f) {
      extra.push_back({{x, 1, z}, 0, {0, -1, 0}, kInfinity});                        // vertices, edges
      extra.push_back({{x, 0, z}, 0, {0, 1, 0}, kInfinity});                         // starts on the plane
      extra.push_back({{x, 0, z}, 0, normalize(Vec3f{0.3f, -1, 0.2f}), kInfinity});  // into it
      extra.push_back(
          {{x - 0.5f, 1, z - 0.5f}, 0, normalize(Vec3f{0.5f, -1, 0.5f}), kInfinity});  // diagonals
    }
  for (float z = -4; z <= 4; z += 1) extra.push_back({{-5, 0, z}, 0, {1, 0, 0}, kInfinity});  // in the plane
  check_scene("plane", s.views(), {}, 1, extra);
}

TEST_CASE("cross-check: huge and tiny coordinates", "[accel][crosscheck]") {
  struct Variant {
    float scale;
    Vec3f offset;
  };
  for (const Variant& v :
       {Variant{1e-6f, {0, 0, 0}}, Variant{1e-6f, {1e-6f, 2e-6f, 0}}, Variant{1, {1e-6f, 0, 0}},
        Variant{1, {1e3f, -1e3f, 1e3f}}, Variant{1, {1e6f, 0, 1e6f}}, Variant{1e6f, {0, 0, 0}},
        Variant{1e6f, {1e6f, 1e6f, 1e6f}}}) {
    const Soup s = icosphere(2, v.scale, v.offset);
    char name[96];
    std::snprintf(name, sizeof name, "sphere scale %g offset (%g, %g, %g)", v.scale, v.offset.x, v.offset.y,
                  v.offset.z);
    check_scene(name, s.views(), {});
  }
}

TEST_CASE("cross-check: rays from inside a closed sphere always hit (watertightness)",
          "[accel][crosscheck]") {
  const Soup s = icosphere(4, 1.0f, {0.1f, -0.2f, 0.3f});  // 5120 triangles
  const auto views = s.views();
  const auto all = build_all(views);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.9f, 0.9f);
  std::vector<Ray> rays;
  for (int i = 0; i < 100000; ++i) {
    // Half from the centre, half from random points well inside (|p - c| < 0.9; the
    // tessellation's inner radius is above 0.98).
    Vec3f o{0.1f, -0.2f, 0.3f};
    if (i % 2 == 0) {
      Vec3f d;
      do d = {u(rng), u(rng), u(rng)};
      while (dot(d, d) >= 0.81f);
      o = o + d;
    }
    rays.push_back({o, 0, random_direction(rng), kInfinity});
  }
  for (const auto& a : all) {
    const size_t n = a.name == "brute" ? 20000 : rays.size();
    size_t misses = 0, occl_misses = 0;
    for (size_t i = 0; i < n; ++i) {
      Hit h;
      misses += !a.accel->intersect(rays[i], h);
      occl_misses += !a.accel->occluded(rays[i]);
    }
    INFO(a.name << ": " << misses << " misses, " << occl_misses << " occlusion misses in " << n << " rays");
    CHECK(double(misses) <= 2e-5 * double(n));
    CHECK(double(occl_misses) <= 2e-5 * double(n));
  }
}

// ---- Real scenes ----------------------------------------------------------------------------------

TEST_CASE("cross-check: the default scene", "[accel][crosscheck]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto meshes = mesh_views(l.scene);
  const auto instances = instance_views(l.scene);
  // Flattened (one level), and as loaded: the "wall" mesh is instanced by three nodes.
  check_scene("default.gltf", flatten(meshes, instances).views, light_positions(l.scene));
  REQUIRE(l.scene.instances.size() > l.scene.meshes.size());
  check_instanced("default.gltf", meshes, instances, light_positions(l.scene));
}

TEST_CASE("cross-check: Embree without the robust flag and at low and high build quality",
          "[accel][crosscheck]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  const auto views = mesh_views(l.scene);
  for (const auto& [robust, quality] : {std::pair{false, 1}, std::pair{true, 0}, std::pair{true, 2}}) {
    AccelConfig config;
    config.embree.robust = robust;
    config.embree.quality = quality;
    const auto embree = make_accelerator("embree", views, config);
    CHECK(embree->stats().config.find(robust ? "robust 1" : "robust 0") != std::string::npos);
    std::mt19937 rng(7);
    const Bounds3f b = bounds_of(views);
    std::vector<Ray> rays = camera_rays(b, 32);
    const auto rnd = random_rays(b, 2000, rng);
    rays.insert(rays.end(), rnd.begin(), rnd.end());
    const auto brute = make_accelerator("brute", views);
    const auto res = cross_check(*embree, reference(*brute, rays), views, length(b.extent()), false, 1e-4f);
    INFO(summary("embree " + embree->stats().config + " vs brute", res));
    CHECK(res.failures() == 0);
  }
}

TEST_CASE("cross-check: every valid corpus model", "[accel][crosscheck][corpus]") {
  const auto corpus = corpus_dir();
  if (!corpus) return skip("no corpus (set PENUMBRA_CORPUS)");
  size_t models = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(*corpus / "valid")) {
    const auto ext = e.path().extension();
    if (!e.is_regular_file() || (ext != ".gltf" && ext != ".glb")) continue;
    const LoadedScene l = load_gltf(e.path());
    const auto meshes = mesh_views(l.scene);
    const auto instances = instance_views(l.scene);
    const std::string name = e.path().filename().string();
    check_scene(name, flatten(meshes, instances).views, light_positions(l.scene));
    if (std::any_of(l.scene.instances.begin(), l.scene.instances.end(),
                    [](const Instance& i) { return !i.identity; }))
      check_instanced(name, meshes, instances, light_positions(l.scene));
    ++models;
  }
  CHECK(models >= 30);
}

TEST_CASE("cross-check, slow: the default scene and spheres with 16x the rays",
          "[.][slow][accel][crosscheck]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  check_scene("default.gltf", flatten(mesh_views(l.scene), instance_views(l.scene)).views,
              light_positions(l.scene), 4);
  const Soup s = icosphere(3, 1.0f, {1e3f, 0, 0});
  check_scene("sphere", s.views(), {}, 4);
}

// ---- Renderer level -------------------------------------------------------------------------------

TEST_CASE("the default scene renders the same image with every accelerator", "[accel][render]") {
  const LoadedScene l = load_gltf(source_dir() / "scenes/default.gltf");
  RenderConfig cfg;
  cfg.width = 160;
  cfg.height = 90;
  cfg.spp = 1;
  cfg.threads = 2;
  std::vector<NamedAccel> all;
  for (const auto& name : accelerator_names()) all.push_back({name, make_scene_accelerator(name, l.scene)});
  std::vector<Film> films;
  for (const auto& a : all) films.push_back(render_whitted(l.scene, *a.accel, l.scene.cameras.at(0), cfg));
  const Film& embree = films[0];
  const Film& brute = films.back();
  REQUIRE(all[0].name == "embree");
  REQUIRE(all.back().name == "brute");
  for (size_t i = 1; i < all.size(); ++i) {
    // Back ends sharing the watertight test: the same image as brute force, bit for bit.
    CHECK(std::memcmp(films[i].rgba.data(), brute.rgba.data(), brute.rgba.size() * sizeof(float)) == 0);
    // Against Embree: every pixel within 1e-4 (relative above 1), except where Embree's own
    // triangle test resolves a tie on a shared edge differently.
    size_t differing = 0;
    for (size_t p = 0; p < embree.rgba.size(); p += 4) {
      bool same = true;
      for (int c = 0; c < 4; ++c)
        same &= std::fabs(films[i].rgba[p + c] - embree.rgba[p + c]) <=
                1e-4f * std::max(1.0f, std::fabs(embree.rgba[p + c]));
      differing += !same;
    }
    INFO(all[i].name << ": " << differing << " of " << embree.rgba.size() / 4
                     << " pixels differ from embree by > 1e-4");
    CHECK(differing <= embree.rgba.size() / 4 / 1000);
  }
}
