// The PENUMBRA_shapes node extension (io/gltf/shapes.cpp): every field and its default, the CSG
// primitives and operators against their closed-form distances, CSG and node transforms,
// EXT_mesh_gpu_instancing and animation on shape nodes, materials, the extension lists, one test
// per class of bad value (each error names the file, the JSON path and the field), the depth and
// size limits, and the shipped shape scenes rendered with every accelerator.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>

#include "io/files/error.h"
#include "io/gltf/gltf_writer.h"
#include "io/gltf/loader.h"
#include "renderer/accel/factory.h"
#include "renderer/integrators/render.h"
#include "renderer/integrators/scene_accel.h"
#include "support/gltf_load.h"
#include "support/gltf_writer.h"
#include "support/scene_builder.h"
#include "support/sdf_trees.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;
using Catch::Matchers::EndsWith;
using penumbra::test::GltfWriter;
using json = nlohmann::json;

namespace {

const std::string kExt = "nodes[0].extensions.PENUMBRA_shapes";
const std::string kCsg = kExt + ".csg";

/// A file whose only root node carries `ext` as its PENUMBRA_shapes extension (plus `fields`),
/// with two materials "m0" and "m1".
GltfWriter shape_file(json ext, json fields = json::object()) {
  GltfWriter w;
  w.j["materials"] = json::array({{{"name", "m0"}}, {{"name", "m1"}}});
  w.j["extensionsUsed"] = {"PENUMBRA_shapes"};
  fields["extensions"]["PENUMBRA_shapes"] = std::move(ext);
  w.node(std::move(fields));
  return w;
}

/// A fresh folder name per load, so files never collide.
std::string next_name() {
  static int n = 0;
  return "shapes-" + std::to_string(n++);
}

LoadedScene load_shape(json ext, GltfLoadOptions opt = {}) {
  GltfWriter w = shape_file(std::move(ext));
  return test::write_and_load(w, next_name(), opt);
}

/// The one shape the extension object `ext` loads to.
Shape shape_of(json ext) {
  const LoadedScene l = load_shape(std::move(ext));
  REQUIRE(l.scene.shapes.size() == 1);
  return l.scene.shapes[0].shape;
}

json implicit(json csg) {
  return {{"type", "implicit"}, {"csg", std::move(csg)}};
}

/// The CSG tree an implicit shape with root `csg` loads to.
SdfTree tree_of(json csg) {
  const Shape s = shape_of(implicit(std::move(csg)));
  REQUIRE(s.kind == ShapeKind::Implicit);
  return s.sdf;
}

/// The node of `kind` in `tree` (the first one).
const SdfNode& node_of(const SdfTree& tree, SdfKind kind) {
  for (const SdfNode& n : tree.nodes)
    if (n.kind == kind) return n;
  FAIL("no node of the kind in the tree");
  return tree.nodes.at(0);
}

/// What loading the file with extension object `ext` throws (InputError's text), or "" if it loads.
std::string error_of(json ext, GltfLoadOptions opt = {}) {
  try {
    load_shape(std::move(ext), opt);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// The error of the raw JSON text `text` (a whole glTF file), or "" if it loads.
std::string error_of_text(const std::string& text) {
  const auto dir = test::temp_dir(next_name());
  std::ofstream(dir / "scene.gltf") << text;
  try {
    load_gltf(dir / "scene.gltf");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

json sphere(float radius, std::vector<float> translation = {}) {
  json j = {{"type", "sphere"}, {"radius", radius}};
  if (!translation.empty()) j["translation"] = translation;
  return j;
}

json op(const char* type, json children) {
  return {{"type", type}, {"children", std::move(children)}};
}

}  // namespace

TEST_CASE("shapes: analytic shapes read every field and apply the defaults", "[io][gltf][shapes][quick]") {
  SECTION("sphere and disk: radius, default 1") {
    CHECK(shape_of({{"type", "sphere"}}).radius == 1);
    CHECK(shape_of({{"type", "sphere"}, {"radius", 2.5}}).radius == 2.5f);
    CHECK(shape_of({{"type", "disk"}}).kind == ShapeKind::Disk);
    CHECK(shape_of({{"type", "disk"}}).radius == 1);
    CHECK(shape_of({{"type", "disk"}, {"radius", 0.5}}).radius == 0.5f);
  }
  SECTION("plane: size [w, d], default [2, 2], halved") {
    const Shape def = shape_of({{"type", "plane"}});
    CHECK(def.kind == ShapeKind::Plane);
    CHECK(def.half_size.x == 1);
    CHECK(def.half_size.z == 1);
    const Shape p = shape_of({{"type", "plane"}, {"size", {4, 6}}});
    CHECK(p.half_size.x == 2);
    CHECK(p.half_size.z == 3);
  }
  SECTION("box: size [x, y, z] full extents, default [1, 1, 1]") {
    test::check_vec(shape_of({{"type", "box"}}).half_size, {0.5f, 0.5f, 0.5f});
    test::check_vec(shape_of({{"type", "box"}, {"size", {2, 4, 6}}}).half_size, {1, 2, 3});
  }
  SECTION("capsule: radius (default 0.5) and height (default 1, half_height = height / 2)") {
    const Shape def = shape_of({{"type", "capsule"}});
    CHECK(def.kind == ShapeKind::Capsule);
    CHECK(def.radius == 0.5f);
    CHECK(def.half_height == 0.5f);
    const Shape c = shape_of({{"type", "capsule"}, {"radius", 0.25}, {"height", 3}});
    CHECK(c.radius == 0.25f);
    CHECK(c.half_height == 1.5f);
    CHECK(shape_of({{"type", "capsule"}, {"height", 0}}).half_height == 0);  // a sphere
  }
  SECTION("implicit: maxSteps (default 512) and epsilon (default 1e-5)") {
    const Shape def = shape_of(implicit(sphere(1)));
    CHECK(def.trace.max_steps == 512);
    CHECK(def.trace.relative_epsilon == 1e-5f);
    json ext = implicit(sphere(1));
    ext["maxSteps"] = 64;
    ext["epsilon"] = 1e-3;
    const Shape s = shape_of(ext);
    CHECK(s.trace.max_steps == 64);
    CHECK(s.trace.relative_epsilon == 1e-3f);
    CHECK(s.lipschitz == Approx(1));
    test::check_vec(s.sdf_bounds.lo, {-1, -1, -1});
    test::check_vec(s.sdf_bounds.hi, {1, 1, 1});
  }
  SECTION("material: default none, else the index; name and node from the glTF node") {
    GltfWriter w = shape_file({{"type", "sphere"}, {"material", 1}}, {{"name", "ball"}});
    w.node({{"extensions", {{"PENUMBRA_shapes", {{"type", "box"}}}}}});
    const LoadedScene l = test::write_and_load(w, next_name());
    CHECK(l.warnings.empty());
    REQUIRE(l.scene.shapes.size() == 2);
    CHECK(l.scene.shapes[0].material == 1);
    CHECK(l.scene.shapes[0].name == "ball");
    CHECK(l.scene.shapes[0].node == 0);
    CHECK(l.scene.shapes[1].material == -1);
    CHECK(l.scene.shapes[1].name == "nodes[1]");
    REQUIRE(l.scene.instances.size() == 2);
    CHECK(instance_material(l.scene, l.scene.instances[0]) == 1);
    CHECK(instance_material(l.scene, l.scene.instances[1]) == -1);
    CHECK(l.scene.instances[0].shape == 0);
    CHECK(l.scene.instances[0].mesh == -1);
    CHECK(l.scene.instances[0].copy == -1);
    CHECK(l.scene.instances[1].node == 1);
  }
}

TEST_CASE("shapes: CSG primitives map their fields and give their closed-form distances",
          "[io][gltf][shapes][quick]") {
  auto f = [](const SdfTree& t, Vec3f p) { return sdf_eval(t, p); };
  SECTION("sphere: radius, default 1") {
    CHECK(f(tree_of({{"type", "sphere"}}), {3, 0, 0}) == Approx(2));
    const SdfTree t = tree_of(sphere(2));
    CHECK(t.nodes.at(0).size.x == 2);
    CHECK(f(t, {0, 0, 0}) == Approx(-2));
    CHECK(f(t, {0, 3, 0}) == Approx(1));
  }
  SECTION("box: size full extents, default [1, 1, 1]") {
    CHECK(f(tree_of({{"type", "box"}}), {1, 0, 0}) == Approx(0.5));
    const SdfTree t = tree_of({{"type", "box"}, {"size", {2, 4, 6}}});
    test::check_vec(t.nodes.at(0).size, {1, 2, 3});
    CHECK(f(t, {3, 0, 0}) == Approx(2));
    CHECK(f(t, {0, 0, 0}) == Approx(-1));
  }
  SECTION("roundBox: size and edge radius") {
    const SdfTree t = tree_of({{"type", "roundBox"}, {"size", {2, 2, 2}}, {"radius", 0.5}});
    CHECK(t.nodes.at(0).radius == 0.5f);
    test::check_vec(t.nodes.at(0).size, {1, 1, 1});
    CHECK(f(t, {2, 0, 0}) == Approx(1));
    CHECK(f(t, {2, 2, 2}) == Approx(1.5 * std::sqrt(3.0) - 0.5));  // to the rounded corner
  }
  SECTION("capsule, cylinder, cone: radius (default 0.5), height (default 1) along Y") {
    const SdfTree capsule = tree_of({{"type", "capsule"}, {"radius", 0.5}, {"height", 2}});
    CHECK(capsule.nodes.at(0).size.y == 1);
    CHECK(f(capsule, {0, 2, 0}) == Approx(0.5));
    CHECK(f(capsule, {1, 0, 0}) == Approx(0.5));
    const SdfTree cylinder = tree_of({{"type", "cylinder"}, {"radius", 0.5}, {"height", 2}});
    CHECK(f(cylinder, {0, 2, 0}) == Approx(1));
    CHECK(f(cylinder, {1, 0, 0}) == Approx(0.5));
    const SdfTree cone = tree_of({{"type", "cone"}, {"radius", 1}, {"height", 2}});
    CHECK(cone.nodes.at(0).radius == 1);
    CHECK(f(cone, {0, -2, 0}) == Approx(1));  // below the base's centre
    CHECK(f(cone, {0, 2, 0}) == Approx(1));   // above the apex
    for (const char* type : {"capsule", "cylinder", "cone"}) {
      const SdfNode n = tree_of({{"type", type}}).nodes.at(0);
      CHECK(n.radius == 0.5f);
      CHECK(n.size.y == 0.5f);
    }
  }
  SECTION("torus: majorRadius (default 1) and minorRadius (default 0.25)") {
    const SdfNode def = tree_of({{"type", "torus"}}).nodes.at(0);
    CHECK(def.size.x == 1);
    CHECK(def.radius == 0.25f);
    const SdfTree t = tree_of({{"type", "torus"}, {"majorRadius", 2}, {"minorRadius", 0.5}});
    CHECK(f(t, {2, 0, 0}) == Approx(-0.5));
    CHECK(f(t, {0, 0, 0}) == Approx(1.5));
    CHECK(f(t, {0, 0, 2}) == Approx(-0.5));
  }
  SECTION("halfSpace: normal normalised (default +Y), offset along it (default 0)") {
    const SdfTree t = tree_of(
        op("intersection", {{{"type", "halfSpace"}, {"normal", {0, 2, 0}}, {"offset", 1}}, sphere(100)}));
    const SdfNode& h = node_of(t, SdfKind::HalfSpace);
    test::check_vec(h.normal, {0, 1, 0});
    CHECK(h.offset == 1);
    CHECK(f(t, {0, 3, 0}) == Approx(2));
    CHECK(f(t, {0, -3, 0}) == Approx(-4));
    const SdfTree defaults = tree_of(op("intersection", {{{"type", "halfSpace"}}, sphere(1)}));
    const SdfNode& def = node_of(defaults, SdfKind::HalfSpace);
    test::check_vec(def.normal, {0, 1, 0});
    CHECK(def.offset == 0);
  }
  SECTION("convexPolyhedron: planes normalised with d scaled") {
    json planes = json::array();
    for (int k = 0; k < 3; ++k)
      for (float s : {2.0f, -2.0f}) {
        std::vector<float> p = {0, 0, 0, 2};  // |x_k| <= 1 with normals of length 2
        p[size_t(k)] = s;
        planes.push_back(p);
      }
    const SdfTree t = tree_of({{"type", "convexPolyhedron"}, {"planes", planes}});
    REQUIRE(t.planes.size() == 6);
    CHECK(t.nodes.at(0).plane_count == 6);
    CHECK(t.planes[0].x == 1);
    CHECK(t.planes[0].w == 1);
    CHECK(f(t, {3, 0, 0}) == Approx(2));
    CHECK(f(t, {0, 0, 0}) == Approx(-1));
  }
}

TEST_CASE("shapes: CSG operators fold their children left to right", "[io][gltf][shapes][quick]") {
  auto f = [](const SdfTree& t, Vec3f p) { return sdf_eval(t, p); };
  SECTION("union of three: ((c0 u c1) u c2)") {
    const SdfTree t = tree_of(op("union", {sphere(1), sphere(2), sphere(3)}));
    REQUIRE(t.nodes.size() == 5);
    const SdfNode& root = t.nodes.at(size_t(t.root));
    CHECK(root.kind == SdfKind::Union);
    CHECK(t.nodes.at(size_t(root.b)).size.x == 3);
    const SdfNode& inner = t.nodes.at(size_t(root.a));
    CHECK(inner.kind == SdfKind::Union);
    CHECK(t.nodes.at(size_t(inner.a)).size.x == 1);
    CHECK(t.nodes.at(size_t(inner.b)).size.x == 2);
    CHECK(f(t, {4, 0, 0}) == Approx(1));
  }
  SECTION("subtraction: the first minus each of the others") {
    const SdfTree t = tree_of(op("subtraction", {sphere(3), sphere(1, {2, 0, 0}), sphere(1, {-2, 0, 0})}));
    CHECK(f(t, {2, 0, 0}) == Approx(1));
    CHECK(f(t, {-2, 0, 0}) == Approx(1));
    CHECK(f(t, {0, 0, 0}) == Approx(-1));
    CHECK(f(t, {0, 2.5f, 0}) == Approx(-0.5));
  }
  SECTION("intersection and complement: a shell") {
    const SdfTree t = tree_of(op("intersection", {sphere(2), op("complement", {sphere(1)})}));
    CHECK(node_of(t, SdfKind::Complement).b == -1);
    CHECK(f(t, {0, 0, 0}) == Approx(1));
    CHECK(f(t, {1.5f, 0, 0}) == Approx(-0.5));
    CHECK(f(t, {3, 0, 0}) == Approx(1));
  }
  SECTION("smooth operators keep their blend radius") {
    json u = op("smoothUnion", {sphere(1, {-1.5f, 0, 0}), sphere(1, {1.5f, 0, 0})});
    u["radius"] = 1;
    const SdfTree t = tree_of(u);
    CHECK(t.nodes.at(size_t(t.root)).radius == 1);
    // Both parts 0.5 away at the origin: the polynomial smooth minimum is 0.5 - k / 4.
    CHECK(f(t, {0, 0, 0}) == Approx(0.25));
    CHECK(f(t, {-1.5f, 0, 0}) == Approx(-1).margin(1e-6));  // far from the blend
    for (const char* type : {"smoothIntersection", "smoothSubtraction"}) {
      json s = op(type, {sphere(2), sphere(1, {1.5f, 0, 0})});
      s["radius"] = 0.25;
      const SdfTree st = tree_of(s);
      CHECK(st.nodes.at(size_t(st.root)).radius == 0.25f);
    }
  }
}

TEST_CASE("shapes: CSG transforms place a node's frame in its parent's", "[io][gltf][shapes][quick]") {
  auto f = [](const SdfTree& t, Vec3f p) { return sdf_eval(t, p); };
  SECTION("a child's translation") {
    const SdfTree t = tree_of(op("union", {sphere(1), sphere(1, {3, 0, 0})}));
    CHECK(f(t, {3, 0, 0}) == Approx(-1));
    CHECK(f(t, {1.5f, 0, 0}) == Approx(0.5));
    CHECK(f(t, {5, 0, 0}) == Approx(1));
    CHECK(f(t, {3, 1.5f, 0}) == Approx(0.5));
  }
  SECTION("rotation: a cylinder turned 90 degrees about Z lies along X") {
    const float h = float(std::sqrt(0.5));
    const SdfTree t =
        tree_of({{"type", "cylinder"}, {"radius", 0.5}, {"height", 2}, {"rotation", {0, 0, h, h}}});
    CHECK(f(t, {2, 0, 0}) == Approx(1));
    CHECK(f(t, {0, 1, 0}) == Approx(0.5));
  }
  SECTION("scale: the zero set scales, the Lipschitz bound follows the inverse") {
    const SdfTree t = tree_of({{"type", "sphere"}, {"scale", {2, 2, 2}}});
    CHECK(f(t, {2, 0, 0}) == Approx(0).margin(1e-6));
    CHECK(f(t, {1.9f, 0, 0}) < 0);
    CHECK(f(t, {2.1f, 0, 0}) > 0);
    CHECK(sdf_lipschitz(t) == Approx(0.5));
    const Shape s = shape_of(implicit({{"type", "box"}, {"scale", {1, 2, -3}}}));
    test::check_vec(s.sdf_bounds.hi, {0.5f, 1, 1.5f}, 1e-5f);
  }
  SECTION("matrix: column-major as glTF, the same as TRS") {
    const SdfTree m = tree_of(
        op("union",
           {sphere(1), {{"type", "sphere"}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 3, 0, 0, 1}}}}));
    CHECK(f(m, {3, 0, 0}) == Approx(-1));
    CHECK(f(m, {5, 0, 0}) == Approx(1));
  }
  SECTION("an operator's transform moves its children; a child's composes after it") {
    json u = op("union", {sphere(1), sphere(1, {3, 0, 0})});
    u["translation"] = {0, 5, 0};
    const SdfTree t = tree_of(u);
    CHECK(f(t, {0, 5, 0}) == Approx(-1));
    CHECK(f(t, {3, 5, 0}) == Approx(-1));
    CHECK(f(t, {3, 0, 0}) == Approx(4));
  }
}

TEST_CASE("shapes: nodes place shapes with their world transform, hierarchy included",
          "[io][gltf][shapes][quick]") {
  GltfWriter w;
  const double h = std::sqrt(0.5);
  const int child = w.node({{"translation", {1, 2, 3}},
                            {"scale", {2, 2, 2}},
                            {"extensions", {{"PENUMBRA_shapes", {{"type", "sphere"}}}}}},
                           false);
  w.node({{"translation", {10, 0, 0}}, {"rotation", {0, h, 0, h}}, {"children", {child}}});
  const LoadedScene l = test::write_and_load(w, next_name());
  REQUIRE(l.scene.instances.size() == 1);
  const Instance& inst = l.scene.instances[0];
  CHECK(inst.node == child);
  CHECK_FALSE(inst.identity);
  // Parent x child: p -> R_y(90) (2 p + (1, 2, 3)) + (10, 0, 0); R_y(90) maps (x, y, z) to (z, y, -x).
  test::check_vec(apply_point(inst.to_world, {0, 0, 0}), {13, 2, -1}, 1e-5f);
  test::check_vec(apply_point(inst.to_world, {1, 0, 0}), {13, 2, -3}, 1e-5f);
  test::check_vec(apply_point(inst.to_object, {13, 2, -3}), {1, 0, 0}, 1e-5f);
  const Bounds3f b = compute_bounds(l.scene);
  test::check_vec(b.lo, {11, 0, -3}, 1e-4f);
  test::check_vec(b.hi, {15, 4, 1}, 1e-4f);
}

TEST_CASE(
    "shapes: EXT_mesh_gpu_instancing places one instance per copy; a node's mesh and shape are both placed",
    "[io][gltf][shapes][instances][quick]") {
  GltfWriter w;
  const std::vector<float> t = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  const int acc = w.accessor(t.data(), t.size() * 4, 5126, 3, "VEC3");
  const int quad =
      w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
  w.node({{"translation", {0, 0, 5}},
          {"mesh", quad},
          {"extensions",
           {{"PENUMBRA_shapes", {{"type", "sphere"}, {"radius", 0.25}}},
            {"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", acc}}}}}}}});
  w.j["extensionsUsed"] = {"PENUMBRA_shapes", "EXT_mesh_gpu_instancing"};
  const LoadedScene l = test::write_and_load(w, next_name());
  CHECK(l.warnings.empty());
  const Scene& s = l.scene;
  REQUIRE(s.shapes.size() == 1);
  CHECK(count_shape_instances(s) == 3);
  std::vector<const Instance*> shapes, meshes;
  for (const Instance& inst : s.instances) (inst.shape >= 0 ? shapes : meshes).push_back(&inst);
  REQUIRE(shapes.size() == 3);
  CHECK(meshes.size() == 3);  // the quad, once per copy too
  for (int k = 0; k < 3; ++k) {
    CHECK(shapes[size_t(k)]->shape == 0);
    CHECK(shapes[size_t(k)]->copy == k);
    CHECK(shapes[size_t(k)]->node == 0);
    test::check_vec(apply_point(shapes[size_t(k)]->to_world, {0, 0, 0}), {float(k), 0, 5}, 1e-6f);
  }
}

TEST_CASE("shapes: a shape node's animation is evaluated at the load time",
          "[io][gltf][shapes][animation][quick]") {
  GltfWriter w = shape_file({{"type", "box"}});
  const std::vector<float> times = {0, 2}, values = {0, 0, 0, 4, 0, 0};
  const int in = w.accessor(times.data(), 8, 5126, 2, "SCALAR");
  const int out = w.accessor(values.data(), 24, 5126, 2, "VEC3");
  w.j["animations"] =
      json::array({{{"samplers", {{{"input", in}, {"output", out}}}},
                    {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}});
  GltfLoadOptions opt;
  opt.time = 0.5;
  const LoadedScene l = test::write_and_load(w, next_name(), opt);
  REQUIRE(l.scene.instances.size() == 1);
  test::check_vec(apply_point(l.scene.instances[0].to_world, {0, 0, 0}), {1, 0, 0}, 1e-6f);
  const LoadedScene still = test::write_and_load(w, next_name());
  CHECK(still.scene.instances.at(0).identity);
}

TEST_CASE("shapes: the extension is supported, required or only used", "[io][gltf][shapes][quick]") {
  const auto supported = supported_gltf_extensions();
  CHECK(std::find(supported.begin(), supported.end(), "PENUMBRA_shapes") != supported.end());
  GltfWriter w = shape_file({{"type", "sphere"}});
  w.j["extensionsRequired"] = {"PENUMBRA_shapes"};
  const LoadedScene l = test::write_and_load(w, next_name());
  CHECK(l.warnings.empty());
  CHECK(l.scene.shapes.size() == 1);
  CHECK(l.info.extensions_required == std::vector<std::string>{"PENUMBRA_shapes"});
  // A node outside the scene is checked but not placed.
  GltfWriter off = shape_file({{"type", "sphere"}});
  off.node({{"extensions", {{"PENUMBRA_shapes", {{"type", "box"}}}}}}, false);
  const LoadedScene o = test::write_and_load(off, next_name());
  CHECK(o.scene.shapes.size() == 1);
  CHECK(o.scene.instances.size() == 1);
  GltfWriter bad = shape_file({{"type", "sphere"}});
  bad.node({{"extensions", {{"PENUMBRA_shapes", {{"type", "box"}, {"size", 1}}}}}}, false);
  CHECK_THROWS_WITH(test::write_and_load(bad, next_name()),
                    Contains("nodes[1].extensions.PENUMBRA_shapes.size"));
}

TEST_CASE("shapes: unknown keys and keys of another type are errors naming them",
          "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of({{"type", "sphere"}, {"colour", 1}}),
             Contains("scene.gltf: " + kExt + ".colour: unknown key") && Contains("type, material, radius"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"size", {1, 1, 1}}}),
             Contains(kExt + ".size: does not apply to a \"sphere\" shape"));
  CHECK_THAT(error_of({{"type", "box"}, {"csg", sphere(1)}}),
             Contains(kExt + ".csg: does not apply to a \"box\""));
  CHECK_THAT(error_of(implicit({{"type", "sphere"}, {"height", 1}})),
             Contains(kCsg + ".height: does not apply to a \"sphere\" CSG node"));
  CHECK_THAT(error_of(implicit(op("union", {sphere(1), {{"type", "sphere"}, {"extras", 1}}}))),
             Contains(kCsg + ".children[1].extras: unknown key"));
  CHECK_THAT(error_of(implicit({{"type", "union"}, {"radius", 1}, {"children", {sphere(1), sphere(2)}}})),
             Contains(kCsg + ".radius: does not apply to a \"union\" CSG node"));
}

TEST_CASE("shapes: unknown and missing types are errors listing the known ones",
          "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of({{"type", "cube"}}),
             Contains(kExt + ".type: unknown shape type \"cube\"") && Contains("sphere, plane, disk, box"));
  CHECK_THAT(error_of(json::object()), Contains(kExt + ".type: is required"));
  CHECK_THAT(error_of(implicit({{"type", "pyramid"}})),
             Contains(kCsg + ".type: unknown CSG node type \"pyramid\"") && Contains("convexPolyhedron"));
  CHECK_THAT(error_of(implicit(op("union", {sphere(1), {{"radius", 1}}}))),
             Contains(kCsg + ".children[1].type: is required"));
}

TEST_CASE("shapes: missing required fields are errors naming them", "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of({{"type", "implicit"}}), Contains(kCsg + ": is required"));
  CHECK_THAT(error_of(implicit({{"type", "union"}})), Contains(kCsg + ".children: is required"));
  CHECK_THAT(error_of(implicit({{"type", "convexPolyhedron"}})), Contains(kCsg + ".planes: is required"));
  CHECK_THAT(error_of(implicit({{"type", "roundBox"}})), Contains(kCsg + ".radius: is required"));
  CHECK_THAT(error_of(implicit(op("smoothUnion", {sphere(1), sphere(1)}))),
             Contains(kCsg + ".radius: is required"));
}

TEST_CASE("shapes: wrong JSON types are errors naming the field", "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of(json::array({1})), Contains(kExt + ": must be an object"));
  CHECK_THAT(error_of({{"type", 3}}), Contains(kExt + ".type: must be a string"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"radius", "1"}}),
             Contains(kExt + ".radius: must be a number (got \"1\")"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"radius", true}}), Contains(kExt + ".radius: must be a number"));
  CHECK_THAT(error_of({{"type", "box"}, {"size", 1}}),
             Contains(kExt + ".size: must be an array of 3 numbers"));
  CHECK_THAT(error_of({{"type", "plane"}, {"size", {1, 2, 3}}}),
             Contains(kExt + ".size: must be an array of 2 numbers"));
  CHECK_THAT(error_of({{"type", "box"}, {"size", {1, "2", 3}}}),
             Contains(kExt + ".size[1]: must be a number"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"material", 0.5}}),
             Contains(kExt + ".material: must be an integer material index"));
  json steps = implicit(sphere(1));
  steps["maxSteps"] = 12.5;
  CHECK_THAT(error_of(steps), Contains(kExt + ".maxSteps: must be an integer"));
  CHECK_THAT(error_of(implicit(json::array())), Contains(kCsg + ": must be a CSG node object"));
  CHECK_THAT(error_of(implicit({{"type", "union"}, {"children", sphere(1)}})),
             Contains(kCsg + ".children: must be an array"));
  CHECK_THAT(error_of(implicit(op("union", {sphere(1), 7}))),
             Contains(kCsg + ".children[1]: must be a CSG node object"));
  CHECK_THAT(error_of(implicit({{"type", "convexPolyhedron"}, {"planes", {1, 2, 3, 4}}})),
             Contains(kCsg + ".planes[0]: must be an array of 4 numbers"));
  CHECK_THAT(error_of(implicit({{"type", "sphere"}, {"translation", {1, 2}}})),
             Contains(kCsg + ".translation: must be an array of 3 numbers"));
}

TEST_CASE("shapes: zero, negative, overflowing and out-of-range numbers are errors naming the field",
          "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of({{"type", "sphere"}, {"radius", 0}}), Contains(kExt + ".radius: must be > 0 (got 0)"));
  CHECK_THAT(error_of({{"type", "disk"}, {"radius", -1}}), Contains(kExt + ".radius: must be > 0 (got -1)"));
  CHECK_THAT(error_of({{"type", "box"}, {"size", {1, 0, 1}}}), Contains(kExt + ".size[1]: must be > 0"));
  CHECK_THAT(error_of({{"type", "plane"}, {"size", {-2, 2}}}), Contains(kExt + ".size[0]: must be > 0"));
  CHECK_THAT(error_of({{"type", "capsule"}, {"height", -1}}), Contains(kExt + ".height: must be >= 0"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"radius", 1e39}}),
             Contains(kExt + ".radius: is beyond the 32-bit float range"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"radius", 1e-50}}),
             Contains(kExt + ".radius: must be > 0") && Contains("0 as a 32-bit float"));
  CHECK_THAT(error_of(implicit(op("union", {sphere(1), sphere(0)}))),
             Contains("scene.gltf: " + kCsg + ".children[1].radius: must be > 0"));
  CHECK_THAT(error_of(implicit({{"type", "cylinder"}, {"height", 0}})),
             Contains(kCsg + ".height: must be > 0"));
  CHECK_THAT(error_of(implicit({{"type", "torus"}, {"majorRadius", 1}, {"minorRadius", 1}})),
             Contains(kCsg + ".minorRadius: must be < majorRadius"));
  CHECK_THAT(error_of(implicit({{"type", "roundBox"}, {"size", {1, 0.2, 1}}, {"radius", 0.2}})),
             Contains(kCsg + ".radius: must be <= the smallest half extent 0.1"));
  CHECK_THAT(
      error_of(implicit(op("intersection", {{{"type", "halfSpace"}, {"normal", {0, 0, 0}}}, sphere(1)}))),
      Contains(kCsg + ".children[0].normal: must be non-zero"));
  json smooth = op("smoothUnion", {sphere(1), sphere(1)});
  smooth["radius"] = -0.5;
  CHECK_THAT(error_of(implicit(smooth)), Contains(kCsg + ".radius: must be > 0"));
  for (int steps : {0, 100001}) {
    json e = implicit(sphere(1));
    e["maxSteps"] = steps;
    CHECK_THAT(error_of(e), Contains(kExt + ".maxSteps: must be in [1, 100000]"));
  }
  for (double eps : {0.0, 0.1}) {
    json e = implicit(sphere(1));
    e["epsilon"] = eps;
    CHECK_THAT(error_of(e), Contains(kExt + ".epsilon: must be"));
  }
  // JSON has no NaN or infinity: such literals are parse errors before any field is read.
  const std::string head =
      R"({"asset":{"version":"2.0"},"nodes":[{"extensions":{"PENUMBRA_shapes":{"type":"sphere","radius":)";
  CHECK_THAT(error_of_text(head + "NaN}}}]}"), Contains("JSON: parse error"));
  CHECK_THAT(error_of_text(head + "1e999}}}]}"), Contains("JSON: parse error") && Contains("overflow"));
}

TEST_CASE("shapes: empty, missing or miscounted children are errors naming them",
          "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of(implicit(op("union", json::array()))),
             Contains(kCsg + ".children: must hold at least 2 CSG nodes (got 0)"));
  CHECK_THAT(error_of(implicit(op("subtraction", {sphere(1)}))),
             Contains(kCsg + ".children: must hold at least 2"));
  CHECK_THAT(error_of(implicit(op("complement", {sphere(1), sphere(2)}))),
             Contains(kCsg + ".children: must hold exactly 1 CSG node (got 2)"));
  CHECK_THAT(error_of(implicit(
                 {{"type", "convexPolyhedron"}, {"planes", {{1, 0, 0, 1}, {-1, 0, 0, 1}, {0, 1, 0, 1}}}})),
             Contains(kCsg + ".planes: must hold 4 to 4096 planes (got 3)"));
  CHECK_THAT(error_of(implicit({{"type", "convexPolyhedron"},
                                {"planes", {{1, 0, 0, 1}, {-1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 0, 1}}}})),
             Contains(kCsg + ".planes[3]: the normal") && Contains("non-zero"));
}

TEST_CASE("shapes: a material index outside the materials is an error",
          "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of({{"type", "sphere"}, {"material", 2}}),
             Contains(kExt + ".material: index 2 out of range (2 materials)"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"material", -1}}),
             Contains(kExt + ".material: index -1 is negative"));
  CHECK_THAT(error_of({{"type", "sphere"}, {"material", 4294967296}}),
             Contains(kExt + ".material: index 4294967296 out of range"));
}

TEST_CASE("shapes: degenerate CSG transforms are errors naming the node",
          "[io][gltf][shapes][hostile][quick]") {
  CHECK_THAT(error_of(implicit({{"type", "sphere"}, {"scale", {1, 0, 1}}})),
             Contains(kCsg + ".scale[1]: must be non-zero"));
  CHECK_THAT(error_of(implicit({{"type", "sphere"}, {"rotation", {0, 0, 0, 2}}})),
             Contains(kCsg + ".rotation: must be a unit quaternion (length 2)"));
  CHECK_THAT(
      error_of(implicit({{"type", "sphere"}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}}})),
      Contains(kCsg + ".matrix: the transform is singular"));
  CHECK_THAT(
      error_of(implicit({{"type", "sphere"}, {"matrix", {1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}})),
      Contains(kCsg + ".matrix: must be affine"));
  CHECK_THAT(error_of(implicit({{"type", "sphere"},
                                {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}},
                                {"translation", {1, 0, 0}}})),
             Contains(kCsg + ".matrix: cannot be given together with translation"));
  CHECK_THAT(
      error_of(implicit(op(
          "union", {sphere(1),
                    {{"type", "sphere"}, {"scale", {1e-30, 1e-30, 1e-30}}, {"translation", {1e30, 0, 0}}}}))),
      Contains(kCsg +
               ".children[1]: the transform is singular or its inverse is beyond the 32-bit float range"));
}

TEST_CASE("shapes: an implicit shape whose inside is unbounded or empty is an error",
          "[io][gltf][shapes][hostile][quick]") {
  const std::string unbounded =
      kCsg + ": the shape's inside is unbounded (intersect half-spaces and complements with a finite shape)";
  CHECK_THAT(error_of(implicit({{"type", "halfSpace"}})), Contains(unbounded));
  CHECK_THAT(error_of(implicit(op("complement", {sphere(1)}))), Contains(unbounded));
  CHECK_THAT(error_of(implicit(op("union", {sphere(1), {{"type", "halfSpace"}}}))), Contains(unbounded));
  CHECK_THAT(error_of(implicit(op("subtraction", {op("complement", {sphere(1)}), sphere(2)}))),
             Contains(unbounded));
  CHECK_THAT(error_of(implicit({{"type", "convexPolyhedron"},
                                {"planes", {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 1}}}})),
             Contains(unbounded));
  CHECK_THAT(error_of(implicit(op("intersection", {sphere(1), sphere(1, {5, 0, 0})}))),
             Contains(kCsg + ": the shape's inside is empty"));
  // Intersected with something finite, half-spaces and complements are fine.
  CHECK(error_of(implicit(
            op("intersection", {{{"type", "halfSpace"}}, op("complement", {sphere(1)}), sphere(2)}))) == "");
}

namespace {

// `levels` operators nested through their first child, each with a sphere as its second.
json nested_unions(int levels) {
  json j = sphere(1);
  for (int i = 0; i < levels; ++i) j = op("union", {j, sphere(1)});
  return j;
}

// A balanced union tree of 2^depth spheres (2^(depth + 1) - 1 nodes).
json balanced(int depth) {
  return depth == 0 ? sphere(1) : op("union", {balanced(depth - 1), balanced(depth - 1)});
}

}  // namespace

TEST_CASE("shapes: CSG trees deeper than kMaxSdfDepth or larger than 4096 nodes are refused",
          "[io][gltf][shapes][hostile][quick]") {
  GltfLoadOptions deep_json;
  deep_json.max_json_depth = 4000;
  // 63 nested operators put their deepest leaves at level 64: allowed; one more is not.
  CHECK(error_of(implicit(nested_unions(63)), deep_json) == "");
  CHECK_THAT(error_of(implicit(nested_unions(64)), deep_json),
             Contains(kCsg + ".children[0]") && Contains("deeper than 64 levels"));
  // Checked before recursing: a thousand levels end in the same error, not in a stack overflow.
  json chain = sphere(1);
  for (int i = 0; i < 1000; ++i) chain = op("complement", {chain});
  CHECK_THAT(error_of(implicit(op("intersection", {chain, sphere(2)})), deep_json),
             Contains("deeper than 64 levels"));
  // A union of n children folds into n - 1 nested binary nodes.
  json wide = json::array();
  for (int i = 0; i < 64; ++i) wide.push_back(sphere(1, {float(i), 0, 0}));
  CHECK(error_of(implicit(op("union", wide))) == "");
  wide.push_back(sphere(1));
  CHECK_THAT(error_of(implicit(op("union", wide))),
             Contains(kCsg + ".children: 65 children fold into 64 nested binary nodes"));
  // 2^11 leaves (4095 nodes) load; 2^12 leaves (8191 nodes) are too many.
  CHECK(error_of(implicit(balanced(11))) == "");
  CHECK_THAT(error_of(implicit(balanced(12))), Contains("the CSG tree has more than 4096 nodes"));
}

TEST_CASE("shapes: CSG nodes are charged to the memory budget as they are read",
          "[io][gltf][shapes][hostile][quick]") {
  // The smallest budget that loads a 127-node tree is reached while its nodes are read (the
  // raw JSON's DOM is still charged then); a byte less fails naming the tree.
  GltfWriter w = shape_file(implicit(balanced(6)));
  const auto dir = test::temp_dir(next_name());
  w.write_embedded(dir / "scene.gltf");
  auto loads = [&](uint64_t budget, std::string* error) {
    GltfLoadOptions opt;
    opt.max_memory_bytes = budget;
    try {
      load_gltf(dir / "scene.gltf", opt);
      return true;
    } catch (const InputError& e) {
      if (error) *error = e.what();
      return false;
    }
  };
  uint64_t lo = 1, hi = 1ull << 30;  // loads(hi), !loads(lo)
  REQUIRE(loads(hi, nullptr));
  while (hi - lo > 1) {
    const uint64_t mid = lo + (hi - lo) / 2;
    (loads(mid, nullptr) ? hi : lo) = mid;
  }
  std::string error;
  REQUIRE_FALSE(loads(lo, &error));
  CHECK_THAT(error, Contains(kCsg) && Contains("its CSG node needs"));
}

TEST_CASE("shapes: shape placements are charged to the memory budget before they are made",
          "[io][gltf][shapes][hostile][quick]") {
  // Translations from an accessor without a bufferView (all zeros): 10^7 declared are refused
  // before they are decoded, 1000 fit.
  GltfLoadOptions opt;
  opt.max_memory_bytes = 3ull << 30;
  for (int count : {10000000, 1000}) {
    GltfWriter w = shape_file({{"type", "sphere"}});
    w.j["accessors"].push_back({{"componentType", 5126}, {"count", count}, {"type", "VEC3"}});
    w.j["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"] = {{"attributes", {{"TRANSLATION", 0}}}};
    if (count > 1000)
      CHECK_THROWS_WITH(test::write_and_load(w, next_name(), opt),
                        Contains("nodes[0].extensions.EXT_mesh_gpu_instancing: 10000000 instances need") &&
                            Contains("over the 3.0 GiB budget"));
    else
      CHECK(count_shape_instances(test::write_and_load(w, next_name(), opt).scene) == 1000);
  }
}
TEST_CASE("shapes: the shipped shape scenes load and render with every accelerator",
          "[io][gltf][shapes][render]") {
  for (const char* name : {"csg.gltf", "spheres.gltf"}) {
    INFO(name);
    const LoadedScene l = load_gltf(test::source_dir() / "scenes" / name);
    CHECK(l.warnings.empty());
    CHECK(l.scene.shapes.size() >= 3);
    REQUIRE_FALSE(l.scene.cameras.empty());
    CHECK_FALSE(l.scene.lights.empty());
    RenderConfig cfg;
    cfg.width = 48;
    cfg.height = 32;
    cfg.spp = 1;
    for (const std::string& accel : accelerator_names()) {
      INFO(accel);
      const auto a = make_scene_accelerator(accel, l.scene);
      const Film film = render_whitted(l.scene, *a, l.scene.cameras[0], cfg);
      size_t lit = 0;
      for (size_t i = 0; i < film.rgba.size(); i += 4)
        if (std::max({film.rgba[i], film.rgba[i + 1], film.rgba[i + 2]}) > 0.02f) ++lit;
      CHECK(lit > size_t(cfg.width * cfg.height) / 2);  // the shapes and the room fill most of the view
    }
  }
}

namespace {

json displace(json child, double amplitude) {
  json j = op("displace", {std::move(child)});
  j["amplitude"] = amplitude;
  return j;
}

}  // namespace

TEST_CASE("shapes: displace nodes read every noise field and apply the defaults",
          "[io][gltf][shapes][quick]") {
  SECTION("defaults: fbm at frequency 1 with seed 0 and FractalParams' defaults") {
    const SdfTree t = tree_of(displace(sphere(1), 0.1));
    const SdfNode& root = t.nodes.at(size_t(t.root));
    REQUIRE(root.kind == SdfKind::Displace);
    CHECK(root.b == -1);
    REQUIRE(t.displacements.size() == 1);
    REQUIRE(root.displacement == 0);
    const SdfDisplacement& d = t.displacements[0];
    const FractalParams defaults;
    CHECK(d.amplitude == 0.1f);
    CHECK(d.frequency == 1);
    CHECK(d.table.seed == 0);
    CHECK(d.table.perm == make_perlin_table(0).perm);
    CHECK(d.params.kind == FractalKind::Fbm);
    CHECK(d.params.detail == defaults.detail);
    CHECK(d.params.roughness == defaults.roughness);
    CHECK(d.params.lacunarity == defaults.lacunarity);
    CHECK(d.params.offset == defaults.offset);
    CHECK(d.params.gain == defaults.gain);
    CHECK(d.params.distortion == defaults.distortion);
  }
  SECTION("every field, under a transform: f = child + amplitude x noise(frequency x local p)") {
    json j = displace(sphere(1), -0.25);
    j["frequency"] = 3;
    j["seed"] = 4000000000u;
    j["noise"] = "ridged";
    j["detail"] = 2.5;
    j["roughness"] = 0.75;
    j["lacunarity"] = 2.5;
    j["offset"] = 0.9;
    j["gain"] = 1.5;
    j["distortion"] = 0.3;
    j["translation"] = {1, 0, 0};
    const SdfTree t = tree_of(j);
    const SdfDisplacement& d = t.displacements.at(0);
    CHECK(d.amplitude == -0.25f);
    CHECK(d.frequency == 3);
    CHECK(d.table.seed == 4000000000u);
    CHECK(d.table.perm == make_perlin_table(4000000000u).perm);
    CHECK(d.params.kind == FractalKind::Ridged);
    CHECK(d.params.detail == 2.5f);
    CHECK(d.params.roughness == 0.75f);
    CHECK(d.params.lacunarity == 2.5f);
    CHECK(d.params.offset == 0.9f);
    CHECK(d.params.gain == 1.5f);
    CHECK(d.params.distortion == 0.3f);
    for (const Vec3f p : {Vec3f{1.5f, 0.2f, 0}, Vec3f{0, 0, 0}, Vec3f{2, 1, -1}}) {
      const Vec3f local = p - Vec3f{1, 0, 0};
      const float expected = length(local) - 1 - 0.25f * fractal_noise(d.table, local * 3, d.params).value;
      CHECK(sdf_eval(t, p) == Approx(expected).margin(1e-6));
    }
  }
  SECTION("turbulence, and amplitude 0") {
    json j = displace(sphere(2), 0);
    j["noise"] = "turbulence";
    const SdfTree t = tree_of(j);
    CHECK(t.displacements.at(0).params.kind == FractalKind::Turbulence);
    CHECK(sdf_eval(t, {3, 0, 0}) == Approx(1));
  }
}

TEST_CASE("shapes: bad displace fields are errors naming the node and the field",
          "[io][gltf][shapes][hostile][quick]") {
  const auto with = [](const char* key, json value) {
    json j = displace(sphere(1), 0.1);
    j[key] = std::move(value);
    return error_of(implicit(op("union", {sphere(1, {3, 0, 0}), j})));
  };
  const std::string node = kCsg + ".children[1]";
  CHECK_THAT(with("colour", 1),
             Contains(node + ".colour: unknown key") && Contains("amplitude, frequency, seed"));
  CHECK_THAT(with("radius", 1), Contains(node + ".radius: does not apply to a \"displace\" CSG node"));
  CHECK_THAT(with("detail", 20), Contains(node + ".detail: must be in [0, 15] (got 20)"));
  CHECK_THAT(with("detail", -1), Contains(node + ".detail: must be in [0, 15]"));
  CHECK_THAT(with("roughness", -1), Contains(node + ".roughness: must be in [0, 1] (got -1)"));
  CHECK_THAT(with("lacunarity", 1), Contains(node + ".lacunarity: must be in [1.01, 16] (got 1)"));
  CHECK_THAT(with("lacunarity", 17), Contains(node + ".lacunarity: must be in [1.01, 16]"));
  CHECK_THAT(with("distortion", -0.5), Contains(node + ".distortion: must be in [0, 16]"));
  CHECK_THAT(with("frequency", 0), Contains(node + ".frequency: must be > 0 (got 0)"));
  CHECK_THAT(with("frequency", -2), Contains(node + ".frequency: must be > 0"));
  CHECK_THAT(with("frequency", 1e7), Contains(node + ".frequency: must be <= 1e+06"));
  CHECK_THAT(with("amplitude", 1e7), Contains(node + ".amplitude: must be in [-1e+06, 1e+06]"));
  CHECK_THAT(with("amplitude", "big"), Contains(node + ".amplitude: must be a number"));
  CHECK_THAT(with("seed", 1.5), Contains(node + ".seed: must be an integer in [0, 4294967295] (got 1.5)"));
  CHECK_THAT(with("seed", -1), Contains(node + ".seed: must be an integer in [0, 4294967295] (got -1)"));
  CHECK_THAT(with("seed", 4294967296u), Contains(node + ".seed: must be an integer in [0, 4294967295]"));
  CHECK_THAT(with("noise", "perlin"),
             Contains(node + ".noise: 'perlin' is not one of \"fbm\", \"turbulence\", \"ridged\""));
  CHECK_THAT(with("noise", 2), Contains(node + ".noise: must be one of \"fbm\""));
  CHECK_THAT(with("offset", 1),
             Contains(node + ".offset: applies to \"ridged\" noise only (this one is \"fbm\")"));
  CHECK_THAT(with("gain", 1), Contains(node + ".gain: applies to \"ridged\" noise only"));
  json ridged = displace(sphere(1), 0.1);
  ridged["noise"] = "ridged";
  ridged["offset"] = 2.5;
  CHECK_THAT(error_of(implicit(ridged)), Contains(kCsg + ".offset: must be in [0, 2] (got 2.5)"));
  ridged["offset"] = 1;
  ridged["gain"] = -1;
  CHECK_THAT(error_of(implicit(ridged)), Contains(kCsg + ".gain: must be in [0, 16]"));
  json steep = displace(sphere(1), 1);
  steep["noise"] = "ridged";
  steep["detail"] = 15;
  steep["lacunarity"] = 16;
  steep["gain"] = 16;
  steep["frequency"] = 100;
  CHECK_THAT(error_of(implicit(steep)),
             Contains(kCsg + ": the noise raises the Lipschitz bound by") && Contains("(at most 10000"));
  json no_amplitude = op("displace", {sphere(1)});
  CHECK_THAT(error_of(implicit(no_amplitude)), Contains(kCsg + ".amplitude: is required"));
  CHECK_THAT(error_of(implicit({{"type", "displace"}, {"amplitude", 0.1}})),
             Contains(kCsg + ".children: is required"));
  json none = displace(sphere(1), 0.1);
  none["children"] = json::array();
  CHECK_THAT(error_of(implicit(none)), Contains(kCsg + ".children: must hold exactly 1 CSG node (got 0)"));
  none["children"] = {sphere(1), sphere(2)};
  CHECK_THAT(error_of(implicit(none)), Contains(kCsg + ".children: must hold exactly 1 CSG node (got 2)"));
  CHECK_THAT(error_of(implicit(displace({{"type", "halfSpace"}}, 0.1))),
             Contains(kCsg + ": the shape's inside is unbounded"));
}

namespace {

// Polyhedron CSG nodes: glTF meshes of test::TriMesh (sdf_trees.h), one TRIANGLES primitive each
// unless split.

// Adds `m` as a mesh (FLOAT positions, UNSIGNED_INT indices, `mode`); returns the mesh index.
int add_tri_mesh(GltfWriter& w, const test::TriMesh& m, int mode = 4) {
  std::vector<float> xyz;
  for (const Vec3f& p : m.positions) xyz.insert(xyz.end(), {p.x, p.y, p.z});
  return w.mesh(w.positions(xyz), w.indices(m.indices), mode);
}

json polyhedron(int mesh) {
  return {{"type", "polyhedron"}, {"mesh", mesh}};
}

// A file whose node 0 is the implicit shape of `csg`, with the meshes `meshes` (indices 0, 1, ...).
GltfWriter polyhedron_file(json csg, const std::vector<test::TriMesh>& meshes) {
  GltfWriter w = shape_file(implicit(std::move(csg)));
  for (const test::TriMesh& m : meshes) add_tri_mesh(w, m);
  return w;
}

std::string load_error(GltfWriter& w, GltfLoadOptions opt = {}) {
  try {
    test::write_and_load(w, next_name(), opt);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const test::TriMesh kCube = test::box_mesh({-1, -1, -1}, {1, 1, 1});

}  // namespace

TEST_CASE("shapes: polyhedron CSG nodes are the solids of their meshes' triangles",
          "[io][gltf][shapes][polyhedron][quick]") {
  const SdfTree box = test::single_shape(test::sdf_primitive(SdfKind::Box, {1, 1, 1}));
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(-2.5f, 2.5f);
  SECTION("alone: the 24-vertex cube of a typical glTF file, welded") {
    GltfWriter w = polyhedron_file(polyhedron(0), {test::split_box_mesh({-1, -1, -1}, {1, 1, 1})});
    const LoadedScene l = test::write_and_load(w, next_name());
    REQUIRE(l.scene.shapes.size() == 1);
    CHECK(l.warnings.empty());
    const Shape& s = l.scene.shapes[0].shape;
    REQUIRE(s.sdf.polyhedra.size() == 1);
    CHECK(node_of(s.sdf, SdfKind::Polyhedron).polyhedron == 0);
    CHECK(s.sdf.polyhedra[0].positions.size() == 8);
    CHECK(s.lipschitz == Approx(1));
    test::check_vec(s.sdf_bounds.lo, {-1, -1, -1});
    test::check_vec(s.sdf_bounds.hi, {1, 1, 1});
    for (int i = 0; i < 500; ++i) {
      const Vec3f p{u(rng), u(rng), u(rng)};
      REQUIRE(sdf_eval(s.sdf, p) == Approx(sdf_eval(box, p)).margin(1e-5));
    }
    ShapeHit hit;
    Ray r;
    r.org = {0, 0, -5};
    r.dir = {0, 0, 1};
    REQUIRE(intersect_shape(s, r, hit));
    CHECK(hit.t == Approx(4).margin(1e-4));
  }
  SECTION("an operand: a cube mesh minus a sphere, as the analytic CSG") {
    const json ball = sphere(1.25f, {0.3f, 0.2f, 0.1f});
    GltfWriter w = polyhedron_file(op("subtraction", {polyhedron(0), ball}), {kCube});
    const Shape s = test::write_and_load(w, next_name()).scene.shapes.at(0).shape;
    const SdfTree analytic = tree_of(op("subtraction", {{{"type", "box"}, {"size", {2, 2, 2}}}, ball}));
    for (int i = 0; i < 500; ++i) {
      const Vec3f p{u(rng), u(rng), u(rng)};
      REQUIRE(sdf_eval(s.sdf, p) == Approx(sdf_eval(analytic, p)).margin(1e-5));
    }
  }
  SECTION("several TRIANGLES primitives, with and without indices, make one mesh") {
    // The cube's first three faces indexed, the other three as a triangle soup.
    GltfWriter w = shape_file(implicit(polyhedron(0)));
    std::vector<float> first, soup;
    for (const Vec3f& p : kCube.positions) first.insert(first.end(), {p.x, p.y, p.z});
    const std::vector<uint32_t> indexed(kCube.indices.begin(), kCube.indices.begin() + 18);
    for (size_t k = 18; k < kCube.indices.size(); ++k) {
      const Vec3f p = kCube.positions[kCube.indices[k]];
      soup.insert(soup.end(), {p.x, p.y, p.z});
    }
    w.mesh(w.positions(first), w.indices(indexed));
    w.j["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", w.positions(soup)}}}});
    const Shape s = test::write_and_load(w, next_name()).scene.shapes.at(0).shape;
    CHECK(s.sdf.polyhedra.at(0).positions.size() == 8);
    CHECK(sdf_eval(s.sdf, {0, 0, 0}) == Approx(-1));
    CHECK(sdf_eval(s.sdf, {0, 0, 3}) == Approx(2));
  }
  SECTION("a mesh used twice is built once and copied; an inward mesh is reversed with a warning") {
    json moved = polyhedron(0);
    moved["translation"] = {3, 0, 0};
    GltfWriter w = polyhedron_file(op("union", {polyhedron(0), moved}), {kCube.flipped()});
    const LoadedScene l = test::write_and_load(w, next_name());
    const Shape& s = l.scene.shapes.at(0).shape;
    REQUIRE(s.sdf.polyhedra.size() == 2);
    CHECK(s.sdf.polyhedra[0].indices == s.sdf.polyhedra[1].indices);
    CHECK(sdf_eval(s.sdf, {0, 0, 0}) == Approx(-1));
    CHECK(sdf_eval(s.sdf, {3, 0, 0}) == Approx(-1));
    CHECK(sdf_eval(s.sdf, {1.5f, 0, 0}) == Approx(0.5f));
    REQUIRE(l.warnings.size() == 1);
    CHECK(l.warnings[0] == kCsg +
                               ".children[0].mesh: mesh 0 winds inwards (its signed volume is negative); its "
                               "triangles are taken reversed");
  }
  SECTION("the node's transform places the mesh's frame") {
    json p = polyhedron(0);
    p["translation"] = {2, 0, 0};
    p["scale"] = {2, 2, 2};
    GltfWriter w = polyhedron_file(p, {kCube});
    const Shape shape = test::write_and_load(w, next_name()).scene.shapes.at(0).shape;
    // Values pass through transforms: a bound whose Lipschitz constant is 1 / the scale.
    CHECK(sdf_eval(shape.sdf, {2, 0, 0}) == Approx(-1));
    CHECK(sdf_eval(shape.sdf, {7, 0, 0}) == Approx(1.5));
    CHECK(sdf_eval(shape.sdf, {2, 0, 5}) == Approx(1.5));
    CHECK(shape.lipschitz == Approx(0.5));
    test::check_vec(shape.sdf_bounds.lo, {0, -2, -2}, 1e-5f);
    test::check_vec(shape.sdf_bounds.hi, {4, 2, 2}, 1e-5f);
  }
}

TEST_CASE("shapes: bad polyhedron nodes and meshes are errors naming the node's mesh member",
          "[io][gltf][shapes][polyhedron][hostile][quick]") {
  const std::string mesh = kCsg + ".mesh: ";
  SECTION("the mesh index: missing, of another type, negative, out of range") {
    CHECK_THAT(error_of(implicit({{"type", "polyhedron"}})),
               Contains("scene.gltf: " + mesh +
                        "is required (the index of the glTF mesh whose triangles bound the solid)"));
    CHECK_THAT(error_of(implicit({{"type", "polyhedron"}, {"mesh", "0"}})),
               Contains(mesh + "must be an integer mesh index (got \"0\")"));
    CHECK_THAT(error_of(implicit({{"type", "polyhedron"}, {"mesh", -1}})),
               Contains(mesh + "index -1 is negative"));
    CHECK_THAT(error_of(implicit(polyhedron(0))), Contains(mesh + "mesh 0 out of range (0 meshes)"));
    GltfWriter w = polyhedron_file(polyhedron(3), {kCube});
    CHECK_THAT(load_error(w), Contains(mesh + "mesh 3 out of range (1 meshes)"));
    CHECK_THAT(error_of(implicit({{"type", "polyhedron"}, {"mesh", 0}, {"radius", 1}})),
               Contains(kCsg + ".radius: does not apply to a \"polyhedron\" CSG node"));
  }
  SECTION("an open mesh, as the second operand") {
    test::TriMesh open = kCube;
    open.indices.erase(open.indices.begin(), open.indices.begin() + 3);
    GltfWriter w = polyhedron_file(op("subtraction", {polyhedron(0), polyhedron(1)}), {kCube, open});
    CHECK_THAT(load_error(w),
               EndsWith("scene.gltf: nodes[0].extensions.PENUMBRA_shapes.csg.children[1].mesh: mesh 1 "
                        "is not closed: edge (0, 4) is used by 1 triangle"));
  }
  SECTION("inconsistent winding, non-manifold edges, no volume") {
    test::TriMesh bad = kCube;
    std::swap(bad.indices[1], bad.indices[2]);
    GltfWriter w = polyhedron_file(polyhedron(0), {bad});
    CHECK_THAT(load_error(w),
               EndsWith(mesh + "mesh 0 is not consistently oriented: edge (0, 4) is used by 2 triangles in "
                               "the same direction (4 -> 0)"));
    test::TriMesh two = test::box_mesh({0, 0, 0}, {1, 1, 1});
    two.append(test::box_mesh({1, 1, 0}, {2, 2, 1}));
    GltfWriter w2 = polyhedron_file(polyhedron(0), {two});
    CHECK_THAT(load_error(w2), Contains(mesh + "mesh 0 is not closed: edge (3, 7) is used by 4 triangles"));
    const test::TriMesh sheet{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 1}};
    GltfWriter w3 = polyhedron_file(polyhedron(0), {sheet});
    CHECK_THAT(load_error(w3), EndsWith(mesh + "mesh 0 encloses no volume (signed volume 0)"));
  }
  SECTION("a non-finite vertex") {
    test::TriMesh bad = kCube;
    bad.positions[3].y = std::numeric_limits<float>::quiet_NaN();
    GltfWriter w = polyhedron_file(polyhedron(0), {bad});
    CHECK_THAT(load_error(w), EndsWith(mesh + "mesh 0 has a non-finite vertex 3 (1, nan, -1)"));
  }
  SECTION("primitives other than TRIANGLES, or without POSITION") {
    for (int mode : {1, 5}) {
      GltfWriter w = shape_file(implicit(polyhedron(0)));
      add_tri_mesh(w, kCube, mode);
      CHECK_THAT(load_error(w), EndsWith(mesh + "mesh 0's primitives[0] has mode " + std::to_string(mode) +
                                         (mode == 1 ? " (LINES)" : " (TRIANGLE_STRIP)") +
                                         "; a polyhedron needs TRIANGLES (mode 4) primitives"));
    }
    GltfWriter w = polyhedron_file(polyhedron(0), {kCube});
    w.j["meshes"][0]["primitives"].push_back({{"attributes", json::object()}});
    CHECK_THAT(load_error(w), EndsWith(mesh + "mesh 0's primitives[1] has no POSITION attribute"));
  }
  SECTION("more than kMaxPolyhedronTriangles triangles") {
    // Positions from an accessor without a bufferView (all zeros), not indexed.
    GltfWriter w = shape_file(implicit(polyhedron(0)));
    w.j["accessors"].push_back({{"componentType", 5126}, {"count", 3 * 65537}, {"type", "VEC3"}});
    w.j["meshes"].push_back({{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}});
    CHECK_THAT(load_error(w),
               EndsWith(mesh + "mesh 0 has more than 65536 triangles (the most a polyhedron may have)"));
  }
  SECTION("the shape's inside is checked once the solids are built") {
    GltfWriter w = polyhedron_file(op("intersection", {polyhedron(0), sphere(1, {5, 0, 0})}), {kCube});
    CHECK_THAT(load_error(w),
               EndsWith(kCsg + ": the shape's inside is empty (the parts it intersects do not overlap)"));
  }
}

TEST_CASE("shapes: a polyhedron's solid is charged to the memory budget",
          "[io][gltf][shapes][polyhedron][hostile]") {
  // The same file but for the CSG (a ring mesh's polyhedron, or a sphere with the mesh unused),
  // its buffer external so that the end of the load is its peak.
  const test::TriMesh ring = test::ring_mesh(1, 0.35f, 48, 24);
  const auto file = [&](bool use_mesh) {
    GltfWriter w = polyhedron_file(use_mesh ? polyhedron(0) : sphere(1), {ring});
    const auto dir = test::temp_dir(next_name());
    w.write_external(dir / "scene.gltf", "scene.bin");
    return dir / "scene.gltf";
  };
  const auto with_mesh = file(true), without = file(false);
  const auto loads = [](const std::filesystem::path& path, uint64_t budget, std::string* error) {
    GltfLoadOptions opt;
    opt.max_memory_bytes = budget;
    try {
      load_gltf(path, opt);
      return true;
    } catch (const InputError& e) {
      if (error) *error = e.what();
      return false;
    }
  };
  const auto smallest = [&](const std::filesystem::path& path) {
    uint64_t lo = 1, hi = 1ull << 30;
    REQUIRE(loads(path, hi, nullptr));
    while (hi - lo > 1) {
      const uint64_t mid = lo + (hi - lo) / 2;
      (loads(path, mid, nullptr) ? hi : lo) = mid;
    }
    return hi;
  };
  const uint64_t plain = smallest(without), solid = smallest(with_mesh);
  const SolidMesh expected = build_solid_mesh(ring.positions, ring.indices);
  CHECK(solid >= plain + solid_mesh_bytes(expected));
  std::string error;
  REQUIRE_FALSE(loads(with_mesh, plain, &error));
  CHECK_THAT(error, Contains(kCsg + ".mesh: mesh 0's") && Contains("over the"));
}

TEST_CASE("shapes: polyhedra come back through write_gltf", "[io][gltf][shapes][polyhedron][quick]") {
  json moved = polyhedron(0);
  moved["translation"] = {0.5f, 0, 0};
  GltfWriter w = polyhedron_file(op("subtraction", {polyhedron(0), moved}), {test::l_prism_mesh()});
  w.node({{"extensions", {{"PENUMBRA_shapes", implicit(polyhedron(0))}}}});
  const LoadedScene first = test::write_and_load(w, next_name());
  REQUIRE(first.scene.shapes.size() == 2);
  const auto dir = test::temp_dir(next_name());
  write_gltf(first.scene, dir / "again.gltf");
  const LoadedScene second = load_gltf(dir / "again.gltf");
  REQUIRE(second.scene.shapes.size() == 2);
  CHECK(second.warnings.empty());
  std::mt19937 rng(32);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  for (size_t k = 0; k < 2; ++k) {
    const SdfTree& a = first.scene.shapes[k].shape.sdf;
    const SdfTree& b = second.scene.shapes[k].shape.sdf;
    REQUIRE(b.polyhedra.size() == a.polyhedra.size());
    CHECK(b.polyhedra[0].positions.size() == a.polyhedra[0].positions.size());
    for (int i = 0; i < 300; ++i) {
      const Vec3f p{u(rng), u(rng), u(rng)};
      REQUIRE(sdf_eval(b, p) == sdf_eval(a, p));
    }
  }
}
