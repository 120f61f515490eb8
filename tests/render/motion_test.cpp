// Motion blur through the render session: a blurred streak as long as the velocity times the
// shutter, a spinning bar whose blur follows the arc (slerp) and not the chord, and a blurred
// render equal to the mean of still renders spread over the shutter, for moving nodes and for
// skinned and morphed meshes; the shutter's settings are checked and recorded in the identity.
// Scenes are small glTF files with node, skin and morph-weight animations.
#include "render/motion.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "io/files/error.h"
#include "render/session.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

namespace penumbra {
namespace {

/// A glTF file: an orthographic camera at z = 5 looking down -Z (half-height `ymag`) and one
/// mesh (`xyz`, a quad's two triangles) on node 1, animated by `anim`.
template <class Animate>
std::filesystem::path write_scene(const std::string& name, const std::vector<float>& xyz, float ymag,
                                  Animate&& anim) {
  test::GltfWriter w;
  const int mesh = w.mesh(w.positions(xyz), w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
  w.j["cameras"] = {{{"type", "orthographic"},
                     {"orthographic", {{"xmag", ymag}, {"ymag", ymag}, {"znear", 0.01}, {"zfar", 100}}}}};
  w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  const int node = w.node({{"mesh", mesh}});
  anim(w, node);
  const auto dir = test::temp_dir("motion");
  std::filesystem::create_directories(dir);
  const auto path = dir / (name + ".gltf");
  w.write_embedded(path);
  return path;
}

/// The scene loaded at `time` with its animation kept, as a session.
void load(Session& s, const std::filesystem::path& file, double time) {
  GltfLoadOptions o;
  o.time = time;
  o.keep_animation = true;
  s.file = file.string();
  s.loaded = load_gltf(file, o);
  s.loaded_at_time = true;
  s.time = time;
}

RenderSpec spec_of(int size, int spp, const char* accel = "embree") {
  return {.width = size, .height = size, .spp = spp, .accel = accel};
}

float alpha(const Film& f, int x, int y) {
  return f.pixel(x, y)[3];
}

}  // namespace

TEST_CASE("motion blur: a translating quad's streak is its velocity times the shutter", "[motion]") {
  // A 0.1-wide quad moving along +X at 24 units per second; at frame time 1 (24 fps, shutter
  // 0.5: 1/48 s) it sweeps x in [-0.25, 0.25]: its blur spans 0.6 units (19.2 px at 32 px per
  // unit) with a plateau of coverage 0.1 / 0.5 = 0.2 in the middle.
  const auto file =
      write_scene("streak", {-0.05f, -0.05f, 0, 0.05f, -0.05f, 0, 0.05f, 0.05f, 0, -0.05f, 0.05f, 0}, 2,
                  [](test::GltfWriter& w, int node) {
                    w.channel(node, "translation", {0, 2}, {-24, 0, 0, 24, 0, 0}, "VEC3", 3);
                  });
  for (const char* accel : {"embree", "bvh"}) {
    INFO(accel);
    Session s;
    load(s, file, 1.0);
    RenderSpec spec = spec_of(128, 256, accel);
    spec.motion_blur = true;
    const RenderResult r = render_scene(s, spec, 0);
    const Film& f = r.image.film;
    int first = -1, last = -1;
    double energy = 0;
    for (int x = 0; x < 128; ++x) {
      const float a = 0.5f * (alpha(f, x, 63) + alpha(f, x, 64));
      energy += a;
      if (a > 0.01f) last = x, first = first < 0 ? x : first;
    }
    CHECK(float(last + 1 - first) == Approx(19.2).margin(1.5));
    CHECK(energy == Approx(3.2).epsilon(0.05));  // coverage is conserved: the quad's own 3.2 px
    for (int x = 60; x < 68; ++x) CHECK(alpha(f, x, 64) == Approx(0.2).margin(0.04));
    CHECK(r.prepared.identity.entries.at("motion_blur") == "1");
    CHECK(r.prepared.identity.entries.at("scene.shutter").find("..") != std::string::npos);
    // Without motion blur the quad is still, at x = 0: 3.2 px wide.
    const RenderResult still = render_scene(s, spec_of(128, 16, accel), 0);
    int covered = 0;
    for (int x = 0; x < 128; ++x) covered += alpha(still.image.film, x, 64) > 0.01f;
    CHECK(covered <= 5);
    CHECK(still.prepared.identity.entries.count("scene.shutter") == 0);
  }
}

TEST_CASE("motion blur: a still quad seen by a moving camera streaks as far as the camera moves",
          "[motion]") {
  // The camera (node 0) moves along +X at 24 units per second; the 0.1-wide quad stays at the
  // origin: at t = 1 it sweeps the image over 0.5 units (16 px), its blur spans 19.2 px.
  const auto file =
      write_scene("camera", {-0.05f, -0.05f, 0, 0.05f, -0.05f, 0, 0.05f, 0.05f, 0, -0.05f, 0.05f, 0}, 2,
                  [](test::GltfWriter& w, int) {
                    w.channel(0, "translation", {0, 2}, {-24, 0, 5, 24, 0, 5}, "VEC3", 3);
                  });
  Session s;
  load(s, file, 1.0);
  RenderSpec spec = spec_of(128, 256, "bvh");
  spec.motion_blur = true;
  const RenderResult r = render_scene(s, spec, 0);
  CHECK(s.loaded.scene.instance_motion.empty());  // nothing else moves
  int first = -1, last = -1;
  for (int x = 0; x < 128; ++x)
    if (alpha(r.image.film, x, 64) > 0.01f) last = x, first = first < 0 ? x : first;
  CHECK(float(last + 1 - first) == Approx(19.2).margin(1.5));
  CHECK(alpha(r.image.film, 64, 64) == Approx(0.2).margin(0.04));
}

TEST_CASE("motion blur: a spinning bar blurs along the arc its end draws, not the chord", "[motion]") {
  // A bar from the origin to x = 1 turning about +Z: 0, 90 and 180 degrees at t = 0, 1, 2.
  // Rendered at t = 1 with a shutter of one frame at 1 fps it sweeps 45..135 degrees, keyed at
  // 45, 90 and 135 (3 steps). Slerp keeps the tip on the unit circle between keys; a blend of
  // the matrices would pull it to radius cos(22.5 deg) = 0.92 half-way between them.
  const float h = 0.02f;
  const auto file =
      write_scene("bar", {0, -h, 0, 1, -h, 0, 1, h, 0, 0, h, 0}, 1.2f, [](test::GltfWriter& w, int node) {
        const float s = std::sqrt(0.5f);
        w.channel(node, "rotation", {0, 1, 2}, {0, 0, 0, 1, 0, 0, s, s, 0, 0, 1, 0}, "VEC4", 4);
      });
  Session s;
  load(s, file, 1.0);
  RenderSpec spec = spec_of(128, 256, "bvh");
  spec.motion_blur = true;
  spec.fps = 1;
  spec.shutter = 1;
  const RenderResult r = render_scene(s, spec, 0);
  const Film& f = r.image.film;
  const float px = 128 / 2.4f;  // pixels per unit
  double rim = 0, outside = 0;
  int rim_pixels = 0;
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      const float wx = (float(x) + 0.5f - 64) / px, wy = (64 - float(y) - 0.5f) / px;
      const float radius = std::hypot(wx, wy), angle = std::atan2(wy, wx) * 180 / float(kPi);
      if (radius > 1.04f) outside += alpha(f, x, y);
      // Half-way between the keys at 45 and 90 degrees, and between 90 and 135.
      const bool between = std::fabs(angle - 67.5f) < 6 || std::fabs(angle - 112.5f) < 6;
      if (between && radius > 0.95f && radius < 0.99f) rim += alpha(f, x, y), ++rim_pixels;
    }
  CHECK(outside == 0);
  REQUIRE(rim_pixels > 0);
  // The bar covers a point at radius r for (2 h / r) / (pi / 2) of the shutter: ~0.026 at 0.97.
  CHECK(rim / rim_pixels == Approx(2 * h / 0.97 / (kPi / 2)).epsilon(0.35));
}

TEST_CASE("motion blur: a blurred render is the mean of still renders over the shutter", "[motion]") {
  // A quad translating and turning; 16 still renders at the midpoints of 16 equal slices of
  // the shutter against one blurred render with the same number of samples in all.
  const auto file =
      write_scene("average", {-0.4f, -0.3f, 0, 0.4f, -0.3f, 0, 0.4f, 0.3f, 0, -0.4f, 0.3f, 0}, 1.5f,
                  [](test::GltfWriter& w, int node) {
                    const float s = std::sin(0.6f), c = std::cos(0.6f);
                    w.channel(node, "translation", {0, 2}, {-1.5f, 0, 0, 1.5f, 0.5f, 0}, "VEC3", 3);
                    w.channel(node, "rotation", {0, 2}, {0, 0, 0, 1, 0, 0, s, c}, "VEC4", 4);
                  });
  for (const char* accel : {"embree", "bvh", "kdtree"}) {
    INFO(accel);
    Session s;
    load(s, file, 1.0);
    RenderSpec spec = spec_of(48, 256, accel);
    spec.motion_blur = true;
    spec.fps = 2;
    spec.shutter = 1;  // t in [0.75, 1.25]
    const Film blurred = render_scene(s, spec, 0).image.film;
    std::vector<double> mean(blurred.rgba.size(), 0.0);
    const int n = 16;
    for (int i = 0; i < n; ++i) {
      REQUIRE(pose_gltf_scene(*s.loaded.animation, 0.75 + 0.5 * (i + 0.5) / n, s.loaded.scene));
      s.structure = Structure{};  // the placements moved: built anew
      const Film still = render_scene(s, spec_of(48, 16, accel), 0).image.film;
      for (size_t k = 0; k < mean.size(); ++k) mean[k] += still.rgba[k] / n;
    }
    REQUIRE(pose_gltf_scene(*s.loaded.animation, 1.0, s.loaded.scene));
    s.structure = Structure{};
    const Film frame = render_scene(s, spec_of(48, 16, accel), 0).image.film;
    double err = 0, err_still = 0;
    for (size_t k = 3; k < mean.size(); k += 4) {
      err += (blurred.rgba[k] - mean[k]) * (blurred.rgba[k] - mean[k]);
      err_still += (frame.rgba[k] - mean[k]) * (frame.rgba[k] - mean[k]);
    }
    const double pixels = double(mean.size() / 4);
    const double rmse = std::sqrt(err / pixels), rmse_still = std::sqrt(err_still / pixels);
    // Coverage noise of 256 samples is at most 0.03 per pixel; the still frame is far off.
    CHECK(rmse < 0.02);
    CHECK(rmse_still > 5 * rmse);
  }
}

TEST_CASE("motion blur: the shutter's settings need motion blur and are checked", "[motion][quick]") {
  RenderSpec s;
  s.shutter = 0.25f;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("shutter needs motion_blur"));
  s.motion_blur = true;
  CHECK_NOTHROW(validate(s));
  s.motion_steps = 1;
  CHECK_THROWS_WITH(validate(s), Catch::Contains("motion_steps must be in [2, 64]"));
  s.motion_steps = 3;
  s.shutter_offset = 0.5f;
  s.fps = 25;
  const Shutter sh = shutter_interval(s, 2.0);
  CHECK(sh.open == Approx(2.0 + 0.5 / 25 - 0.125 / 25));
  CHECK(sh.close == Approx(2.0 + 0.5 / 25 + 0.125 / 25));
}

namespace {

/// A file whose animation deforms a 0.8 x 0.6 quad (seen as write_scene's camera sees it): a
/// morph target shearing its top edge +1.6 in x at weight 1, weight 0 to 1 over two seconds
/// (`skin` false), or a skin whose right edge follows a joint moving +1.2 in x over two seconds.
/// Both move every vertex linearly in time.
std::filesystem::path write_deforming(bool skin) {
  test::GltfWriter w;
  const int pos = w.positions({-0.4f, -0.3f, 0, 0.4f, -0.3f, 0, 0.4f, 0.3f, 0, -0.4f, 0.3f, 0});
  const int mesh = skin ? w.skinned_mesh(pos, {0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0},
                                         {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0})
                        : w.morph_mesh(pos, w.positions({0, 0, 0, 0, 0, 0, 1.6f, 0, 0, 1.6f, 0, 0}));
  w.j["meshes"][size_t(mesh)]["primitives"][0]["indices"] =
      w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
  w.j["cameras"] = {{{"type", "orthographic"},
                     {"orthographic", {{"xmag", 1.5}, {"ymag", 1.5}, {"znear", 0.01}, {"zfar", 100}}}}};
  w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  const int node = w.node({{"mesh", mesh}});
  if (skin) {
    w.j["nodes"][size_t(node)]["skin"] = 0;
    const int left = w.node(nlohmann::json::object());
    const int right = w.node(nlohmann::json::object());
    w.j["skins"] = {{{"joints", {left, right}}}};
    w.channel(right, "translation", {0, 2}, {0, 0, 0, 1.2f, 0, 0}, "VEC3", 3);
  } else {
    w.channel(node, "weights", {0, 2}, {0, 1}, "SCALAR", 1);
  }
  const auto dir = test::temp_dir("motion");
  std::filesystem::create_directories(dir);
  const auto path = dir / (skin ? "skin.gltf" : "morph.gltf");
  w.write_embedded(path);
  return path;
}

/// A session over `file` loaded at `time`, able to load it at other times.
void load_with_frames(Session& s, const std::filesystem::path& file, double time) {
  load(s, file, time);
  s.load_at = [file](double t) {
    GltfLoadOptions o;
    o.time = t;
    return load_gltf(file, o);
  };
}

}  // namespace

TEST_CASE("motion blur: a skinned or morphed mesh blurs as the mean of still renders", "[motion]") {
  // The deformation over the shutter t in [0.75, 1.25] against 16 stills, each the file loaded
  // at the midpoint of one slice of the shutter; Embree's multi-step geometry, the own BVH and
  // the kD-tree (both through the time-aware deforming structure) and brute force.
  for (const bool skin : {false, true}) {
    const auto file = write_deforming(skin);
    for (const char* accel : {"embree", "bvh", "kdtree", "brute"}) {
      INFO((skin ? "skin " : "morph ") << accel);
      Session s;
      load_with_frames(s, file, 1.0);
      RenderSpec spec = spec_of(48, 1024, accel);
      spec.motion_blur = true;
      spec.fps = 2;
      spec.shutter = 1;
      const Film blurred = render_scene(s, spec, 0).image.film;
      REQUIRE(s.loaded.scene.meshes.size() == 1);
      CHECK(s.loaded.scene.meshes[0].motion_steps == 3);
      std::vector<double> mean(blurred.rgba.size(), 0.0);
      const int n = 16;
      for (int i = 0; i < n; ++i) {
        Session still;
        load(still, file, 0.75 + 0.5 * (i + 0.5) / n);
        const Film f = render_scene(still, spec_of(48, 64, accel), 0).image.film;
        for (size_t k = 0; k < mean.size(); ++k) mean[k] += f.rgba[k] / n;
      }
      Session frame;
      load(frame, file, 1.0);
      const Film f = render_scene(frame, spec_of(48, 64, accel), 0).image.film;
      double err = 0, err_still = 0;
      for (size_t k = 3; k < mean.size(); k += 4) {
        err += (blurred.rgba[k] - mean[k]) * (blurred.rgba[k] - mean[k]);
        err_still += (f.rgba[k] - mean[k]) * (f.rgba[k] - mean[k]);
      }
      const double pixels = double(mean.size() / 4);
      const double rmse = std::sqrt(err / pixels), rmse_still = std::sqrt(err_still / pixels);
      // Coverage noise of 1024 samples is at most 0.016 per pixel; the still frame is far off.
      CHECK(rmse < 0.01);
      CHECK(rmse_still > 5 * rmse);
    }
  }
}

TEST_CASE("motion blur: a moving point light lights a still floor as the mean of its poses", "[motion]") {
  // A point light 0.6 above a floor filling the view, sliding along x at 2 units per second:
  // over the shutter t in [0.75, 1.25] it covers a unit. Whitted: the blurred render against 16
  // stills at the midpoints of 16 slices of the shutter.
  const auto file =
      write_scene("light", {-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0}, 1.5f, [](test::GltfWriter& w, int) {
        w.j["extensionsUsed"] = {"KHR_lights_punctual"};
        w.j["extensions"]["KHR_lights_punctual"]["lights"] = {{{"type", "point"}, {"intensity", 1.0}}};
        nlohmann::json node = {{"translation", {-2, 0, 0.6}}};
        node["extensions"]["KHR_lights_punctual"]["light"] = 0;
        const int light = w.node(node);
        w.channel(light, "translation", {0, 2}, {-2, 0, 0.6f, 2, 0, 0.6f}, "VEC3", 3);
      });
  Session s;
  load(s, file, 1.0);
  RenderSpec spec = spec_of(48, 64);
  spec.motion_blur = true;
  spec.fps = 2;
  spec.shutter = 1;
  const Film blurred = render_scene(s, spec, 0).image.film;
  REQUIRE(s.loaded.scene.light_motion.size() == 1);
  CHECK(s.loaded.scene.light_motion[0].size() == 3);
  std::vector<double> mean(blurred.rgba.size(), 0.0);
  const int n = 16;
  for (int i = 0; i < n; ++i) {
    REQUIRE(pose_gltf_scene(*s.loaded.animation, 0.75 + 0.5 * (i + 0.5) / n, s.loaded.scene));
    const Film still = render_scene(s, spec_of(48, 4), 0).image.film;
    for (size_t k = 0; k < mean.size(); ++k) mean[k] += still.rgba[k] / n;
  }
  REQUIRE(pose_gltf_scene(*s.loaded.animation, 1.0, s.loaded.scene));
  const Film frame = render_scene(s, spec_of(48, 4), 0).image.film;
  double err = 0, err_still = 0, level = 0;
  for (size_t k = 0; k < mean.size(); ++k) {
    if (k % 4 == 3) continue;
    err += (blurred.rgba[k] - mean[k]) * (blurred.rgba[k] - mean[k]);
    err_still += (frame.rgba[k] - mean[k]) * (frame.rgba[k] - mean[k]);
    level += mean[k] * mean[k];
  }
  INFO("rms " << std::sqrt(level) << " blurred " << std::sqrt(err) << " still " << std::sqrt(err_still));
  CHECK(std::sqrt(err) < 0.02 * std::sqrt(level));
  CHECK(err_still > 25 * err);
}

namespace {

/// A floor filling write_scene's view (white diffuse) under a 0.4 x 0.4 double-sided emitter
/// 0.6 above it that slides from x = -2 to x = 2 over two seconds: its node moves (`deform`
/// false), or its mesh does, by a morph target that adds 4 to every vertex's x.
std::filesystem::path write_moving_emitter(bool deform) {
  test::GltfWriter w;
  const int floor = w.mesh(w.positions({-2, -2, 0, 2, -2, 0, 2, 2, 0, -2, 2, 0}),
                           w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3}));
  const int quad = w.positions({-0.2f, -0.2f, 0, 0.2f, -0.2f, 0, 0.2f, 0.2f, 0, -0.2f, 0.2f, 0});
  const int light =
      deform ? w.morph_mesh(quad, w.positions({4, 0, 0, 4, 0, 0, 4, 0, 0, 4, 0, 0})) : w.mesh(quad);
  w.j["meshes"][size_t(light)]["primitives"][0]["indices"] =
      w.indices(std::vector<uint16_t>{0, 1, 2, 0, 2, 3});
  w.j["materials"] = {
      {{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1}}, {"metallicFactor", 0}}}},
      {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}}},
       {"emissiveFactor", {1, 1, 1}},
       {"doubleSided", true}}};
  w.j["meshes"][size_t(floor)]["primitives"][0]["material"] = 0;
  w.j["meshes"][size_t(light)]["primitives"][0]["material"] = 1;
  w.j["cameras"] = {{{"type", "orthographic"},
                     {"orthographic", {{"xmag", 1.5}, {"ymag", 1.5}, {"znear", 0.01}, {"zfar", 100}}}}};
  w.node({{"camera", 0}, {"translation", {0, 0, 5}}});
  w.node({{"mesh", floor}});
  if (deform) {
    const int node = w.node({{"mesh", light}, {"translation", {-2, 0, 0.6}}});
    w.channel(node, "weights", {0, 2}, {0, 1}, "SCALAR", 1);
  } else {
    const int node = w.node({{"mesh", light}});
    w.channel(node, "translation", {0, 2}, {-2, 0, 0.6f, 2, 0, 0.6f}, "VEC3", 3);
  }
  const auto dir = test::temp_dir("motion");
  std::filesystem::create_directories(dir);
  const auto path = dir / (deform ? "emitter_morph.gltf" : "emitter_node.gltf");
  w.write_embedded(path);
  return path;
}

}  // namespace

TEST_CASE("motion blur: a moving emitter lights a still floor as the mean of its poses", "[motion][heavy]") {
  // The path tracer's light sampling picks points on the emitter where it is at each sample's
  // time (and weighs them against BSDF hits with the density at that time): the blurred render
  // equals the mean of 16 stills at the midpoints of 16 slices of the shutter t in [0.75, 1.25],
  // over which the emitter covers a unit, for a moving node and for a deforming mesh.
  for (const bool deform : {false, true}) {
    INFO((deform ? "morph" : "node"));
    const auto file = write_moving_emitter(deform);
    Session s;
    load_with_frames(s, file, 1.0);
    RenderSpec spec = spec_of(32, 512);
    spec.integrator = "path";
    spec.max_depth = 1;
    spec.motion_blur = true;
    spec.fps = 2;
    spec.shutter = 1;
    const Film blurred = render_scene(s, spec, 0).image.film;
    std::vector<double> mean(blurred.rgba.size(), 0.0);
    RenderSpec still_spec = spec_of(32, 32);
    still_spec.integrator = "path";
    still_spec.max_depth = 1;
    const int n = 16;
    for (int i = 0; i < n; ++i) {
      Session still;
      load(still, file, 0.75 + 0.5 * (i + 0.5) / n);
      still_spec.seed = uint64_t(i + 1);
      const Film f = render_scene(still, still_spec, 0).image.film;
      for (size_t k = 0; k < mean.size(); ++k) mean[k] += f.rgba[k] / n;
    }
    Session frame;
    load(frame, file, 1.0);
    still_spec.spp = 512;
    const Film f = render_scene(frame, still_spec, 0).image.film;
    // The floor only (the emitter's own pixels, seen directly, are checked by coverage tests).
    double err = 0, err_still = 0, level = 0;
    for (size_t k = 0; k < mean.size(); ++k) {
      if (k % 4 == 3 || mean[k] >= 0.5) continue;
      err += (blurred.rgba[k] - mean[k]) * (blurred.rgba[k] - mean[k]);
      err_still += (f.rgba[k] - mean[k]) * (f.rgba[k] - mean[k]);
      level += mean[k] * mean[k];
    }
    INFO("rms " << std::sqrt(level) << " blurred " << std::sqrt(err) << " still " << std::sqrt(err_still));
    CHECK(std::sqrt(err) < 0.03 * std::sqrt(level));
    CHECK(err_still > 25 * err);
  }
}

TEST_CASE("motion blur: a deforming animation without a way to load the file is refused by name",
          "[motion]") {
  const auto file = write_deforming(false);
  Session s;
  load(s, file, 0.5);  // no load_at
  RenderSpec spec = spec_of(16, 1);
  spec.motion_blur = true;
  CHECK_THROWS_WITH(render_scene(s, spec, 0),
                    Catch::Contains("morph.gltf") && Catch::Contains("deforms meshes"));
  // Without motion blur the frame's pose renders, and no mesh keeps steps.
  spec.motion_blur = false;
  CHECK(render_scene(s, spec, 0).image.film.rgba.size() == 16 * 16 * 4);
  CHECK(s.loaded.scene.meshes[0].motion_steps == 0);
}

TEST_CASE("motion blur: a deforming scene's structure follows each render's shutter", "[motion]") {
  // One session renders the morph with two shutters; the second render must equal a fresh
  // session's render of that shutter (a structure kept from the first would hold its steps).
  const auto file = write_deforming(false);
  for (const char* accel : {"embree", "bvh"}) {
    INFO(accel);
    RenderSpec spec = spec_of(24, 16, accel);
    spec.motion_blur = true;
    spec.fps = 2;
    Session s;
    load_with_frames(s, file, 1.0);
    render_scene(s, spec, 0);
    spec.shutter_offset = -1;
    const Film second = render_scene(s, spec, 0).image.film;
    Session fresh;
    load_with_frames(fresh, file, 1.0);
    const Film expected = render_scene(fresh, spec, 0).image.film;
    CHECK(second.rgba == expected.rgba);
  }
}

TEST_CASE("motion blur: a deforming scene loaded at its rest pose is not matched to loads at times",
          "[motion]") {
  // Loads at the shutter's times are posed; a scene loaded without a time is not: refused.
  const auto file = write_deforming(false);
  Session s;
  load_with_frames(s, file, 1.0);
  s.loaded = load_gltf(file);  // the rest pose
  s.loaded_at_time = false;
  RenderSpec spec = spec_of(16, 1);
  spec.motion_blur = true;
  CHECK_THROWS_WITH(render_scene(s, spec, 0),
                    Catch::Contains("morph.gltf") && Catch::Contains("not loaded at a time"));
}

TEST_CASE("motion blur: a scene loaded without its animation is refused, a still file renders", "[motion]") {
  const auto file = write_scene("refused", test::quad_positions(), 2, [](test::GltfWriter& w, int node) {
    w.channel(node, "translation", {0, 1}, {0, 0, 0, 1, 0, 0}, "VEC3", 3);
  });
  Session s;
  s.file = file.string();
  s.loaded = load_gltf(file);  // the static pose, without the animation
  RenderSpec spec = spec_of(16, 1);
  spec.motion_blur = true;
  CHECK_THROWS_AS(render_scene(s, spec, 0), InputError);
  const auto still = write_scene("still", test::quad_positions(), 2, [](test::GltfWriter&, int) {});
  Session t;
  load(t, still, 0);
  CHECK(render_scene(t, spec, 0).image.film.rgba.size() == 16 * 16 * 4);
  CHECK(t.loaded.scene.instance_motion.empty());
}

}  // namespace penumbra
