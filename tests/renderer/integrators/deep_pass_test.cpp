// Tests for renderer/integrators/deep_pass: the deep samples of both integrators flatten to
// their beauty, stay the same for any thread count or tile size, carry the depth AOV's Z and
// the object ids, and merge each surface into one sample per pixel; Whitted's shadows switch.
#include "renderer/integrators/deep_pass.h"

#include <catch2/catch.hpp>
#include <cstring>
#include <set>

#include "renderer/integrators/aov.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {

/// Looking straight down -z (orthographic, x and y in [-2, 2]): a near red quad (node 4) over
/// x < 0 at z = 0, a far blue one (node 7) over 0 < x < 1 at z = -1, and a green Blend quad
/// (node 9, alpha 0.5) over y > 0.5 at z = 1, lit from above; nothing beyond x = 1.
Scene layered_scene() {
  Scene s;
  const int red = add_material(s, {0.8f, 0.1f, 0.1f}, 0, 1);
  const int blue = add_material(s, {0.1f, 0.2f, 0.9f}, 0, 1);
  const int green = add_material(s, {0.1f, 0.9f, 0.2f}, 0, 0.5f);
  s.materials[size_t(green)].alpha_mode = AlphaMode::Blend;
  s.materials[size_t(green)].alpha = 0.5f;
  s.instances[size_t(add_quad_z(s, -3, 0, -3, 3, 0, red))].node = 4;
  s.instances[size_t(add_quad_z(s, 0, 1, -3, 3, -1, blue))].node = 7;
  s.instances[size_t(add_quad_z(s, -3, 3, 0.5f, 3, 1, green))].node = 9;
  s.lights.push_back(point_light({0.3f, 0.2f, 4}, 30));
  return s;
}

Camera top_camera() {
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 1);
  cam.projection = Projection::Orthographic;
  cam.ymag = 2;
  return cam;
}

/// Checks that every pixel of `deep` flattens (flatten_deep, tested against its definition in
/// film/deep_test) to the film's RGBA within `eps` (relative to 1 + value).
void check_flattens_to(const DeepImage& deep, const Film& film, double eps) {
  REQUIRE(deep.counts.size() == size_t(film.width) * size_t(film.height));
  size_t total = 0;
  for (uint32_t n : deep.counts) total += n;
  CHECK(total == deep.samples.size());
  const Film flat = flatten_deep(deep);
  size_t worst_pixel = 0;
  double worst = 0;
  for (size_t i = 0; i < flat.rgba.size(); ++i) {
    const double err = std::abs(double(flat.rgba[i]) - film.rgba[i]) / (1 + std::abs(double(flat.rgba[i])));
    if (err > worst) {
      worst = err;
      worst_pixel = i / 4;
    }
  }
  INFO("worst pixel " << worst_pixel % size_t(film.width) << "," << worst_pixel / size_t(film.width));
  CHECK(worst <= eps);
}

}  // namespace

TEST_CASE("deep pass: Whitted's deep samples flatten to its beauty, edges and Blend layers included",
          "[deep_pass]") {
  const Scene s = layered_scene();
  const auto accel = make_scene_accelerator("embree", s);
  for (int spp : {1, 16}) {
    RenderConfig cfg = small_render_config(32, 32, spp);
    const Film film = render_whitted(s, *accel, top_camera(), cfg);
    const DeepResult deep =
        render_deep(s, *accel, nullptr, top_camera(), cfg, IntegratorType::Whitted, nullptr);
    REQUIRE_FALSE(deep.over_budget);
    check_flattens_to(deep.image, film, 1e-5);
    // With a coloured background, the escaped light is a sample of its own behind everything.
    cfg.whitted.background = {0.2f, 0.3f, 0.4f};
    const Film lit = render_whitted(s, *accel, top_camera(), cfg);
    const DeepResult bg =
        render_deep(s, *accel, nullptr, top_camera(), cfg, IntegratorType::Whitted, nullptr);
    check_flattens_to(bg.image, lit, 1e-5);
    CHECK(bg.image.samples.size() > deep.image.samples.size());
  }
}

TEST_CASE("deep pass: the path tracer's deep samples flatten to its beauty, adaptive counts included",
          "[deep_pass]") {
  const Scene s = layered_scene();
  const auto accel = make_scene_accelerator("embree", s);
  const AreaLights al = build_area_lights(s);
  const Environment env = make_constant_environment({0.1f, 0.1f, 0.2f});
  const PathLights lights{&al, &env};
  RenderConfig cfg = small_render_config(24, 24, 16);
  cfg.adaptive_threshold = 0.2f;
  cfg.adaptive_min_spp = 4;
  const PathImage img = render_path(s, *accel, lights, top_camera(), cfg);
  CHECK(*std::min_element(img.samples.begin(), img.samples.end()) <
        *std::max_element(img.samples.begin(), img.samples.end()));
  const DeepResult deep =
      render_deep(s, *accel, &lights, top_camera(), cfg, IntegratorType::Path, &img.samples);
  check_flattens_to(deep.image, img.film, 1e-5);
}

TEST_CASE("deep pass: the same samples for any thread count and tile size", "[deep_pass]") {
  const Scene s = layered_scene();
  const auto accel = make_scene_accelerator("embree", s);
  RenderConfig a = small_render_config(40, 24, 9, 4);
  a.threads = 1;
  RenderConfig b = small_render_config(40, 24, 9, 16);
  b.threads = 2;
  const DeepResult da = render_deep(s, *accel, nullptr, top_camera(), a, IntegratorType::Whitted, nullptr);
  const DeepResult db = render_deep(s, *accel, nullptr, top_camera(), b, IntegratorType::Whitted, nullptr);
  CHECK(da.image.counts == db.image.counts);
  REQUIRE(da.image.samples.size() == db.image.samples.size());
  CHECK(std::memcmp(da.image.samples.data(), db.image.samples.data(),
                    da.image.samples.size() * sizeof(DeepSample)) == 0);
}

TEST_CASE("deep pass: Z is the depth AOV's, ids are the object ids, one sample per surface", "[deep_pass]") {
  const Scene s = layered_scene();
  const auto accel = make_scene_accelerator("embree", s);
  const RenderConfig cfg = small_render_config(32, 32, 16);
  const DeepResult deep =
      render_deep(s, *accel, nullptr, top_camera(), cfg, IntegratorType::Whitted, nullptr);
  const DataAovs aov = render_data_aovs(s, *accel, top_camera(), cfg, IntegratorType::Whitted);
  size_t first = 0, single = 0;
  for (size_t i = 0; i < deep.image.counts.size(); ++i) {
    const uint32_t n = deep.image.counts[i];
    std::set<float> ids;
    for (size_t k = first; k < first + n; ++k) ids.insert(deep.image.samples[k].id);
    CHECK(ids.size() == n);  // each surface merged into one sample
    CHECK(n <= 3);           // at most the two quads' edge and the Blend layer
    for (float id : ids) CHECK((id == 5 || id == 8 || id == 10));
    if (n == 1) {
      ++single;
      CHECK(deep.image.samples[first].z == aov.depth[i]);
      CHECK(deep.image.samples[first].zback == aov.depth[i]);
      CHECK(deep.image.samples[first].id == aov.object_id[i]);
    }
    first += n;
  }
  CHECK(single > 100);
}

TEST_CASE("deep pass: over the memory budget the pass stops and says so", "[deep_pass]") {
  const Scene s = layered_scene();
  const auto accel = make_scene_accelerator("embree", s);
  const RenderConfig cfg = small_render_config(32, 32, 4);
  DeepConfig tight;
  tight.max_bytes = 1000;
  const DeepResult r =
      render_deep(s, *accel, nullptr, top_camera(), cfg, IntegratorType::Whitted, nullptr, tight);
  CHECK(r.over_budget);
  CHECK(r.image.samples.empty());
  CHECK(r.samples_found > 0);
}

TEST_CASE("whitted: without shadows no object darkens another", "[deep_pass]") {
  // A floor under a light, and a blocker between them that the camera does not see.
  Scene s;
  const int grey = add_lambert(s, {0.5f, 0.5f, 0.5f});
  add_quad_z(s, -2, 2, -2, 2, 0, grey);
  s.lights.push_back(point_light({0, 0, 4}, 20));
  const Scene open = s;
  add_quad_z(s, -1, 1, -1, 1, 2, grey, true);  // facing down, behind the camera
  Camera cam = look_at({0, 0, 1.5f}, {0, 0, 0}, {0, 1, 0}, 1);
  RenderConfig cfg = small_render_config(16, 16, 1);
  const auto a_open = make_scene_accelerator("embree", open);
  const auto a_blocked = make_scene_accelerator("embree", s);
  const Film lit = render_whitted(open, *a_open, cam, cfg);
  const Film shadowed = render_whitted(s, *a_blocked, cam, cfg);
  cfg.whitted.shadows = false;
  const Film unshadowed = render_whitted(s, *a_blocked, cam, cfg);
  const size_t centre = (8 * 16 + 8) * 4;
  CHECK(shadowed.rgba[centre] < 0.5f * lit.rgba[centre]);
  CHECK(unshadowed.rgba == lit.rgba);
}
