// The render session: its phases against the integrators called directly, the default key
// light added and removed, the structure kept between renders, and the front ends' one path.
#include "render/session.h"

#include <catch2/catch.hpp>

#include "io/files/error.h"
#include "renderer/core/motion.h"
#include "renderer/integrators/raster.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/scene/camera_rig.h"
#include "support/scene_builder.h"
#include "support/test_util.h"

namespace penumbra {
namespace {

LoadedScene default_scene() {
  return load_gltf(test::source_dir() / "scenes/default.gltf");
}

RenderSpec small(const char* integrator) {
  RenderSpec s;
  s.integrator = integrator;
  s.width = 24;
  s.height = 16;
  s.spp = 2;
  s.accel = "bvh";
  return s;
}

}  // namespace

TEST_CASE("session: one signature renders what each integrator renders when called directly", "[session]") {
  LoadedScene loaded = default_scene();
  for (const char* integrator : {"whitted", "path", "raster"}) {
    INFO(integrator);
    const RenderSpec spec = small(integrator);
    PrepareOptions o;
    o.scene_file = "default.gltf";
    PreparedRender p = prepare_render(loaded, spec, o);
    REQUIRE(p.config.width == 24);
    REQUIRE(p.config.height == 16);
    const Structure s = build_structure(loaded.scene, p.spec, false);
    REQUIRE(s.accel);
    CHECK(s.update == "built");
    const RenderImage image = render_image(loaded.scene, s.accel.get(), p);
    Film direct;
    if (p.integrator() == IntegratorType::Path)
      direct = render_path(loaded.scene, *s.accel, p.path_lights(), p.camera, p.config).film;
    else if (p.integrator() == IntegratorType::Raster)
      direct = render_raster(loaded.scene, s.accel.get(), p.camera, p.config);
    else
      direct = render_whitted(loaded.scene, *s.accel, p.camera, p.config);
    CHECK(image.film.rgba == direct.rgba);
    CHECK(image.complete);
    finish_render(loaded, p);
  }
}

TEST_CASE("session: the default key light lights an unlit scene for one render only", "[session]") {
  LoadedScene loaded;  // one white quad seen by the camera that frames it, and no light
  loaded.scene.materials.push_back(Material{});
  test::add_quad_z(loaded.scene, -1, 1, -1, 1, 0, 0);
  Session session;
  session.file = "default.gltf";
  session.loaded = std::move(loaded);
  const RenderResult r = render_scene(session, small("whitted"), 0);
  CHECK(r.prepared.default_light);
  CHECK(session.loaded.scene.lights.empty());
  // Lit by exactly the default key light: the same image as the scene with that light added.
  Scene lit = session.loaded.scene;
  lit.lights.push_back(default_key_light(r.prepared.camera));
  const auto accel = make_scene_accelerator("bvh", lit);
  CHECK(render_whitted(lit, *accel, r.prepared.camera, r.prepared.config).rgba == r.image.film.rgba);
  const Film unlit = render_whitted(session.loaded.scene, *accel, r.prepared.camera, r.prepared.config);
  CHECK(unlit.rgba != r.image.film.rgba);
}

TEST_CASE("session: the structure is kept while its name and parameters stay, rebuilt when they change",
          "[session]") {
  Session session;
  session.file = "default.gltf";
  session.loaded = default_scene();
  render_scene(session, small("whitted"), 0);
  const Accelerator* first = session.structure.accel.get();
  REQUIRE(first);
  render_scene(session, small("whitted"), 0);
  CHECK(session.structure.accel.get() == first);
  CHECK(session.structure.update == "built");
  RenderSpec other = small("whitted");
  other.accel_params = {"bvh.max_leaf_size=2"};
  render_scene(session, other, 0);
  CHECK(session.structure.key == "bvh bvh.max_leaf_size=2");
}

TEST_CASE("session: layers come from the beauty's samples and the identity from the spec", "[session]") {
  Session session;
  session.file = "default.gltf";
  session.loaded = default_scene();
  RenderSpec spec = small("path");
  spec.aovs = {"albedo", "id", "crypto_object", "cost"};
  const RenderResult r = render_scene(session, spec, 0);
  const size_t pixels = 24 * 16;
  CHECK(r.layers.data.albedo.size() == pixels * 3);
  CHECK(r.layers.data.object_id.size() == pixels);
  CHECK_FALSE(r.layers.id_manifest.empty());
  REQUIRE(r.layers.crypto_manifests.size() == 1);
  CHECK(r.layers.crypto.layers.size() == 1);
  CHECK(r.layers.cost.nanoseconds.size() == pixels);
  const RenderSettings again = render_identity(r.prepared.spec, r.prepared.camera, {});
  CHECK(canonical_text(again) == canonical_text(r.prepared.identity));
  CHECK(r.prepared.identity.entries.at("integrator") == "path");
  CHECK(r.prepared.identity.entries.at("accel") == "bvh");
}

TEST_CASE("session: a camera that does not exist is an InputError naming the file", "[session]") {
  LoadedScene loaded = default_scene();
  RenderSpec spec = small("whitted");
  spec.camera = "7";
  PrepareOptions o;
  o.scene_file = "default.gltf";
  CHECK_THROWS_AS(prepare_render(loaded, spec, o), InputError);
  spec.camera = "no such camera";
  CHECK_THROWS_WITH(prepare_render(loaded, spec, o),
                    Catch::Contains("default.gltf") && Catch::Contains("no camera named"));
}

TEST_CASE("session: the lens from the spec, focused by distance or by what a pixel shows", "[session][dof]") {
  // The camera at the origin looks down -z at a near quad (depth 3) on the left and a far one
  // (depth 6) on the right of the image.
  LoadedScene loaded;
  Scene& s = loaded.scene;
  const int mat = test::add_material(s, {1, 1, 1}, 0, 1);
  test::add_quad_z(s, -10, 0, -10, 10, -3, mat);
  test::add_quad_z(s, 0, 10, -10, 10, -6, mat);
  Camera cam;
  cam.name = "lens";
  cam.yfov = 2 * std::atan(0.5f);
  s.cameras.push_back(cam);
  PrepareOptions o;
  o.scene_file = "lens.gltf";
  RenderSpec spec = small("path");
  spec.aperture_radius = 0.1f;
  spec.focus_at = "4,8";
  PreparedRender p = prepare_render(loaded, spec, o);
  CHECK(p.camera.lens.radius == 0.1f);
  CHECK(p.camera.lens.focus_distance == Approx(3).epsilon(1e-5));
  CHECK(p.identity.entries.at("camera.lens").find("focus 3") != std::string::npos);
  finish_render(loaded, p);
  spec.focus_at = "20,8";
  p = prepare_render(loaded, spec, o);
  CHECK(p.camera.lens.focus_distance == Approx(6).epsilon(1e-5));
  finish_render(loaded, p);
  spec.focus_at.clear();
  spec.focus_distance = 4.5f;
  spec.aperture_blades = 5;
  spec.aperture_rotation = 90;
  p = prepare_render(loaded, spec, o);
  CHECK(p.camera.lens.focus_distance == 4.5f);
  CHECK(p.camera.lens.blades == 5);
  CHECK(p.camera.lens.rotation == Approx(kPi / 2));
  finish_render(loaded, p);
  // An f-number: focal length from the field of view on a 36 mm sensor across the width.
  spec.aperture_radius = 0;
  spec.fstop = 4;
  p = prepare_render(loaded, spec, o);
  const double focal_m = 0.018 / (0.5 * 24.0 / 16.0);
  CHECK(p.camera.lens.radius == Approx(focal_m / 8).epsilon(1e-5));
  finish_render(loaded, p);
  // The raster preview keeps its pinhole and says so.
  spec.integrator = "raster";
  p = prepare_render(loaded, spec, o);
  CHECK(p.camera.lens.radius == 0);
  REQUIRE(p.warnings.size() == 1);
  CHECK(p.warnings[0].find("ignores depth of field") != std::string::npos);
  finish_render(loaded, p);
  // An orthographic camera takes a radius, not an f-number.
  s.cameras[0].projection = Projection::Orthographic;
  spec.integrator = "whitted";
  CHECK_THROWS_WITH(prepare_render(loaded, spec, o), Catch::Contains("fstop needs a perspective camera"));
  spec.focus_at = "900,1";
  spec.fstop = 0;
  spec.aperture_radius = 0.1f;
  spec.focus_distance = 0;
  CHECK_THROWS_WITH(prepare_render(loaded, spec, o), Catch::Contains("outside the 24 x 16 image"));
}

TEST_CASE("session: with a lens the data AOVs see what the beauty's samples see", "[session][dof]") {
  // A quad at depth 2 fills the view; focused at 4 through a wide aperture, the depth of
  // each sample still reads 2 (a plane facing the camera), and the albedo is its colour.
  Session session;
  session.file = "plane.gltf";
  Scene& s = session.loaded.scene;
  const int mat = test::add_material(s, {0.25f, 0.5f, 0.75f}, 0, 1);
  test::add_quad_z(s, -10, 10, -10, 10, -2, mat);
  Camera cam;
  cam.yfov = 2 * std::atan(0.5f);
  s.cameras.push_back(cam);
  RenderSpec spec = small("whitted");
  spec.aperture_radius = 0.3f;
  spec.focus_distance = 4;
  spec.aovs = {"Z", "albedo"};
  const RenderResult r = render_scene(session, spec, 0);
  for (float z : r.layers.data.depth) CHECK(z == Approx(2).epsilon(1e-4));
  CHECK(r.layers.data.albedo[1] == Approx(0.5f));
}

namespace {

/// A 6 x 6 checkerboard of unlit quads at z = 0 before a grey one at z = -1.5.
LoadedScene checker_scene() {
  LoadedScene loaded;
  Scene& s = loaded.scene;
  const int dark = test::add_material(s, {0.1f, 0.2f, 0.1f}, 0, 1, true);
  const int light = test::add_material(s, {0.9f, 0.8f, 0.7f}, 0, 1, true);
  const int grey = test::add_material(s, {0.4f, 0.4f, 0.4f}, 0, 1, true);
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i)
      test::add_quad_z(s, -1.5f + 0.5f * float(i), -1.0f + 0.5f * float(i), -1.5f + 0.5f * float(j),
                       -1.0f + 0.5f * float(j), 0, (i + j) % 2 ? dark : light);
  test::add_quad_z(s, -4, 4, -4, 4, -1.5f, grey);
  return loaded;
}

/// An orbit turned by a 24-frame turntable, at frame 3 plus `frames`.
Camera turntable_camera(const Scene& scene, int width, int height, double frames) {
  CameraRig rig;
  rig.placement = CameraPlacement::Orbit;
  rig.azimuth = 0.1;
  rig.elevation = 0.2;
  rig.distance = 6;
  rig.turntable_frames = 24;
  rig.turntable_frame = 3;
  rig.turntable_phase = frames;
  return rig_camera(rig, nullptr, compute_bounds(scene), float(width) / float(height));
}

double rmse(const std::vector<float>& a, const std::vector<float>& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += double(a[i] - b[i]) * double(a[i] - b[i]);
  return std::sqrt(sum / double(a.size()));
}

}  // namespace

TEST_CASE("session: a turning camera blurs over the shutter as the mean of its stills", "[session][motion]") {
  LoadedScene loaded = checker_scene();
  RenderSpec spec = small("whitted");
  spec.width = 32;
  spec.height = 24;
  PrepareOptions o;
  o.scene_file = "default.gltf";
  o.camera_index = -1;
  double phase = 0;
  o.place = [&](const Scene& sc, int, int w, int h) { return turntable_camera(sc, w, h, phase); };
  o.turn = [](const Scene& sc, int, int w, int h, double frames) {
    return turntable_camera(sc, w, h, frames);
  };
  // Without motion blur the camera holds still.
  PreparedRender p = prepare_render(loaded, spec, o);
  CHECK(p.camera.motion.empty());
  CHECK(p.identity.entries.count("camera.motion") == 0);
  finish_render(loaded, p);
  // The shutter [0, 0.5] frames after the frame: the keys follow the turn (its arc, to well under
  // a thousandth of the distance).
  spec.motion_blur = true;
  spec.shutter = 0.5f;
  spec.shutter_offset = 0.25f;
  p = prepare_render(loaded, spec, o);
  REQUIRE(p.camera.motion.size() >= 3);
  CHECK(p.identity.entries.count("camera.motion") == 1);
  const float reach = length(p.camera.eye - compute_bounds(loaded.scene).center());
  for (double t : {0.0, 0.3, 0.5, 0.77, 1.0}) {
    const Camera want = turntable_camera(loaded.scene, 32, 24, 0.5 * t);
    const Affine3f got = interpolate_motion(p.camera.motion, float(t));
    const Vec3f eye{got.m[0][3], got.m[1][3], got.m[2][3]};
    const Vec3f w{got.m[0][2], got.m[1][2], got.m[2][2]};
    INFO("time " << t);
    CHECK(length(eye - want.eye) < 1e-4f * reach);
    CHECK(dot(w, want.w) > 1 - 1e-6f);
  }
  const Structure s = build_structure(loaded.scene, p.spec, false);
  spec.spp = 256;
  p = prepare_render(loaded, spec, o);
  const Film blurred = render_image(loaded.scene, s.accel.get(), p).film;
  finish_render(loaded, p);
  // The mean of 16 stills spread over the shutter, and the still at the frame itself.
  spec.motion_blur = false;
  spec.shutter_offset = 0;
  spec.shutter = 0.5f;
  spec.spp = 16;
  std::vector<float> mean(blurred.rgba.size(), 0.0f);
  constexpr int kStills = 16;
  for (int k = 0; k < kStills; ++k) {
    phase = 0.5 * (k + 0.5) / kStills;
    p = prepare_render(loaded, spec, o);
    const Film still = render_image(loaded.scene, s.accel.get(), p).film;
    finish_render(loaded, p);
    for (size_t i = 0; i < mean.size(); ++i) mean[i] += still.rgba[i] / kStills;
  }
  phase = 0;
  spec.spp = 64;
  p = prepare_render(loaded, spec, o);
  const Film frame = render_image(loaded.scene, s.accel.get(), p).film;
  finish_render(loaded, p);
  const double to_mean = rmse(blurred.rgba, mean), to_frame = rmse(blurred.rgba, frame.rgba);
  INFO("RMSE to the mean of stills " << to_mean << ", to the frame's still " << to_frame);
  CHECK(to_frame > 0.01);
  CHECK(to_mean < 0.2 * to_frame);
}

TEST_CASE("session: a turning camera's vector layer reprojects through its previous and next placements",
          "[session][vector]") {
  LoadedScene loaded = checker_scene();
  RenderSpec spec = small("whitted");
  spec.width = 32;
  spec.height = 24;
  spec.aovs = {"vector"};
  PrepareOptions o;
  o.scene_file = "default.gltf";
  o.camera_index = -1;
  o.place = [](const Scene& sc, int, int w, int h) { return turntable_camera(sc, w, h, 0); };
  o.turn = [](const Scene& sc, int, int w, int h, double frames) {
    return turntable_camera(sc, w, h, frames);
  };
  const PreparedRender p = prepare_render(loaded, spec, o);  // no time: the scene's static pose
  CHECK(p.warnings.empty());
  REQUIRE(p.motion);
  CHECK(p.motion->same_scene);
  CHECK(p.identity.entries.count("vector.cameras") == 1);
  const Structure s = build_structure(loaded.scene, p.spec, false);
  const RenderLayers layers = render_layers(loaded, s.accel.get(), p);
  REQUIRE(layers.vector.size() == size_t(32 * 24 * 4));
  const Camera before = turntable_camera(loaded.scene, 32, 24, -1),
               after = turntable_camera(loaded.scene, 32, 24, 1);
  CHECK(length(p.motion->previous_camera.eye - before.eye) < 1e-6f);
  CHECK(length(p.motion->next_camera.eye - after.eye) < 1e-6f);
  CHECK(length(p.camera.eye - turntable_camera(loaded.scene, 32, 24, 0).eye) < 1e-6f);
  int surface = 0, moving = 0;
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 32; ++x) {
      const float* v = &layers.vector[size_t(y * 32 + x) * 4];
      Hit hit;
      const Ray ray = generate_camera_ray(p.camera, 32, 24, x + 0.5f, y + 0.5f);
      if (!s.accel->intersect(ray, hit)) {
        for (int c = 0; c < 4; ++c) CHECK(v[c] == 0);
        continue;
      }
      ++surface;
      const Vec3f point = ray.org + ray.dir * hit.t;
      Vec2f was, will;
      REQUIRE(project_to_raster(before, 32, 24, point, was));
      REQUIRE(project_to_raster(after, 32, 24, point, will));
      INFO("pixel " << x << "," << y);
      // Raster rows run down, the layer's Y up.
      CHECK(v[0] == Approx(was.x - (x + 0.5f)).margin(0.01));
      CHECK(v[1] == Approx((y + 0.5f) - was.y).margin(0.01));
      CHECK(v[2] == Approx((x + 0.5f) - will.x).margin(0.01));
      CHECK(v[3] == Approx(will.y - (y + 0.5f)).margin(0.01));
      moving += std::fabs(v[0]) > 0.5f;
    }
  CHECK(surface > 100);
  CHECK(moving > 100);
}

}  // namespace penumbra
