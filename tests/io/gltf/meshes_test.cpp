// Mesh placement and instancing (io/gltf/meshes.cpp): a mesh placed by several nodes is stored once (object
// space) and instanced, EXT_mesh_gpu_instancing places one instance per TRS element after the node's
// transform, --flatten (GltfLoadOptions::flatten) gives world-space copies instead, malformed
// instancing data is an error naming the element, and instanced and flattened scenes render
// the same image with every accelerator.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/files/error.h"
#include "io/gltf/gltf_writer.h"
#include "io/gltf/loader.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using penumbra::test::GltfWriter;
using penumbra::test::write_and_load;
using json = nlohmann::json;

namespace {

void check_vec(Vec3f a, Vec3f b, float eps = 1e-5f) {
  test::check_vec(a, b, eps);
}

/// A file whose unit quad mesh is placed by three nodes (moved, mirrored, rotated) and whose
/// triangle mesh is placed by one node (moved).
GltfWriter shared_mesh_file() {
  GltfWriter w;
  const int quad =
      w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
  const int tri = w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  w.node({{"mesh", quad}, {"translation", {2, 0, 0}}});
  w.node({{"mesh", quad}, {"scale", {-1, 1, 1}}});
  w.node({{"mesh", quad}, {"rotation", {0, 0, std::sqrt(0.5), std::sqrt(0.5)}}});  // 90 degrees about z
  w.node({{"mesh", tri}, {"translation", {0, 0, 3}}});
  return w;
}

/// The positions an instance puts in the world.
std::vector<Vec3f> world_positions(const Scene& s, const Instance& inst) {
  return test::world_copy(s, inst).positions;
}

}  // namespace

TEST_CASE("gltf instancing: a mesh placed by several nodes is stored once", "[io][gltf][instances][quick]") {
  GltfWriter w = shared_mesh_file();
  const LoadedScene l = write_and_load(w, "inst-shared");
  const Scene& s = l.scene;
  CHECK(l.warnings.empty());
  REQUIRE(s.meshes.size() == 2);     // the quad once, the triangle once
  REQUIRE(s.instances.size() == 4);  // one per node
  CHECK(count_stored_triangles(s) == 3);
  CHECK(count_triangles(s) == 7);
  // The quad (placed three times) stays in object space; the triangle (placed once) is moved
  // into world space and placed by the identity.
  const Instance& tri = s.instances[3];
  CHECK(tri.identity);
  CHECK(tri.node == 3);
  check_vec(s.meshes[size_t(tri.mesh)].positions[1], {1, 0, 3});
  for (int k = 0; k < 3; ++k) {
    const Instance& inst = s.instances[size_t(k)];
    CHECK(inst.node == k);
    CHECK_FALSE(inst.identity);
    CHECK(inst.mesh == s.instances[0].mesh);
    CHECK(inst.mirrored == (k == 1));
  }
  check_vec(s.meshes[size_t(s.instances[0].mesh)].positions[2], {1, 1, 0});  // object space
  check_vec(world_positions(s, s.instances[0])[2], {3, 1, 0});
  check_vec(world_positions(s, s.instances[1])[2], {-1, 1, 0});
  check_vec(world_positions(s, s.instances[2])[2], {-1, 1, 0});
  check_vec(world_positions(s, s.instances[2])[1], {0, 1, 0});
  const Bounds3f b = compute_bounds(s);
  check_vec(b.lo, {-1, 0, 0});
  check_vec(b.hi, {3, 1, 3});

  // Flattened: one world-space copy per node, the same triangles (winding reversed where the
  // node mirrors, so counter-clockwise stays the front).
  GltfLoadOptions flat_opt;
  flat_opt.flatten = true;
  GltfWriter w2 = shared_mesh_file();
  const LoadedScene f = write_and_load(w2, "inst-shared-flat", flat_opt);
  REQUIRE(f.scene.meshes.size() == 4);
  REQUIRE(f.scene.instances.size() == 4);
  for (size_t k = 0; k < 4; ++k) {
    CHECK(f.scene.instances[k].identity);
    const Mesh copy = test::world_copy(s, s.instances[k]);
    const Mesh& m = f.scene.meshes[k];
    CHECK(m.indices == copy.indices);
    REQUIRE(m.positions.size() == copy.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) check_vec(m.positions[i], copy.positions[i]);
    for (size_t i = 0; i < m.normals.size(); ++i) check_vec(m.normals[i], copy.normals[i]);
  }
  check_vec(compute_bounds(f.scene).lo, b.lo);
  check_vec(compute_bounds(f.scene).hi, b.hi);
}

TEST_CASE("gltf instancing: EXT_mesh_gpu_instancing places T R S per instance after the node",
          "[io][gltf][instances][quick]") {
  for (bool flatten : {false, true}) {
    INFO("flatten " << flatten);
    GltfWriter w;
    const int quad =
        w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
    const std::vector<float> t = {0, 0, 0, 0, 5, 0};
    const int16_t h = 23170;  // sqrt(1/2) as a normalized short: 90 degrees about z
    const std::vector<int16_t> r = {0, 0, 0, 32767, 0, 0, h, h};
    const std::vector<float> sc = {1, 1, 1, 2, 2, 2};
    const int ta = w.accessor(t.data(), t.size() * 4, 5126, 2, "VEC3");
    const int ra = w.accessor(r.data(), r.size() * 2, 5122, 2, "VEC4");
    w.j["accessors"][size_t(ra)]["normalized"] = true;
    const int sa = w.accessor(sc.data(), sc.size() * 4, 5126, 2, "VEC3");
    const json attributes = {{"TRANSLATION", ta}, {"ROTATION", ra}, {"SCALE", sa}, {"_ID", ta}};
    json node = {{"mesh", quad}, {"translation", {10, 0, 0}}};
    node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = attributes;
    w.node(node);
    w.j["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
    w.j["extensionsRequired"] = {"EXT_mesh_gpu_instancing"};
    GltfLoadOptions opt;
    opt.flatten = flatten;
    const LoadedScene l = write_and_load(w, "inst-gpu", opt);
    CHECK(l.warnings.empty());  // the extension is supported; "_ID" is an application attribute
    const Scene& s = l.scene;
    REQUIRE(s.instances.size() == 2);  // the node's mesh is drawn only through its instances
    CHECK(s.meshes.size() == (flatten ? 2u : 1u));
    // World = node (T 10,0,0) x instance (T R S): vertex (1, 0, 0) goes to (11, 0, 0) for the
    // first instance and to (10, 0, 0) + (0, 5, 0) + Rz90 (2, 0, 0) = (10, 7, 0) for the second.
    check_vec(world_positions(s, s.instances[0])[1], {11, 0, 0}, 1e-4f);
    check_vec(world_positions(s, s.instances[1])[1], {10, 7, 0}, 1e-3f);  // normalized-short rotation
    check_vec(world_positions(s, s.instances[1])[2], {8, 7, 0}, 1e-3f);   // (1, 1, 0) -> (-2, 2, 0)
    if (!flatten) {
      CHECK(s.instances[0].copy == 0);
      CHECK(s.instances[1].copy == 1);
    }
  }
}

TEST_CASE("gltf instancing: malformed EXT_mesh_gpu_instancing is an error naming the attribute, or a warning",
          "[io][gltf][instances][quick]") {
  auto file = [](json attributes) {
    GltfWriter w;
    const int quad =
        w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
    const std::vector<float> three = {0, 0, 0, 1, 0, 0, 2, 0, 0}, two = {0, 0, 0, 1, 1, 1};
    const std::vector<float> zero_scale = {1, 1, 1, 0, 0, 0};
    const std::vector<float> vec2 = {0, 0, 1, 1};
    const int a3 = w.accessor(three.data(), three.size() * 4, 5126, 3, "VEC3");
    const int a2 = w.accessor(two.data(), two.size() * 4, 5126, 2, "VEC3");
    const int az = w.accessor(zero_scale.data(), zero_scale.size() * 4, 5126, 2, "VEC3");
    const int av = w.accessor(vec2.data(), vec2.size() * 4, 5126, 2, "VEC2");
    // Placeholders name the accessors: "three", "two", "zero", "vec2".
    for (auto& [key, v] : attributes.items())
      if (v.is_string()) v = v == "three" ? a3 : v == "two" ? a2 : v == "zero" ? az : av;
    json node = {{"mesh", quad}};
    node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = attributes;
    w.node(node);
    return w;
  };
  const std::string ext = "nodes[0].extensions.EXT_mesh_gpu_instancing";
  {
    GltfWriter w = file({{"TRANSLATION", "three"}, {"SCALE", "two"}});
    CHECK_THROWS_WITH(write_and_load(w, "inst-count"),
                      Contains(ext + ".attributes.SCALE") && Contains("same count"));
  }
  {
    GltfWriter w = file({{"TRANSLATION", "vec2"}});
    CHECK_THROWS_WITH(write_and_load(w, "inst-type"),
                      Contains(ext + ".attributes.TRANSLATION") && Contains("accessor type"));
  }
  {
    GltfWriter w = file({{"TRANSLATION", 1.5}});
    CHECK_THROWS_WITH(write_and_load(w, "inst-index"),
                      Contains(ext + ".attributes.TRANSLATION") && Contains("accessor index"));
  }
  {
    GltfWriter w = file({{"TRANSLATION", 99}});
    CHECK_THROWS_AS(write_and_load(w, "inst-range"), InputError);
  }
  {
    GltfWriter w = file(json::array({1}));
    CHECK_THROWS_WITH(write_and_load(w, "inst-attr"), Contains(ext + ".attributes") && Contains("object"));
  }
  {  // One instance of two has a zero scale: skipped with one warning naming the extension.
    GltfWriter w = file({{"SCALE", "zero"}, {"FOO", "two"}});
    const LoadedScene l = write_and_load(w, "inst-zero");
    CHECK(l.scene.instances.size() == 1);
    REQUIRE(l.warnings.size() == 2);
    CHECK_THAT(l.warnings[0], Contains(ext + ".attributes.FOO") && Contains("unknown instance attribute"));
    CHECK_THAT(l.warnings[1], Contains(ext) && Contains("1 of 2 instances"));
  }
  {  // No attributes at all: the mesh is placed once, with a warning.
    GltfWriter w = file(json::object());
    const LoadedScene l = write_and_load(w, "inst-none");
    CHECK(l.scene.instances.size() == 1);
    REQUIRE(l.warnings.size() == 1);
    CHECK_THAT(l.warnings[0], Contains("no TRANSLATION, ROTATION or SCALE"));
  }
}

TEST_CASE("gltf instancing: SimpleInstancing has 125 instances of one cube, as its README says",
          "[io][gltf][instances][corpus]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("no corpus (set PENUMBRA_CORPUS)");
  const LoadedScene l = load_gltf(*corpus / "valid/SimpleInstancing/glTF-Binary/SimpleInstancing.glb");
  const Scene& s = l.scene;
  CHECK(l.warnings.empty());
  REQUIRE(s.meshes.size() == 1);
  REQUIRE(s.instances.size() == 125);
  CHECK(count_triangles(s) == 125 * 12);
  // "the first instance that is rendered is the unmodified unit cube"
  CHECK(is_identity(s.instances[0].to_world));
  // "the last instance is a cube at (10, 10, 10) that is rotated around the axis (1, 1, 1) ...
  // and scaled by (2, 2, 2)". Its ROTATION element is (0.5, 0.5, 0.5, 0.5): 120 degrees about
  // (1, 1, 1) (the README's "90 degrees along each axis" composed), which cycles the axes
  // x -> y -> z -> x and keeps the axis fixed.
  const Instance& last = s.instances.back();
  check_vec(apply_point(last.to_world, {0, 0, 0}), {10, 10, 10}, 1e-4f);
  check_vec(apply_vector(last.to_world, {1, 0, 0}), {0, 2, 0}, 1e-4f);
  check_vec(apply_vector(last.to_world, {0, 1, 0}), {0, 0, 2}, 1e-4f);
  check_vec(apply_vector(last.to_world, {1, 1, 1}), {2, 2, 2}, 1e-4f);
}

namespace {

/// A UV sphere of radius 1 with smooth normals.
Mesh uv_sphere(int n, int material) {
  Mesh m;
  m.name = "sphere";
  m.material = material;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= 2 * n; ++i) {
      const float th = kPi * float(j) / float(n), ph = kPi * float(i) / float(n);
      m.positions.push_back({std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < 2 * n; ++i) {
      const uint32_t a = uint32_t(j * (2 * n + 1) + i), b = a + 1, c = a + uint32_t(2 * n + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  m.normals = compute_smooth_normals(m.positions, m.indices);
  return m;
}

/// Pixels of `a` differing from `b` by more than 1e-3 (relative above 1), and the mean
/// absolute difference.
std::pair<size_t, double> compare(const Film& a, const Film& b) {
  size_t differing = 0;
  double sum = 0;
  for (size_t p = 0; p < a.rgba.size(); p += 4) {
    bool same = true;
    for (int c = 0; c < 4; ++c) {
      const float d = std::fabs(a.rgba[p + size_t(c)] - b.rgba[p + size_t(c)]);
      sum += d;
      same &= d <= 1e-3f * std::max(1.0f, std::fabs(b.rgba[p + size_t(c)]));
    }
    differing += !same;
  }
  return {differing, sum / double(a.rgba.size())};
}

/// Renders `file` instanced with every accelerator and flattened with Embree; every image
/// must match the flattened one (rounding at silhouettes aside).
void check_instanced_matches_flattened(const std::filesystem::path& file, const Camera* camera) {
  GltfLoadOptions flat_opt;
  flat_opt.flatten = true;
  const LoadedScene inst = load_gltf(file), flat = load_gltf(file, flat_opt);
  REQUIRE(flat.scene.instances.size() == inst.scene.instances.size());
  REQUIRE(flat.scene.meshes.size() > inst.scene.meshes.size());  // something really is instanced
  const Camera cam = camera ? *camera : inst.scene.cameras.at(0);
  RenderConfig cfg;
  cfg.width = 120;
  cfg.height = 90;
  cfg.spp = 1;
  cfg.threads = 2;
  cfg.whitted.max_depth = 2;
  const Film reference = render_whitted(flat.scene, *make_scene_accelerator("embree", flat.scene), cam, cfg);
  size_t covered = 0;
  for (size_t p = 3; p < reference.rgba.size(); p += 4) covered += reference.rgba[p] > 0;
  CHECK(covered > reference.rgba.size() / 4 / 10);  // the instances are in view
  for (const auto& name : accelerator_names()) {
    const Film f = render_whitted(inst.scene, *make_scene_accelerator(name, inst.scene), cam, cfg);
    const auto [differing, mean] = compare(f, reference);
    INFO(file.filename().string() << ", " << name << ": " << differing << " pixels differ, mean |difference| "
                                  << mean);
    CHECK(differing <= reference.rgba.size() / 4 / 200);
    CHECK(mean < 1e-3);
  }
}

}  // namespace

TEST_CASE("gltf instancing: instanced and flattened scenes render the same image with every accelerator",
          "[io][gltf][instances][render]") {
  // One sphere mesh placed five times (in place, rotated and stretched, mirrored, small, far)
  // over a floor, with shadows and a mirror bounce; the mirrored copy's material is
  // single-sided so its culling depends on the winding rule.
  Scene s;
  const int red = test::add_material(s, {0.8f, 0.2f, 0.1f}, 0, 0.4f);
  const int mirror = test::add_material(s, {0.9f, 0.9f, 0.9f}, 1, 0);
  const int floor = test::add_material(s, {0.7f, 0.7f, 0.7f}, 0, 1);
  s.materials[size_t(red)].double_sided = false;
  const int sphere = int(s.meshes.size());
  s.meshes.push_back(uv_sphere(16, red));
  const int shiny = int(s.meshes.size());
  s.meshes.push_back(uv_sphere(12, mirror));
  test::add_quad_z(s, -6, 6, -6, 6, 0, floor);
  auto place = [&](int mesh, Vec3f t, Quat q, Vec3f sc) {
    s.instances.push_back(
        make_instance(mesh, to_affine(compose_trs({t.x, t.y, t.z}, q, {sc.x, sc.y, sc.z}))));
  };
  const double h = std::sqrt(0.5);
  place(sphere, {0, 0, 1}, {}, {1, 1, 1});
  place(sphere, {2.5f, 0, 1}, {0, h, 0, h}, {0.5f, 1.5f, 1});
  place(sphere, {-2.5f, 0, 1}, {}, {-1, 1, 1});
  place(sphere, {0, -2.5f, 0.4f}, {0.3, 0.1, 0.2, 0.9}, {0.4f, 0.4f, 0.4f});
  place(shiny, {0, 2.5f, 1}, {}, {1, 1, 1});
  place(shiny, {2.5f, 2.5f, 0.6f}, {}, {0.6f, 0.6f, 0.6f});
  s.lights.push_back(test::point_light({3, -4, 6}, 60));
  Camera cam = look_at({0, -9, 6}, {0, 0, 0.5f}, {0, 0, 1}, 0.8f);
  s.cameras.push_back(cam);
  const auto dir = test::temp_dir("inst-render");
  write_gltf(s, dir / "spheres.gltf");
  check_instanced_matches_flattened(dir / "spheres.gltf", nullptr);
}

TEST_CASE("gltf instancing: SimpleInstancing renders the same instanced and flattened with every accelerator",
          "[io][gltf][instances][render][corpus]") {
  const auto corpus = test::corpus_dir();
  if (!corpus) return test::skip("no corpus (set PENUMBRA_CORPUS)");
  const Camera view = look_at({-8, 18, 26}, {5, 5, 5}, {0, 1, 0}, 0.9f);
  check_instanced_matches_flattened(*corpus / "valid/SimpleInstancing/glTF-Binary/SimpleInstancing.glb",
                                    &view);
}
