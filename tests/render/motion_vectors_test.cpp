// The vector layer end to end: small animated glTF files loaded at a time, their neighbouring
// frames loaded through PrepareOptions::load_at, and every pixel's vector compared with the
// displacement projected by hand (pinhole formula, not the renderer's projection).
#include <catch2/catch.hpp>
#include <cmath>
#include <optional>
#include <set>

#include "io/files/error.h"
#include "render/session.h"
#include "renderer/integrators/scene_accel.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

namespace penumbra {
namespace {

constexpr int kWidth = 48, kHeight = 32;
constexpr float kYfov = 0.8f;
constexpr double kFps = 24;
constexpr float kTolerance = 0.01f;  // pixels

/// How the quad's vertices are given.
enum class Quad { Rigid, Morph, Skin };

/// A 2 x 2 quad in the z = 0 plane (centred on its node) seen by a camera node at z = 5 looking
/// down -z; `animate` adds what moves (given the writer, the node that moves the quad: its own,
/// or for Quad::Skin the joint its right edge follows, and the camera's node). Written as
/// `name`.gltf in a fresh folder.
template <class Animate>
std::filesystem::path write_scene(const std::string& name, Quad kind, Animate&& animate) {
  test::GltfWriter w;
  const int pos = w.positions({-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0});
  const int idx = w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
  int mesh = 0;
  if (kind == Quad::Morph) {
    // Every vertex moves +1 in x at weight 1.
    mesh = w.morph_mesh(pos, w.positions({1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0}));
  } else if (kind == Quad::Skin) {
    // The left vertices follow joint 0, the right ones joint 1 (bind pose: identity).
    mesh = w.skinned_mesh(pos, {0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0},
                          {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0});
  } else {
    mesh = w.mesh(pos);
  }
  w.j["meshes"][size_t(mesh)]["primitives"][0]["indices"] = idx;
  int moved = w.node({{"mesh", mesh}});
  if (kind == Quad::Skin) {
    w.j["nodes"][size_t(moved)]["skin"] = 0;
    const int left = w.node(nlohmann::json::object());
    moved = w.node(nlohmann::json::object());
    w.j["skins"] = {{{"joints", {left, moved}}}};
  }
  w.j["cameras"] = {
      {{"type", "perspective"}, {"perspective", {{"yfov", kYfov}, {"znear", 0.1}, {"aspectRatio", 1.5}}}}};
  const int camera = w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  animate(w, moved, camera);
  const auto dir = test::temp_dir("vector-" + name);
  const auto file = dir / (name + ".gltf");
  w.write_embedded(file);
  return file;
}

RenderSpec vector_spec(const char* integrator) {
  RenderSpec s;
  s.integrator = integrator;
  s.width = kWidth;
  s.height = kHeight;
  s.spp = 1;
  s.accel = "bvh";
  s.aovs = {"vector"};
  s.fps = kFps;
  return s;
}

/// Renders the vector layer (or the layers `aovs`) of `file` at `time` (unset: its static pose).
RenderLayers render_vectors(const std::filesystem::path& file, std::optional<double> time,
                            const char* integrator = "whitted", PreparedRender* prepared_out = nullptr,
                            const std::set<std::string>& aovs = {"vector"}) {
  GltfLoadOptions lo;
  lo.time = time;
  LoadedScene loaded = load_gltf(file, lo);
  PrepareOptions o;
  o.scene_file = file.string();
  o.time = time;
  o.load_at = [&](double t) {
    GltfLoadOptions at;
    at.time = t;
    return load_gltf(file, at);
  };
  RenderSpec spec = vector_spec(integrator);
  spec.aovs = aovs;
  const PreparedRender p = prepare_render(loaded, spec, o);
  const Structure s = build_structure(loaded.scene, p.spec, time.has_value());
  RenderLayers layers = render_layers(loaded, s.accel.get(), p);
  finish_render(loaded, p);
  if (prepared_out) *prepared_out = p;
  return layers;
}

/// What the centre of pixel (x, y) sees on the plane z = 0 through a camera at `eye` looking
/// down -z (the pinhole formula: the image plane at depth 1 spans tan(yfov/2) * (aspect, 1)).
Vec3f plane_point(Vec3f eye, int x, int y) {
  const float tan_y = std::tan(0.5f * kYfov), tan_x = tan_y * float(kWidth) / float(kHeight);
  const float sx = 2 * (float(x) + 0.5f) / float(kWidth) - 1, sy = 1 - 2 * (float(y) + 0.5f) / float(kHeight);
  return {eye.x + eye.z * sx * tan_x, eye.y + eye.z * sy * tan_y, 0};
}

/// Pixels per scene unit on the plane z = 0 seen from depth 5.
float pixels_per_unit() {
  return float(kHeight) / (2 * 5 * std::tan(0.5f * kYfov));
}

/// Whether point p of the plane lies on the quad centred at `centre`, `margin` inside its edges.
bool on_quad(Vec3f p, Vec3f centre, float margin) {
  return std::abs(p.x - centre.x) < 1 - margin && std::abs(p.y - centre.y) < 1 - margin;
}

/// Checks every pixel: on the quad (at `centre` now) the expected vector, off it 0; pixels
/// within 0.1 of an edge are skipped (the edge moves between frames).
void check_pixels(const std::vector<float>& v, Vec3f eye, Vec3f centre, const float expected[4]) {
  REQUIRE(v.size() == size_t(kWidth) * kHeight * 4);
  int on = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const Vec3f p = plane_point(eye, x, y);
      const bool inside = on_quad(p, centre, 0.1f), outside = !on_quad(p, centre, -0.1f);
      if (!inside && !outside) continue;
      on += inside;
      const size_t i = (size_t(y) * kWidth + size_t(x)) * 4;
      for (int c = 0; c < 4; ++c) {
        INFO("pixel " << x << "," << y << " channel "
                      << "XYZW"[c]);
        CHECK(std::abs(v[i + size_t(c)] - (inside ? expected[c] : 0.0f)) < kTolerance);
      }
    }
  CHECK(on > 50);
}

}  // namespace

TEST_CASE("vector: a translating object moves by its projected displacement", "[session][vector]") {
  // The quad moves +x at 1.5 units per second (0.3 s to 3.3 s: linear through 1 s +- 1/24).
  const auto file = write_scene("translate", Quad::Rigid, [](test::GltfWriter& w, int quad, int) {
    w.channel(quad, "translation", {0.0f, 2.0f}, {0, 0, 0, 3, 0, 0}, "VEC3", 3);
  });
  const double time = 1.0;
  const float step = float(1.5 / kFps) * pixels_per_unit();
  // Cycles: X,Y = previous - now (the quad was to the left: negative), Z,W = now - next.
  const float expected[4] = {-step, 0, -step, 0};
  for (const char* integrator : {"whitted", "path", "raster"}) {
    INFO(integrator);
    const RenderLayers layers = render_vectors(file, time, integrator);
    check_pixels(layers.vector, {0, 0, 5}, {1.5f, 0, 0}, expected);
  }
}

TEST_CASE("vector: a moving camera reprojects the still world point of each pixel", "[session][vector]") {
  // The camera rises at 2 units per second and moves -x at 1: its eye at time t is (-t, 2t, 5).
  const auto file = write_scene("camera", Quad::Rigid, [](test::GltfWriter& w, int, int camera) {
    w.channel(camera, "translation", {0.0f, 1.0f}, {0, 0, 5, -1, 2, 5}, "VEC3", 3);
  });
  const double time = 0.25;
  const Vec3f eye{-0.25f, 0.5f, 5};
  const RenderLayers layers = render_vectors(file, time);
  REQUIRE(layers.vector.size() == size_t(kWidth) * kHeight * 4);
  const float dt = float(1 / kFps), tan_y = std::tan(0.5f * kYfov);
  const float tan_x = tan_y * float(kWidth) / float(kHeight);
  // Raster position (y up, as the layer counts) of world point p through the camera at `e`.
  const auto raster_up = [&](Vec3f p, Vec3f e) {
    return Vec2f{(1 + (p.x - e.x) / (e.z * tan_x)) * 0.5f * kWidth,
                 (1 + (p.y - e.y) / (e.z * tan_y)) * 0.5f * kHeight};
  };
  int on = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const Vec3f p = plane_point(eye, x, y);
      if (!on_quad(p, {0, 0, 0}, 0.01f)) continue;
      ++on;
      const Vec2f now = raster_up(p, eye);
      const Vec2f before = raster_up(p, eye + Vec3f{dt, -2 * dt, 0});
      const Vec2f after = raster_up(p, eye + Vec3f{-dt, 2 * dt, 0});
      const size_t i = (size_t(y) * kWidth + size_t(x)) * 4;
      INFO("pixel " << x << "," << y);
      CHECK(std::abs(layers.vector[i] - (before.x - now.x)) < kTolerance);
      CHECK(std::abs(layers.vector[i + 1] - (before.y - now.y)) < kTolerance);
      CHECK(std::abs(layers.vector[i + 2] - (now.x - after.x)) < kTolerance);
      CHECK(std::abs(layers.vector[i + 3] - (now.y - after.y)) < kTolerance);
      // The camera rises: the still quad was higher in the previous frame (Y > 0).
      CHECK(layers.vector[i + 1] > 0.5f);
    }
  CHECK(on > 50);
}

TEST_CASE("vector: a morph target's moving vertices", "[session][vector]") {
  // The weight of a +1 x offset rises from 0 to 1 over 2 s: the vertices move +x at 0.5 per second.
  const auto file = write_scene("morph", Quad::Morph, [](test::GltfWriter& w, int quad, int) {
    w.channel(quad, "weights", {0.0f, 2.0f}, {0, 1}, "SCALAR", 1);
  });
  const float step = float(0.5 / kFps) * pixels_per_unit();
  const float expected[4] = {-step, 0, -step, 0};
  const RenderLayers layers = render_vectors(file, 1.0);
  REQUIRE(step > 0.1f);
  check_pixels(layers.vector, {0, 0, 5}, {0.5f, 0, 0}, expected);
}

TEST_CASE("vector: a skin stretching the quad moves each point by its share", "[session][vector]") {
  // The right edge's joint moves +x at 1.5 units per second; the left edge stays. At time 1 the
  // quad spans x in [-1, 2.5]; a point a fraction f of the way across moves f * 1.5 / fps.
  const auto file = write_scene("skin", Quad::Skin, [](test::GltfWriter& w, int joint, int) {
    w.channel(joint, "translation", {0.0f, 2.0f}, {0, 0, 0, 3, 0, 0}, "VEC3", 3);
  });
  const RenderLayers layers = render_vectors(file, 1.0);
  REQUIRE(layers.vector.size() == size_t(kWidth) * kHeight * 4);
  int on = 0;
  float largest = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const Vec3f p = plane_point({0, 0, 5}, x, y);
      if (!(p.x > -0.9f && p.x < 2.4f && std::abs(p.y) < 0.9f)) continue;
      ++on;
      const float f = (p.x + 1) / 3.5f;
      const float step = f * float(1.5 / kFps) * pixels_per_unit();
      const size_t i = (size_t(y) * kWidth + size_t(x)) * 4;
      INFO("pixel " << x << "," << y);
      CHECK(std::abs(layers.vector[i] + step) < kTolerance);
      CHECK(std::abs(layers.vector[i + 1]) < kTolerance);
      CHECK(std::abs(layers.vector[i + 2] + step) < kTolerance);
      CHECK(std::abs(layers.vector[i + 3]) < kTolerance);
      largest = std::max(largest, step);
    }
  CHECK(on > 50);
  CHECK(largest > 0.3f);
}

TEST_CASE("vector: EXT_mesh_gpu_instancing copies follow their animated node", "[session][vector]") {
  // Two copies of a 0.8-wide quad at x = -1.5 and +1.5 under a node rising at 1.5 units per
  // second: every copy moves up 1.5 / fps a frame (Y = W = minus that, in pixels).
  test::GltfWriter w;
  const int pos = w.positions({-0.4f, -0.4f, 0, 0.4f, -0.4f, 0, 0.4f, 0.4f, 0, -0.4f, 0.4f, 0});
  const int mesh = w.mesh(pos, w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
  const int copies = w.floats({-1.5f, 0, 0, 1.5f, 0, 0}, "VEC3", 3);
  nlohmann::json node = {{"mesh", mesh}};
  node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {{"TRANSLATION", copies}};
  const int moved = w.node(node);
  w.j["extensionsUsed"] = {"EXT_mesh_gpu_instancing"};
  w.j["cameras"] = {
      {{"type", "perspective"}, {"perspective", {{"yfov", kYfov}, {"znear", 0.1}, {"aspectRatio", 1.5}}}}};
  w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  w.channel(moved, "translation", {0.0f, 2.0f}, {0, 0, 0, 0, 3, 0}, "VEC3", 3);
  const auto file = test::temp_dir("vector-instancing") / "instancing.gltf";
  w.write_embedded(file);
  // At time 0.2 the copies are centred at (-+1.5, 0.3).
  const RenderLayers layers = render_vectors(file, 0.2);
  REQUIRE(layers.vector.size() == size_t(kWidth) * kHeight * 4);
  const float step = float(1.5 / kFps) * pixels_per_unit();
  int on = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const Vec3f p = plane_point({0, 0, 5}, x, y);
      const bool inside = std::abs(std::abs(p.x) - 1.5f) < 0.3f && std::abs(p.y - 0.3f) < 0.3f;
      const bool outside = std::abs(std::abs(p.x) - 1.5f) > 0.5f || std::abs(p.y - 0.3f) > 0.5f;
      if (!inside && !outside) continue;
      on += inside;
      const float want[4] = {0, inside ? -step : 0, 0, inside ? -step : 0};
      const size_t i = (size_t(y) * kWidth + size_t(x)) * 4;
      INFO("pixel " << x << "," << y);
      for (int c = 0; c < 4; ++c) CHECK(std::abs(layers.vector[i + size_t(c)] - want[c]) < kTolerance);
    }
  CHECK(on > 20);
}

TEST_CASE("vector: still scenes and static renders give zero vectors", "[session][vector]") {
  const auto still = write_scene("still", Quad::Rigid, [](test::GltfWriter&, int, int) {});
  const float zero[4] = {0, 0, 0, 0};
  check_pixels(render_vectors(still, 2.0).vector, {0, 0, 5}, {0, 0, 0}, zero);
  // The static pose is no point of the timeline: zero, with a warning.
  const auto moving = write_scene("static", Quad::Rigid, [](test::GltfWriter& w, int quad, int) {
    w.channel(quad, "translation", {0.0f, 2.0f}, {0, 0, 0, 3, 0, 0}, "VEC3", 3);
  });
  PreparedRender p;
  const RenderLayers layers = render_vectors(moving, std::nullopt, "whitted", &p);
  check_pixels(layers.vector, {0, 0, 5}, {0, 0, 0}, zero);
  CHECK(p.motion == nullptr);
  REQUIRE(p.warnings.size() == 1);
  CHECK(p.warnings[0].find("static pose") != std::string::npos);
}

TEST_CASE("vector: neighbouring frames that do not match the scene are an error", "[session][vector]") {
  const auto file = write_scene("mismatch", Quad::Rigid, [](test::GltfWriter&, int, int) {});
  const auto other = write_scene("mismatch-other", Quad::Morph, [](test::GltfWriter& w, int, int) {
    w.node({{"mesh", 0}, {"translation", {3, 0, 0}}});
  });
  LoadedScene loaded = load_gltf(file, {});
  PrepareOptions o;
  o.scene_file = file.string();
  o.time = 0.5;
  o.load_at = [&](double t) {
    GltfLoadOptions at;
    at.time = t;
    return load_gltf(other, at);
  };
  CHECK_THROWS_WITH(prepare_render(loaded, vector_spec("whitted"), o), Catch::Contains("instances"));
  o.load_at = nullptr;
  CHECK_THROWS_AS(prepare_render(loaded, vector_spec("whitted"), o), std::invalid_argument);
}

/// Checks the velocity layer at every pixel whose centre sees the quad at `centre` (0.1 inside
/// its edges) through a camera at `eye`: `expected`, in camera space; 0 well off the quad.
void check_velocity(const std::vector<float>& v, Vec3f eye, Vec3f centre, Vec3f expected) {
  REQUIRE(v.size() == size_t(kWidth) * kHeight * kVelocityChannels);
  int on = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const Vec3f p = plane_point(eye, x, y);
      const bool inside = on_quad(p, centre, 0.1f), outside = !on_quad(p, centre, -0.3f);
      if (!inside && !outside) continue;
      on += inside;
      const size_t i = (size_t(y) * kWidth + size_t(x)) * kVelocityChannels;
      for (int c = 0; c < kVelocityChannels; ++c) {
        INFO("pixel " << x << "," << y << " channel "
                      << "XYZ"[c]);
        CHECK(v[i + size_t(c)] == Approx(inside ? expected[c] : 0.0f).margin(1e-3));
      }
    }
  CHECK(on > 50);
}

TEST_CASE("velocity: a translating quad's camera-space velocity", "[session][vector]") {
  // The quad moves +x at 1.5 units per second and, in a second file, towards the camera (+z) at
  // 1; the camera stays at z = 5 looking down -z, so camera space is world space shifted.
  const auto across = write_scene("velocity-x", Quad::Rigid, [](test::GltfWriter& w, int quad, int) {
    w.channel(quad, "translation", {0.0f, 2.0f}, {0, 0, 0, 3, 0, 0}, "VEC3", 3);
  });
  const RenderLayers both = render_vectors(across, 1.0, "whitted", nullptr, {"vector", "velocity"});
  check_velocity(both.velocity, {0, 0, 5}, {1.5f, 0, 0}, {1.5f, 0, 0});
  REQUIRE(both.vector.size() == size_t(kWidth) * kHeight * kMotionVectorChannels);
  // The velocity alone: the same numbers, and no vector layer.
  const RenderLayers alone = render_vectors(across, 1.0, "path", nullptr, {"velocity"});
  CHECK(alone.velocity == both.velocity);
  CHECK(alone.vector.empty());
  const auto towards = write_scene("velocity-z", Quad::Rigid, [](test::GltfWriter& w, int quad, int) {
    w.channel(quad, "translation", {0.0f, 2.0f}, {0, 0, 0, 0, 0, 2}, "VEC3", 3);
  });
  const RenderLayers z = render_vectors(towards, 1.0, "whitted", nullptr, {"velocity"});
  const size_t centre = (size_t(kHeight / 2) * kWidth + size_t(kWidth / 2)) * kVelocityChannels;
  CHECK(z.velocity[centre] == Approx(0).margin(1e-3));
  CHECK(z.velocity[centre + 1] == Approx(0).margin(1e-3));
  CHECK(z.velocity[centre + 2] == Approx(1).margin(1e-3));  // approaching: +Z
}

TEST_CASE("velocity: a moving camera sees the still quad move the other way", "[session][vector]") {
  // The camera's eye moves (-1, 2, 0) units per second: in its space (axes those of the world)
  // every still point moves (1, -2, 0).
  const auto file = write_scene("velocity-camera", Quad::Rigid, [](test::GltfWriter& w, int, int camera) {
    w.channel(camera, "translation", {0.0f, 1.0f}, {0, 0, 5, -1, 2, 5}, "VEC3", 3);
  });
  const RenderLayers layers = render_vectors(file, 0.25, "whitted", nullptr, {"velocity"});
  check_velocity(layers.velocity, {-0.25f, 0.5f, 5}, {0, 0, 0}, {1, -2, 0});
}

TEST_CASE("vector: the identity records fps with the layer", "[session][vector]") {
  RenderSpec a = vector_spec("path"), b = a;
  b.fps = 30;
  const SceneIdentity scene;
  const Camera cam;
  CHECK(render_identity(a, cam, scene).entries != render_identity(b, cam, scene).entries);
  a.aovs.clear();
  b.aovs.clear();
  CHECK(render_identity(a, cam, scene).entries == render_identity(b, cam, scene).entries);
  a.aovs = b.aovs = {"velocity"};
  CHECK(render_identity(a, cam, scene).entries != render_identity(b, cam, scene).entries);
}

}  // namespace penumbra
