// write_gltf: everything it writes comes back through load_gltf (geometry bit for bit,
// materials, lights and cameras), as .gltf + .bin and as one .glb (its chunks checked byte by
// byte), and bad scenes or folders fail without leaving files; shapes written as PENUMBRA_shapes
// come back with every field and every CSG node; implicit shapes loaded from PENUMBRA_shapes,
// meshed and written as .glb come back closed and in place.
#include "io/gltf/gltf_writer.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>
#include <iterator>
#include <random>
#include <vector>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/shape_mesh.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"
#include "support/mesh_checks.h"
#include "support/scene_builder.h"
#include "support/sdf_trees.h"
#include "support/test_util.h"

using namespace penumbra;
using penumbra::test::check_vec;
using namespace penumbra::test;

namespace {

Scene sample_scene() {
  Scene s;
  Material plain;
  plain.name = "plain";
  plain.base_color = {0.25f, 0.5f, 0.75f};
  plain.metallic = 0.125f;
  plain.roughness = 0.625f;
  Material glow;
  glow.name = "glow";
  glow.emissive = {5, 2.5f, 0};  // needs KHR_materials_emissive_strength
  Material flat;
  flat.unlit = true;
  flat.base_color = {1, 0, 0};
  s.materials = {plain, glow, flat};
  Mesh a;
  a.name = "tri";
  a.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}};
  a.indices = {0, 1, 2};
  a.normals = compute_smooth_normals(a.positions, a.indices);
  a.uvs = {{0, 0}, {1, 0}, {0, 1}};
  a.material = 0;
  Mesh b;
  b.name = "quad";
  b.positions = {{-1, -1, -2}, {1, -1, -2}, {1, 1, -2}, {-1, 1, -2}};
  b.indices = {0, 1, 2, 0, 2, 3};
  b.material = 1;
  Mesh c = b;
  c.material = 2;
  for (auto& p : c.positions) p.z = -3;
  for (Mesh* m : {&a, &b, &c}) add_world_mesh(s, std::move(*m));
  Light point;
  point.type = LightType::Point;
  point.position = {1, 2, 3};
  point.intensity = 40;
  point.color = {1, 0.5f, 0.25f};
  point.range = 10;
  Light spot;
  spot.type = LightType::Spot;
  spot.position = {0, 5, 0};
  spot.direction = normalize(Vec3f{0.3f, -1, 0.2f});
  spot.inner_cone = 0.2f;
  spot.outer_cone = 0.5f;
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = normalize(Vec3f{0, -1, 0});  // straight down: the frame's degenerate case
  sun.intensity = 3;
  s.lights = {point, spot, sun};
  Camera cam = look_at({3, 2, 5}, {0, 0, 0}, {0, 1, 0}, 0.7f);
  cam.name = "main";
  cam.aspect = 1.5f;
  cam.znear = 0.05f;
  Camera ortho = look_at({0, 10, 0}, {0, 0, 0}, {0, 0, -1}, 0.5f);
  ortho.projection = Projection::Orthographic;
  ortho.xmag = 3;
  ortho.ymag = 2;
  ortho.zfar = 100;
  s.cameras = {cam, ortho};
  return s;
}

}  // namespace

TEST_CASE("write_gltf: a scene comes back through load_gltf", "[gltf][writer]") {
  const Scene s = sample_scene();
  const auto dir = temp_dir("gltf-writer");
  write_gltf(s, dir / "scene.gltf");
  CHECK(std::filesystem::exists(dir / "scene.bin"));
  const LoadedScene l = load_gltf(dir / "scene.gltf");
  CHECK(l.warnings.empty());
  const Scene& r = l.scene;
  REQUIRE(r.meshes.size() == 3);
  for (size_t i = 0; i < 3; ++i) {
    CHECK(r.meshes[i].indices == s.meshes[i].indices);
    REQUIRE(r.meshes[i].positions.size() == s.meshes[i].positions.size());
    CHECK(std::memcmp(r.meshes[i].positions.data(), s.meshes[i].positions.data(),
                      s.meshes[i].positions.size() * 12) == 0);
    CHECK(r.meshes[i].material == s.meshes[i].material);
  }
  for (int k = 0; k < 3; ++k)
    check_vec(r.meshes[0].normals[size_t(k)], s.meshes[0].normals[size_t(k)], 1e-6f);
  REQUIRE(r.meshes[0].uvs.size() == 3);
  CHECK(r.meshes[0].uvs[2].y == 1.0f);
  REQUIRE(r.materials.size() == 3);
  check_vec(r.materials[0].base_color, s.materials[0].base_color);
  CHECK(r.materials[0].metallic == 0.125f);
  CHECK(r.materials[0].roughness == 0.625f);
  check_vec(r.materials[1].emissive, {5, 2.5f, 0}, 1e-5f);
  CHECK(r.materials[2].unlit);
  REQUIRE(r.lights.size() == 3);
  check_vec(r.lights[0].position, {1, 2, 3});
  CHECK(r.lights[0].intensity == 40);
  CHECK(r.lights[0].range == 10);
  check_vec(r.lights[0].color, {1, 0.5f, 0.25f});
  CHECK(r.lights[1].type == LightType::Spot);
  check_vec(r.lights[1].direction, s.lights[1].direction, 1e-5f);
  CHECK(r.lights[1].outer_cone == Approx(0.5f));
  CHECK(r.lights[2].type == LightType::Directional);
  check_vec(r.lights[2].direction, {0, -1, 0}, 1e-5f);
  REQUIRE(r.cameras.size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    check_vec(r.cameras[i].eye, s.cameras[i].eye, 1e-5f);
    check_vec(r.cameras[i].u, s.cameras[i].u, 1e-5f);
    check_vec(r.cameras[i].w, s.cameras[i].w, 1e-5f);
  }
  CHECK(r.cameras[0].name == "main");
  CHECK(r.cameras[0].yfov == Approx(0.7f));
  CHECK(r.cameras[0].aspect == Approx(1.5f));
  CHECK(r.cameras[1].projection == Projection::Orthographic);
  CHECK(r.cameras[1].ymag == 2);
  std::filesystem::remove_all(dir);
}

TEST_CASE("write_gltf: bad scenes and folders fail with the element named and leave no file",
          "[gltf][writer]") {
  const auto dir = temp_dir("gltf-writer-bad");
  Scene s = sample_scene();
  s.meshes[1].positions[2].y = std::nanf("");
  CHECK_THROWS_WITH(write_gltf(s, dir / "bad.gltf"), Catch::Contains("meshes[1]: non-finite position"));
  s = sample_scene();
  s.meshes[2].indices[4] = 9;
  CHECK_THROWS_WITH(write_gltf(s, dir / "bad.gltf"), Catch::Contains("meshes[2]: index 9 >= vertex count 4"));
  s = sample_scene();
  s.meshes[0].indices.push_back(0);
  CHECK_THROWS_WITH(write_gltf(s, dir / "bad.gltf"),
                    Catch::Contains("meshes[0]: index count 4 is not a multiple of 3"));
  CHECK(std::filesystem::is_empty(dir));
  CHECK_THROWS_AS(write_gltf(sample_scene(), dir / "missing" / "x.gltf"), InputError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("write_glb: one binary file with aligned, padded chunks that load_gltf reads back",
          "[gltf][writer]") {
  const Scene s = sample_scene();
  const auto dir = temp_dir("glb-writer");
  write_glb(s, dir / "scene.glb");
  CHECK(!std::filesystem::exists(dir / "scene.bin"));
  // The container, byte by byte (glTF 2.0 spec 4.4): header, JSON chunk, BIN chunk.
  std::ifstream f(dir / "scene.glb", std::ios::binary);
  const std::vector<uint8_t> b((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto u32 = [&](size_t at) {
    return uint32_t(b[at]) | uint32_t(b[at + 1]) << 8 | uint32_t(b[at + 2]) << 16 | uint32_t(b[at + 3]) << 24;
  };
  REQUIRE(b.size() >= 28);
  CHECK(std::memcmp(b.data(), "glTF", 4) == 0);
  CHECK(u32(4) == 2);
  CHECK(u32(8) == b.size());
  const uint32_t json_length = u32(12);
  CHECK(json_length % 4 == 0);
  CHECK(std::memcmp(b.data() + 16, "JSON", 4) == 0);
  CHECK(b[20] == '{');
  size_t last = 20 + json_length - 1;
  while (b[last] == ' ') --last;
  CHECK(b[last] == '}');
  const size_t bin = 20 + json_length;
  REQUIRE(b.size() >= bin + 8);
  CHECK(std::memcmp(b.data() + bin + 4, "BIN\0", 4) == 0);
  CHECK(u32(bin) % 4 == 0);
  CHECK(bin + 8 + u32(bin) == b.size());
  // The same scene as through write_gltf.
  const LoadedScene l = load_gltf(dir / "scene.glb");
  CHECK(l.warnings.empty());
  REQUIRE(l.scene.meshes.size() == s.meshes.size());
  for (size_t i = 0; i < s.meshes.size(); ++i) {
    CHECK(l.scene.meshes[i].indices == s.meshes[i].indices);
    REQUIRE(l.scene.meshes[i].positions.size() == s.meshes[i].positions.size());
    CHECK(std::memcmp(l.scene.meshes[i].positions.data(), s.meshes[i].positions.data(),
                      s.meshes[i].positions.size() * 12) == 0);
    CHECK(l.scene.meshes[i].material == s.meshes[i].material);
  }
  CHECK(l.scene.materials.size() == 3);
  CHECK(l.scene.cameras.size() == 2);
  // A scene without geometry has no BIN chunk.
  Scene empty;
  empty.lights = s.lights;
  write_glb(empty, dir / "empty.glb");
  CHECK(std::filesystem::file_size(dir / "empty.glb") == 20 + [&] {
    std::ifstream e(dir / "empty.glb", std::ios::binary);
    uint8_t h[16];
    e.read(reinterpret_cast<char*>(h), 16);
    return size_t(h[12]) | size_t(h[13]) << 8 | size_t(h[14]) << 16 | size_t(h[15]) << 24;
  }());
  CHECK(load_gltf(dir / "empty.glb").scene.lights.size() == 3);
  CHECK_THROWS_AS(write_glb(s, dir / "missing" / "x.glb"), InputError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("write_glb: implicit shapes meshed from a PENUMBRA_shapes file come back closed",
          "[gltf][writer]") {
  // A unit sphere scaled by 0.5 and moved to (2, 0, 0), with material 0.
  GltfWriter w;
  w.j["materials"] = nlohmann::json::array({{{"name", "red"}}});
  w.j["extensionsUsed"] = {"PENUMBRA_shapes"};
  w.node({{"name", "ball"},
          {"translation", {2, 0, 0}},
          {"scale", {0.5, 0.5, 0.5}},
          {"extensions",
           {{"PENUMBRA_shapes",
             {{"type", "implicit"}, {"material", 0}, {"csg", {{"type", "sphere"}, {"radius", 1}}}}}}}});
  const LoadedScene shapes = write_and_load(w, "glb-shapes");
  REQUIRE(shapes.scene.shapes.size() == 1);
  ShapeMeshConfig config;
  config.resolution = 48;
  const ShapeMeshes meshed = mesh_implicit_shapes(shapes.scene, config);
  const auto dir = temp_dir("glb-shapes-out");
  write_glb(meshed.scene, dir / "ball.glb");
  const LoadedScene back = load_gltf(dir / "ball.glb");
  REQUIRE(back.scene.meshes.size() == 1);
  const Mesh& m = back.scene.meshes[0];
  CHECK(m.positions.size() > 0);
  CHECK(m.material == 0);
  const MeshTopology t = mesh_topology(m.positions.size(), m.indices);
  CHECK(t.closed_manifold());
  CHECK(t.euler == 2);
  // Within one cell (0.5 * 2 / 48 in the world) of the ball's box (1.5, -0.5, -0.5)-(2.5, 0.5, 0.5).
  const float cell = 0.5f * marching_cubes_grid(shapes.scene.shapes[0].shape.sdf_bounds, 48, {}).cell;
  Bounds3f b;
  for (const Vec3f& p : m.positions) b = merge(b, p);
  check_vec(b.lo, {1.5f, -0.5f, -0.5f}, cell);
  check_vec(b.hi, {2.5f, 0.5f, 0.5f}, cell);
  std::filesystem::remove_all(dir);
}

TEST_CASE("write_gltf: shapes come back through PENUMBRA_shapes with every field and CSG node",
          "[gltf][writer][shapes]") {
  Scene s;
  s.materials.resize(2);
  s.materials[1].name = "red";
  std::vector<Shape> shapes(5);
  shapes[0].kind = ShapeKind::Sphere, shapes[0].radius = 0.7f;
  shapes[1].kind = ShapeKind::Plane, shapes[1].half_size = {2, 1, 3};
  shapes[2].kind = ShapeKind::Disk, shapes[2].radius = 1.5f;
  shapes[3].kind = ShapeKind::Box, shapes[3].half_size = {0.5f, 1, 1.5f};
  shapes[4].kind = ShapeKind::Capsule, shapes[4].radius = 0.25f, shapes[4].half_height = 0.75f;
  // Every CSG node kind once, with transforms.
  SdfTree t = csg_part();
  t.nodes[0].to_local = moved_by({0.1f, 0.2f, 0.3f});
  SdfNode torus = sdf_primitive(SdfKind::Torus, {0.8f, 0, 0}, 0.2f),
          cone = sdf_primitive(SdfKind::Cone, {0, 0.5f, 0}, 0.4f);
  SdfNode round = sdf_primitive(SdfKind::RoundBox, {0.5f, 0.4f, 0.3f}, 0.1f),
          capsule = sdf_primitive(SdfKind::Capsule, {0, 0.3f, 0}, 0.2f);
  SdfNode half = sdf_primitive(SdfKind::HalfSpace, {});
  half.normal = normalize(Vec3f{0.2f, 1, 0.1f}), half.offset = 0.3f;
  SdfNode poly;
  poly.kind = SdfKind::ConvexPolyhedron;
  poly.first_plane = 0, poly.plane_count = 6;
  for (int k = 0; k < 3; ++k)
    for (float sgn : {1.0f, -1.0f})
      t.planes.push_back({k == 0 ? sgn : 0, k == 1 ? sgn : 0, k == 2 ? sgn : 0, 0.6f});
  const int a = add_node(t, sdf_operator(SdfKind::SmoothUnion, add_node(t, torus), add_node(t, cone), 0.2f));
  const int b =
      add_node(t, sdf_operator(SdfKind::SmoothIntersection, add_node(t, round), add_node(t, capsule), 0.1f));
  const int c =
      add_node(t, sdf_operator(SdfKind::SmoothSubtraction, add_node(t, poly), add_node(t, half), 0.15f));
  const int d =
      add_node(t, sdf_operator(SdfKind::Complement, add_node(t, sdf_primitive(SdfKind::Sphere, {5, 0, 0}))));
  // Displacement by each noise kind, every field away from its default, one under a transform.
  FractalParams ridged;
  ridged.kind = FractalKind::Ridged, ridged.detail = 2.5f, ridged.roughness = 0.6f, ridged.lacunarity = 2.2f;
  ridged.offset = 0.8f, ridged.gain = 1.5f, ridged.distortion = 0.25f;
  FractalParams turbulence;
  turbulence.kind = FractalKind::Turbulence, turbulence.detail = 3, turbulence.roughness = 0.4f;
  const int da = add_displace(t, a, 0.05f, 3, ridged, 99);
  t.nodes[size_t(da)].to_local = moved_by({0, 0.1f, 0});
  const int db = add_displace(t, b, -0.03f, 5.5f, turbulence, 4000000000u);
  const int dc = add_displace(t, c, 0.02f, 2, FractalParams{}, 7);
  const int blend =
      add_node(t, sdf_operator(SdfKind::Union, da, add_node(t, sdf_operator(SdfKind::Union, db, dc))));
  const int all = add_node(t, sdf_operator(SdfKind::Union, t.root, blend));
  t.root = add_node(t, sdf_operator(SdfKind::Intersection, all, d));
  SphereTraceConfig trace;
  trace.max_steps = 300, trace.relative_epsilon = 2e-5f;
  shapes.push_back(make_implicit_shape(t, trace));
  for (size_t i = 0; i < shapes.size(); ++i) {
    s.shapes.push_back({"shape" + std::to_string(i), shapes[i], int(i % 2), -1});
    s.instances.push_back(make_shape_instance(int(i), translation({float(i), 0.5f, -1}), -1));
  }
  const auto dir = temp_dir("gltf-writer-shapes");
  write_gltf(s, dir / "shapes.gltf");
  const LoadedScene l = load_gltf(dir / "shapes.gltf");
  CHECK(l.warnings.empty());
  const Scene& r = l.scene;
  REQUIRE(r.shapes.size() == s.shapes.size());
  REQUIRE(r.instances.size() == s.instances.size());
  for (size_t i = 0; i < s.shapes.size(); ++i) {
    INFO("shape " << i);
    const Shape &x = s.shapes[i].shape, &y = r.shapes[size_t(r.instances[i].shape)].shape;
    CHECK(r.shapes[size_t(r.instances[i].shape)].material == s.shapes[i].material);
    CHECK(y.kind == x.kind);
    check_vec(apply_point(r.instances[i].to_world, {0, 0, 0}), {float(i), 0.5f, -1});
    if (x.kind != ShapeKind::Implicit) {
      CHECK(y.radius == x.radius);
      CHECK(y.half_height == x.half_height);
      if (x.kind == ShapeKind::Box || x.kind == ShapeKind::Plane) {
        CHECK(y.half_size.x == x.half_size.x);
        CHECK(y.half_size.z == x.half_size.z);
      }
      continue;
    }
    CHECK(y.trace.max_steps == 300);
    CHECK(y.trace.relative_epsilon == 2e-5f);
    CHECK(y.sdf.nodes.size() == x.sdf.nodes.size());
    // The same noise (matched by seed, each seed used once): every field.
    REQUIRE(y.sdf.displacements.size() == x.sdf.displacements.size());
    for (const SdfDisplacement& dx : x.sdf.displacements) {
      const auto dy = std::find_if(y.sdf.displacements.begin(), y.sdf.displacements.end(),
                                   [&](const SdfDisplacement& e) { return e.table.seed == dx.table.seed; });
      REQUIRE(dy != y.sdf.displacements.end());
      CHECK(dy->table.perm == dx.table.perm);
      CHECK(dy->amplitude == dx.amplitude);
      CHECK(dy->frequency == dx.frequency);
      CHECK(dy->params.kind == dx.params.kind);
      CHECK(dy->params.detail == dx.params.detail);
      CHECK(dy->params.roughness == dx.params.roughness);
      CHECK(dy->params.lacunarity == dx.params.lacunarity);
      CHECK(dy->params.offset == dx.params.offset);
      CHECK(dy->params.gain == dx.params.gain);
      CHECK(dy->params.distortion == dx.params.distortion);
    }
    // The same function: equal values at random points (transforms re-inverted in double).
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-2, 2);
    for (int k = 0; k < 2000; ++k) {
      const Vec3f p{u(rng), u(rng), u(rng)};
      REQUIRE(sdf_eval(y.sdf, p) == Approx(sdf_eval(x.sdf, p)).margin(1e-5));
    }
  }
}

TEST_CASE("write_gltf: procedural textures come back through PENUMBRA_procedural with every field",
          "[gltf][writer][procedural]") {
  Scene s;
  std::vector<ProceduralTexture> textures(3);
  ProceduralTexture& noise = textures[0];
  noise.space = ProceduralSpace::Uv;
  noise.texcoord = 1;
  noise.mapping = procedural_mapping({1, 2, 3}, {10, 20, 30}, {2, 0.5f, 4});
  noise.seed = 123456789u;
  noise.fractal = {FractalKind::Ridged, 3.5f, 0.4f, 2.5f, 0.8f, 3, 0.25f};
  noise.drives_base_color = true;
  noise.base_color.stops = {{0, {0.1f, 0.2f, 0.3f}}, {0.4f, {0.9f, 0.5f, 0}}, {1, {1, 1, 1}}};
  noise.base_color.interpolation = RampInterpolation::Smoothstep;
  noise.base_color_compose = Compose::Replace;
  noise.roughness = {true, 0.2f, 0.7f, Compose::Replace};
  noise.metallic = {true, 0, 0.5f, Compose::Multiply};
  noise.emission_strength = {true, 1, 30, Compose::Replace};
  noise.bump_height = -0.02f;
  noise.filter = false;
  ProceduralTexture& cells = textures[1];
  cells.space = ProceduralSpace::World;
  cells.kind = PatternKind::Voronoi;
  cells.voronoi = {WorleyFeature::F2, WorleyMetric::Manhattan, 0.3f};
  cells.voronoi_output = VoronoiOutput::CellRandom;
  cells.seed = 5;
  ProceduralTexture& wave = textures[2];
  wave.kind = PatternKind::Wave;
  wave.wave = {WaveType::Rings, 1, WaveProfile::Triangle, 0.75f};
  wave.fractal.kind = FractalKind::Turbulence;
  wave.seed = 9;
  for (size_t i = 0; i < textures.size(); ++i) {
    textures[i].table = make_perlin_table(textures[i].seed);
    const int m = add_material(s, {1, 1, 1}, 0, 1);
    s.materials[size_t(m)].procedural = int(i);
    add_quad_z(s, -1, 1, -1, 1, float(i), m);
  }
  s.procedurals = textures;
  const auto dir = temp_dir("writer-procedural");
  write_gltf(s, dir / "p.gltf");
  const LoadedScene l = load_gltf(dir / "p.gltf");
  REQUIRE(l.scene.procedurals.size() == 3);
  for (size_t i = 0; i < 3; ++i) {
    INFO("texture " << i);
    REQUIRE(l.scene.materials[i].procedural == int(i));
    const ProceduralTexture &x = textures[i], &y = l.scene.procedurals[i];
    CHECK(y.space == x.space);
    CHECK(y.texcoord == x.texcoord);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) CHECK(y.mapping.m[r][c] == Approx(x.mapping.m[r][c]).margin(1e-6));
    CHECK(y.kind == x.kind);
    CHECK(y.seed == x.seed);
    CHECK(y.table.perm == x.table.perm);
    CHECK(y.filter == x.filter);
    if (x.kind != PatternKind::Voronoi) {
      CHECK(y.fractal.kind == x.fractal.kind);
      CHECK(y.fractal.detail == x.fractal.detail);
      CHECK(y.fractal.roughness == x.fractal.roughness);
      CHECK(y.fractal.lacunarity == x.fractal.lacunarity);
      CHECK(y.fractal.offset == x.fractal.offset);
      CHECK(y.fractal.gain == x.fractal.gain);
      CHECK(y.fractal.distortion == x.fractal.distortion);
    }
    CHECK(y.voronoi.feature == x.voronoi.feature);
    CHECK(y.voronoi.metric == x.voronoi.metric);
    CHECK(y.voronoi.randomness == x.voronoi.randomness);
    CHECK(y.voronoi_output == x.voronoi_output);
    CHECK(y.wave.type == x.wave.type);
    CHECK(y.wave.axis == x.wave.axis);
    CHECK(y.wave.profile == x.wave.profile);
    CHECK(y.wave.distortion == x.wave.distortion);
    CHECK(y.drives_base_color == x.drives_base_color);
    if (x.drives_base_color) {
      REQUIRE(y.base_color.stops.size() == x.base_color.stops.size());
      for (size_t k = 0; k < x.base_color.stops.size(); ++k) {
        CHECK(y.base_color.stops[k].position == x.base_color.stops[k].position);
        CHECK(y.base_color.stops[k].color == x.base_color.stops[k].color);
      }
      CHECK(y.base_color.interpolation == x.base_color.interpolation);
      CHECK(y.base_color_compose == x.base_color_compose);
    }
    for (auto [dx, dy] : {std::pair{x.roughness, y.roughness}, std::pair{x.metallic, y.metallic},
                          std::pair{x.emission_strength, y.emission_strength}}) {
      CHECK(dy.enabled == dx.enabled);
      if (!dx.enabled) continue;
      CHECK(dy.min == dx.min);
      CHECK(dy.max == dx.max);
      CHECK(dy.compose == dx.compose);
    }
    CHECK(y.bump_height == x.bump_height);
    // The same pattern: equal values at random points.
    std::mt19937 rng{uint32_t(i)};
    std::uniform_real_distribution<float> u(-3, 3);
    for (int k = 0; k < 500; ++k) {
      const Vec3f q{u(rng), u(rng), u(rng)};
      REQUIRE(eval_pattern(y, apply_point(y.mapping, q), 0).t ==
              Approx(eval_pattern(x, apply_point(x.mapping, q), 0).t).margin(1e-4));
    }
  }
}

TEST_CASE("write_gltf: points and lines come back as POINTS and LINES with the file's widths",
          "[gltf][writer]") {
  Scene s;
  Mesh lines;
  lines.name = "lines";
  lines.lines = true;
  lines.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  lines.indices = {0, 1, 1, 1, 2, 2};
  lines.radii = {0.1f, 0.2f, 0.3f};
  lines.file_radii = true;
  add_world_mesh(s, lines);
  Mesh points = make_point_set({{0, 2, 0}, {1, 2, 0}}, "points");  // sized by the render
  add_world_mesh(s, points);
  const auto dir = temp_dir("gltf-writer-curves");
  write_gltf(s, dir / "curves.gltf");
  const LoadedScene l = load_gltf(dir / "curves.gltf");
  REQUIRE(l.scene.meshes.size() == 2);
  const Mesh& rl = l.scene.meshes[0];
  CHECK(rl.lines);
  CHECK(rl.indices == lines.indices);
  CHECK(rl.file_radii);
  REQUIRE(rl.radii.size() == 3);
  for (size_t i = 0; i < 3; ++i) CHECK(rl.radii[i] == Approx(lines.radii[i]));
  const Mesh& rp = l.scene.meshes[1];
  CHECK(rp.points);
  CHECK(rp.indices == points.indices);
  CHECK(rp.radii.empty());
  CHECK(l.scene.materials[size_t(rp.material)].unlit);  // no NORMAL written: unlit again
}
