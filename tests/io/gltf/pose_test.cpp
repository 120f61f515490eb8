// Posing a loaded scene at another time (io/gltf/pose.cpp, pose_gltf_scene): on a generated file
// with an animated parent and its child, an animated EXT_mesh_gpu_instancing node, an animated
// shape, an animated camera and a light on the moving parent, the posed scene equals a fresh
// load at each time; moving meshes stay in object space under non-identity instances; morph
// weights and skins are refused with the scene unchanged; a transform that overflows at the
// time is the load's error, with the scene unchanged.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/files/error.h"
#include "io/gltf/loader.h"
#include "support/gltf_writer.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

using namespace penumbra;
using nlohmann::json;

namespace {

GltfLoadOptions at(double t) {
  GltfLoadOptions o;
  o.time = t;
  o.keep_animation = true;
  return o;
}

// Nodes: 0 a moving parent (translation and rotation) with child 1 (a mesh placed once, under
// its own static TRS) and child 2 (a spot light); 3 three EXT_mesh_gpu_instancing copies of a
// second mesh, scaled by a channel; 4 a sphere shape, translated; 5 the camera, moved and turned;
// 6 a still mesh of its own placed once; 7 a mesh placed once whose translation keys are all zero.
std::filesystem::path rigid_file() {
  test::GltfWriter w;
  const int tri = w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}));
  const int quad =
      w.mesh(w.positions(test::quad_positions()), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
  const int parent = w.node({{"name", "parent"}, {"translation", {0, 1, 0}}});
  const int child = w.node({{"mesh", tri}, {"translation", {1, 0, 0}}, {"scale", {1, -2, 1}}}, false);
  const int light = w.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}, false);
  w.j["nodes"][size_t(parent)]["children"] = {child, light};
  const int copies = w.floats({0, 0, 0, 2, 0, 0, 0, 0, 3}, "VEC3", 3);
  const int inst =
      w.node({{"mesh", quad},
              {"extensions", {{"EXT_mesh_gpu_instancing", {{"attributes", {{"TRANSLATION", copies}}}}}}}});
  const int shape = w.node({{"extensions", {{"PENUMBRA_shapes", {{"type", "sphere"}, {"radius", 0.5}}}}}});
  const int cam = w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 4, 0, 0, 0, 0, 4}))}, {"translation", {0, -3, 0}}});
  const int zero = w.node({{"mesh", tri}});
  w.j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"znear", 0.1}}}}};
  w.j["extensions"]["KHR_lights_punctual"]["lights"] = {
      {{"type", "spot"}, {"intensity", 3}, {"spot", {{"innerConeAngle", 0.1}, {"outerConeAngle", 0.5}}}}};
  w.j["extensionsUsed"] = {"EXT_mesh_gpu_instancing", "KHR_lights_punctual", "PENUMBRA_shapes"};
  const float s = float(std::sqrt(0.5));
  w.channel(parent, "translation", {0, 1}, {0, 1, 0, 2, 1, -1}, "VEC3", 3);
  w.channel(parent, "rotation", {0, 1}, {0, 0, 0, 1, 0, s, 0, s}, "VEC4", 4);
  w.channel(inst, "scale", {0, 2}, {1, 1, 1, 0.5f, 2, 1}, "VEC3", 3);
  w.channel(shape, "translation", {0, 1}, {-2, 0, 0, -2, 3, 0}, "VEC3", 3);
  w.channel(cam, "translation", {0, 1}, {0, 0, 5, 3, 1, 5}, "VEC3", 3);
  w.channel(cam, "rotation", {0, 1}, {0, 0, 0, 1, 0, 0.2f, 0, 0.98f}, "VEC4", 4);
  w.channel(zero, "translation", {0, 1}, {0, 0, 0, 0, 0, 0}, "VEC3", 3);
  const auto dir = test::temp_dir("pose");
  w.write_embedded(dir / "rigid.gltf");
  return dir / "rigid.gltf";
}

void check_affine(const Affine3f& a, const Affine3f& b, double eps) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) CHECK(a.m[r][c] == Approx(b.m[r][c]).margin(eps));
}

void check_same_pose(const Scene& posed, const Scene& fresh) {
  REQUIRE(posed.instances.size() == fresh.instances.size());
  REQUIRE(posed.meshes.size() == fresh.meshes.size());
  for (size_t i = 0; i < posed.instances.size(); ++i) {
    INFO("instance " << i);
    const Instance &a = posed.instances[i], &b = fresh.instances[i];
    CHECK(a.mesh == b.mesh);
    CHECK(a.shape == b.shape);
    CHECK(a.node == b.node);
    CHECK(a.copy == b.copy);
    CHECK(a.identity == b.identity);
    CHECK(a.mirrored == b.mirrored);
    check_affine(a.to_world, b.to_world, 1e-6);
    check_affine(a.to_object, b.to_object, 1e-5);
  }
  for (size_t m = 0; m < posed.meshes.size(); ++m)
    CHECK(posed.meshes[m].positions == fresh.meshes[m].positions);
  REQUIRE(posed.cameras.size() == fresh.cameras.size());
  for (size_t k = 0; k < posed.cameras.size(); ++k) {
    test::check_vec(posed.cameras[k].eye, fresh.cameras[k].eye);
    test::check_vec(posed.cameras[k].u, fresh.cameras[k].u);
    test::check_vec(posed.cameras[k].v, fresh.cameras[k].v);
    test::check_vec(posed.cameras[k].w, fresh.cameras[k].w);
  }
  REQUIRE(posed.lights.size() == fresh.lights.size());
  for (size_t k = 0; k < posed.lights.size(); ++k) {
    test::check_vec(posed.lights[k].position, fresh.lights[k].position);
    test::check_vec(posed.lights[k].direction, fresh.lights[k].direction);
  }
}

}  // namespace

TEST_CASE("pose: a scene posed at another time equals a fresh load at that time", "[io][animation][quick]") {
  const auto file = rigid_file();
  LoadedScene loaded = load_gltf(file, at(0.1));
  REQUIRE(loaded.animation);
  const Scene& s = loaded.scene;
  // The moving nodes' meshes stay in object space under instances that are never the identity,
  // even where the pose is (node 7); the still mesh placed once is in world space.
  REQUIRE(s.instances.size() == 7);  // child, 3 copies, shape, still quad, zero
  for (const Instance& inst : s.instances) {
    INFO("node " << inst.node);
    CHECK(inst.identity == (inst.node == 6));
    if (inst.node == 7) {
      CHECK(is_identity(inst.to_world));
      CHECK(s.meshes[size_t(inst.mesh)].positions[1] == Vec3f{1, 0, 0});
    }
  }
  for (double t : {0.5, 0.77, 1.0, 1.5, 3.0, -1.0, 0.1}) {
    INFO("time " << t);
    uint64_t moved = 0;
    REQUIRE(pose_gltf_scene(*loaded.animation, t, loaded.scene, &moved));
    CHECK(moved == 6);  // all but the still mesh's instance
    const LoadedScene fresh = load_gltf(file, at(t));
    check_same_pose(loaded.scene, fresh.scene);
  }
  // A time that moves the camera: its eye follows the channel.
  REQUIRE(pose_gltf_scene(*loaded.animation, 1.0, loaded.scene));
  test::check_vec(loaded.scene.cameras[0].eye, {3, 1, 5}, 1e-5f);
  // Without a time there is nothing to pose with; without keep_animation nothing is kept.
  CHECK_FALSE(load_gltf(file).animation);
  GltfLoadOptions unkept = at(0.5);
  unkept.keep_animation = false;
  CHECK_FALSE(load_gltf(file, unkept).animation);
}

TEST_CASE("pose: morph weights and skins keep nothing to pose (each frame loads the file)",
          "[io][animation][quick]") {
  const auto dir = test::temp_dir("pose-refused");
  test::GltfWriter w;
  const int pos = w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int morph = w.positions({0, 0, 1, 0, 0, 1, 0, 0, 1});
  const int mesh = w.morph_mesh(pos, morph);
  const int a = w.node({{"mesh", mesh}});
  const int b = w.node({{"mesh", mesh}, {"translation", {3, 0, 0}}});
  w.channel(a, "translation", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3);
  w.channel(b, "weights", {0, 1}, {0, 1}, "SCALAR", 1);
  w.write_embedded(dir / "morph.gltf");
  LoadedScene loaded = load_gltf(dir / "morph.gltf", at(0.25));
  CHECK_FALSE(loaded.animation);
  CHECK(loaded.animation_bytes == 0);

  // A skinned mesh follows its joints' motion into its vertices: not a placement either.
  test::GltfWriter sw;
  const int spos = sw.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int skinned =
      sw.skinned_mesh(spos, {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0});
  const int joint = sw.node({{"name", "joint"}});
  sw.node({{"mesh", skinned}, {"skin", 0}});
  sw.j["skins"] = json::array({{{"joints", {joint}}}});
  sw.channel(joint, "translation", {0, 1}, {0, 0, 0, 0, 0, 2}, "VEC3", 3);
  sw.write_embedded(dir / "skin.gltf");
  LoadedScene skin = load_gltf(dir / "skin.gltf", at(0.25));
  CHECK_FALSE(skin.animation);
  // A rigid animation keeps the file, counted in animation_bytes for the memory budget.
  test::GltfWriter rw;
  const int rpos = rw.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  const int rn = rw.node({{"mesh", rw.mesh(rpos)}});
  rw.channel(rn, "translation", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3);
  rw.write_embedded(dir / "rigid.gltf");
  const LoadedScene rigid = load_gltf(dir / "rigid.gltf", at(0.25));
  REQUIRE(rigid.animation);
  CHECK(rigid.animation_bytes >= 9 * sizeof(float));
}

TEST_CASE("pose: a transform that overflows at the time is an error naming the node, the scene unchanged",
          "[io][animation][quick]") {
  // A chain of ten nodes whose scales step from 1 to 1e38 at t = 1: the world transform of the
  // leaf's mesh overflows to infinity there, first at the ninth node (1e38^9 > 1e308).
  test::GltfWriter w;
  int parent = -1;
  for (int k = 0; k < 10; ++k) {
    json fields = json::object();
    if (k == 9) fields["mesh"] = w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}));
    const int n = w.node(fields, parent < 0);
    if (parent >= 0) w.j["nodes"][size_t(parent)]["children"] = {n};
    w.channel(n, "scale", {0, 1}, {1, 1, 1, 1e38f, 1e38f, 1e38f}, "VEC3", 3, "STEP");
    parent = n;
  }
  const auto dir = test::temp_dir("pose-overflow");
  w.write_embedded(dir / "overflow.gltf");
  std::string load_error;
  try {
    load_gltf(dir / "overflow.gltf", at(1.5));
  } catch (const InputError& e) {
    load_error = e.what();
  }
  REQUIRE_THAT(load_error, Catch::Matchers::Contains("nodes[") && Catch::Matchers::Contains("non-finite"));
  LoadedScene loaded = load_gltf(dir / "overflow.gltf", at(0.5));
  REQUIRE(loaded.animation);
  const std::vector<Instance> before = loaded.scene.instances;
  try {
    pose_gltf_scene(*loaded.animation, 1.5, loaded.scene);
    FAIL("no error for an overflowing transform");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == load_error);
  }
  REQUIRE(loaded.scene.instances.size() == before.size());
  for (size_t i = 0; i < before.size(); ++i)
    check_affine(loaded.scene.instances[i].to_world, before[i].to_world, 0);
}
