// Tests for renderer/materials/material: textures, texture transforms, UV sets, vertex colours,
// normal maps, Whitted's blended layers, and procedural textures (composition with the image
// textures, object / world / UV spaces, bump from the analytic gradient, the footprint filter,
// both integrators), with analytic answers.
#include "renderer/materials/material.h"

#include <catch2/catch.hpp>
#include <cmath>

#include "renderer/accel/factory.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/integrators/whitted.h"
#include "renderer/lights/area.h"
#include "renderer/lights/environment.h"
#include "support/material_scenes.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

namespace {
/// The quadrant texture and a material of base colour (0.5, 1, 1) x that texture on a unit quad.
struct QuadrantQuad {
  int tex, mat;
};
QuadrantQuad add_quadrant_quad(Scene& s, float metallic, float roughness) {
  const int tex = add_quadrant_texture(s);
  const int mat = add_material(s, {0.5f, 1, 1}, metallic, roughness);
  s.materials[size_t(mat)].base_color_tex.texture = tex;
  add_uv_quad(s, 0, mat);
  return {tex, mat};
}
}  // namespace

TEST_CASE("material: base colour = factor x texel; KHR_texture_transform and TEXCOORD_1 pick texels",
          "[material][quick]") {
  Probe p;
  const auto [tex, mat] = add_quadrant_quad(p.scene, 0, 1);
  p.build();
  MaterialPoint m = p.at(-0.5f, 0.5f);  // top-left of the quad = top-left texel (red)
  CHECK(m.base_color.x == Approx(0.5).margin(kEps));
  CHECK(m.base_color.y == Approx(0).margin(kEps));
  m = p.at(0.5f, -0.5f);  // bottom-right: white
  CHECK(m.base_color.y == Approx(1).margin(kEps));
  CHECK(m.alpha == 1);  // Opaque ignores the texture's alpha

  // Offset by half the texture in u: the top-left of the quad now shows the top-right texel.
  auto& ref = p.scene.materials[size_t(mat)].base_color_tex;
  ref.m[0][2] = 0.5f;
  CHECK(p.at(-0.5f, 0.5f).base_color.y == Approx(1).margin(kEps));  // green
  // Rotation by 90 degrees (glTF: uv' = R uv with R = [c s; -s c]) maps (u, v) to (v, -u):
  // the point uv = (0.25, 0.75) (bottom-left) reads uv' = (0.75, -0.25) -> wraps to (0.75, 0.75).
  ref.m[0][0] = 0;
  ref.m[0][1] = 1;
  ref.m[0][2] = 0;
  ref.m[1][0] = -1;
  ref.m[1][1] = 0;
  ref.m[1][2] = 0;
  m = p.at(-0.5f, -0.5f);
  CHECK(m.base_color.x == Approx(0.5).margin(kEps));  // bottom-right texel: white x factor
  CHECK(m.base_color.y == Approx(1).margin(kEps));
  // TEXCOORD_1 (mirrored in u): top-left of the quad reads the top-right texel.
  ref = TextureRef{tex, 1};
  CHECK(p.at(-0.5f, 0.5f).base_color.y == Approx(1).margin(kEps));
}

TEST_CASE("material: COLOR_0 multiplies base colour and alpha; metallic-roughness reads B and G",
          "[material][quick]") {
  Probe p;
  const int mat = add_material(p.scene, {0.5f, 0.5f, 0.5f}, 0.8f, 0.6f);
  const int id = add_uv_quad(p.scene, 0, mat);
  for ([[maybe_unused]] auto& c : p.scene.meshes[size_t(id)].positions)
    p.scene.meshes[size_t(id)].colors.push_back({1, 0.5f, 0.25f, 0.5f});
  std::vector<float> mr = {0, 0.5f, 0.25f, 1};  // 1x1: G = roughness 0.5, B = metallic 0.25
  p.scene.textures.push_back(make_texture("mr", 1, 1, mr, {}));
  p.scene.materials[size_t(mat)].metallic_roughness_tex.texture = 0;
  p.scene.materials[size_t(mat)].alpha_mode = AlphaMode::Blend;
  p.build();
  const MaterialPoint m = p.at(0.1f, 0.2f);
  CHECK(m.base_color.x == Approx(0.5).margin(kEps));
  CHECK(m.base_color.y == Approx(0.25).margin(kEps));
  CHECK(m.base_color.z == Approx(0.125).margin(kEps));
  CHECK(m.alpha == Approx(0.5).margin(kEps));
  CHECK(m.metallic == Approx(0.8 * 0.25).margin(kEps));
  CHECK(m.roughness == Approx(0.6 * 0.5).margin(kEps));
}

TEST_CASE("material: a normal map tilts the shading normal in the tangent frame", "[material][quick]") {
  Probe p;
  const int mat = add_material(p.scene, {1, 1, 1}, 0, 1);
  const int id = add_uv_quad(p.scene, 0, mat);
  Mesh& mesh = p.scene.meshes[size_t(id)];
  mesh.tangents = compute_tangents(mesh.positions, mesh.normals, mesh.uvs, mesh.indices);
  // uv = ((x+1)/2, (1-y)/2): +u is +x; +v is -y, so the bitangent (map +Y) is +y and w = +1.
  CHECK(mesh.tangents[0].x == Approx(1));
  CHECK(mesh.tangents[0].w == 1);
  const float theta = 0.5f;
  for (float sx : {1.0f, 0.0f}) {
    // A map encoding (sin t, 0, cos t) tilts towards +x; (0, sin t, cos t) towards +y.
    const float nx = sx * std::sin(theta), ny = (1 - sx) * std::sin(theta), nz = std::cos(theta);
    p.scene.textures = {
        make_texture("n", 1, 1, {nx * 0.5f + 0.5f, ny * 0.5f + 0.5f, nz * 0.5f + 0.5f, 1}, {})};
    p.scene.materials[size_t(mat)].normal_tex.texture = 0;
    p.build();
    const MaterialPoint m = p.at(0.3f, 0.3f);
    CHECK(m.ns.x == Approx(nx).margin(1e-3));
    CHECK(m.ns.y == Approx(ny).margin(1e-3));
    CHECK(m.ns.z == Approx(nz).margin(1e-3));
  }
  // normal_scale 0 flattens the map to the interpolated normal.
  p.scene.materials[size_t(mat)].normal_scale = 0;
  CHECK(p.at(0.3f, 0.3f).ns.z == Approx(1).margin(1e-4));
  // A u-mirrored UV layout flips the tangent, and w keeps the bitangent on +y.
  for (auto& uv : mesh.uvs) uv.x = 1 - uv.x;
  mesh.tangents = compute_tangents(mesh.positions, mesh.normals, mesh.uvs, mesh.indices);
  CHECK(mesh.tangents[0].x == Approx(-1));
  CHECK(mesh.tangents[0].w == -1);  // cross(n, t) = -y, so w = -1 keeps the bitangent on +y
  p.scene.materials[size_t(mat)].normal_scale = 1;
  p.build();
  CHECK(p.at(0.3f, 0.3f).ns.y == Approx(std::sin(theta)).margin(1e-3));  // map +Y still +y
}

TEST_CASE("material: Whitted composites Blend layers front to back (a c + (1 - a) behind)",
          "[material][whitted][quick]") {
  Scene s;
  const int front = add_material(s, {1, 0, 0}, 0, 1, true);  // unlit: radiance = base colour
  s.materials[size_t(front)].alpha = 0.25f;
  s.materials[size_t(front)].alpha_mode = AlphaMode::Blend;
  const int back = add_material(s, {0, 0, 1}, 0, 1, true);
  add_quad_z(s, -1, 1, -1, 1, 1, front);
  add_quad_z(s, -1, 1, -1, 1, 0, back);
  auto accel = make_scene_accelerator("embree", s);
  WhittedConfig cfg;
  cfg.background = {0, 1, 0};
  Ray r;
  r.org = {0.2f, 0.1f, 5};
  r.dir = {0, 0, -1};
  float coverage = 0;
  RayCounts counts;
  Vec3f L = whitted_radiance(s, *accel, cfg, r, RayDifferential{}, coverage, counts);
  CHECK(L.x == Approx(0.25));
  CHECK(L.z == Approx(0.75));
  CHECK(coverage == Approx(1));
  // Without the back quad, the background shows through and coverage is the layer's alpha.
  s.meshes.pop_back();
  s.instances.pop_back();
  accel = make_scene_accelerator("embree", s);
  L = whitted_radiance(s, *accel, cfg, r, RayDifferential{}, coverage, counts);
  CHECK(L.y == Approx(0.75));
  CHECK(coverage == Approx(0.25));
}

namespace {

// A procedural texture of `kind` in `space` whose ramp is black at t = 0 and white at t = 1.
ProceduralTexture gray_ramp(PatternKind kind, ProceduralSpace space, float scale = 1) {
  ProceduralTexture t;
  t.kind = kind;
  t.space = space;
  t.mapping = procedural_mapping({}, {}, {scale, scale, scale});
  t.table = make_perlin_table(t.seed);
  t.drives_base_color = true;
  t.base_color_compose = Compose::Replace;
  return t;
}

// Sine bands along X of `periods` per unit: t = 0.5 + 0.5 sin(2 pi periods x).
ProceduralTexture sine_bands(ProceduralSpace space, float periods) {
  return gray_ramp(PatternKind::Wave, space, periods);
}

int attach(Scene& s, int material, ProceduralTexture t) {
  s.procedurals.push_back(std::move(t));
  s.materials[size_t(material)].procedural = int(s.procedurals.size()) - 1;
  return int(s.procedurals.size()) - 1;
}

float sine_band(float x, float periods) {
  return 0.5f + 0.5f * std::sin(2 * kPi * periods * x);
}

}  // namespace

TEST_CASE("material: a procedural texture multiplies or replaces factor x image texture",
          "[material][procedural][quick]") {
  Probe p;
  const int mat = add_quadrant_quad(p.scene, 0.8f, 0.6f).mat;
  Material& m = p.scene.materials[size_t(mat)];
  m.emissive = {1, 0.5f, 0.25f};
  // A one-stop ramp and flat ranges: every output is a constant whatever the pattern gives.
  ProceduralTexture t = gray_ramp(PatternKind::Noise, ProceduralSpace::World, 3);
  t.base_color.stops = {{0.5f, {0.2f, 0.4f, 0.8f}}};
  t.base_color_compose = Compose::Multiply;
  t.roughness = {true, 0.5f, 0.5f, Compose::Multiply};
  t.metallic = {true, 0.25f, 0.25f, Compose::Replace};
  t.emission_strength = {true, 4, 4, Compose::Multiply};
  const int id = attach(p.scene, mat, t);
  p.build();
  MaterialPoint mp = p.at(0.5f, -0.5f);  // bottom-right texel: white
  CHECK(mp.base_color.x == Approx(0.5f * 0.2f).margin(kEps));
  CHECK(mp.base_color.y == Approx(0.4f).margin(kEps));
  CHECK(mp.base_color.z == Approx(0.8f).margin(kEps));
  CHECK(mp.roughness == Approx(0.6f * 0.5f));
  CHECK(mp.metallic == Approx(0.25f));
  CHECK(mp.emissive.x == Approx(4));
  CHECK(mp.emissive.z == Approx(1));
  mp = p.at(-0.5f, 0.5f);  // top-left texel: red, multiplied
  CHECK(mp.base_color.y == Approx(0).margin(kEps));
  // Replace ignores the factor and the texture.
  ProceduralTexture& r = p.scene.procedurals[size_t(id)];
  r.base_color_compose = Compose::Replace;
  r.roughness.compose = Compose::Replace;
  mp = p.at(-0.5f, 0.5f);
  CHECK(mp.base_color.x == Approx(0.2f));
  CHECK(mp.base_color.y == Approx(0.4f));
  CHECK(mp.roughness == Approx(0.5f));
}

TEST_CASE("material: procedural colours follow the pattern in world, object and UV space",
          "[material][procedural][quick]") {
  const float periods = 0.7f;
  for (ProceduralSpace space : {ProceduralSpace::World, ProceduralSpace::Object, ProceduralSpace::Uv}) {
    Probe p;
    const int mat = add_material(p.scene, {1, 1, 1}, 0, 1);
    const int quad = add_uv_quad(p.scene, 0, mat);
    // The quad's instance moves it by +3 in x: object space sees x - 3, UV space u = (x - 3 + 1) / 2.
    p.scene.instances[size_t(quad)] = make_instance(quad, translation({3, 0, 0}));
    attach(p.scene, mat, sine_bands(space, periods));
    p.build();
    for (float x : {2.3f, 2.8f, 3.1f, 3.6f}) {
      const float obj = x - 3;
      const float coord = space == ProceduralSpace::World    ? x
                          : space == ProceduralSpace::Object ? obj
                                                             : (obj + 1) / 2;
      INFO("space " << int(space) << " x " << x);
      CHECK(p.at(x, 0.2f).base_color.x == Approx(sine_band(coord, periods)).margin(1e-4));
    }
  }
}

TEST_CASE("material: a procedural bump tilts the normal by the pattern's gradient",
          "[material][procedural][quick]") {
  // Sine bands t = 0.5 + 0.5 sin(2 pi k x) of height h: the displaced plane z = h t(x) has normal
  // (-h dt/dx, 0, 1) normalised, dt/dx = pi k cos(2 pi k x); in UV space u = (x + 1) / 2 has
  // du/dx = 1/2 and t = 0.5 + 0.5 sin(2 pi k u).
  const float k = 0.8f, h = 0.1f;
  for (ProceduralSpace space : {ProceduralSpace::World, ProceduralSpace::Uv}) {
    for (bool flip : {false, true}) {
      Probe p;
      const int mat = add_material(p.scene, {1, 1, 1}, 0, 1);
      add_uv_quad(p.scene, 0, mat, flip);
      ProceduralTexture t = sine_bands(space, k);
      t.bump_height = h;
      attach(p.scene, mat, t);
      p.build();
      for (float x : {-0.7f, -0.2f, 0.35f, 0.9f}) {
        const float u = (x + 1) / 2;
        const float slope = space == ProceduralSpace::World ? kPi * k * std::cos(2 * kPi * k * x)
                                                            : kPi * k * std::cos(2 * kPi * k * u) * 0.5f;
        // A quad facing down is seen from its back: its bump goes away from the viewer (z = -h t),
        // whose normal towards the viewer is (+h dt/dx, 0, 1).
        const Vec3f expected = normalize(Vec3f{(flip ? 1.0f : -1.0f) * h * slope, 0, 1});
        INFO("space " << int(space) << " flip " << flip << " x " << x);
        check_vec(p.at(x, 0.3f).ns, expected, 1e-4f);
      }
    }
  }
}

TEST_CASE("material: a bump on a shape stays in its tangent plane and follows the gradient",
          "[material][procedural][shapes][quick]") {
  // World-space sine bands along X on a sphere: at the top (normal +y) the surface gradient is
  // (dt/dx, 0, 0) and the bumped normal tilts against it.
  Probe p;
  const int mat = add_material(p.scene, {1, 1, 1}, 0, 1);
  add_shape(p.scene, sphere_shape(1), translation({0, 0, 0}), mat);
  const float k = 0.3f, h = 0.2f;
  ProceduralTexture t = sine_bands(ProceduralSpace::World, k);
  t.bump_height = h;
  attach(p.scene, mat, t);
  p.build();
  Ray r;
  r.org = {0.25f, 10, 0};
  r.dir = {0, -1, 0};
  Hit hit;
  REQUIRE(intersect_visible(p.scene, *p.accel, r, hit, true));
  const SurfaceInteraction si = make_interaction(p.scene, r, hit);
  const MaterialPoint mp = eval_material(p.scene, si);
  Vec3f g{kPi * k * std::cos(2 * kPi * k * si.p.x), 0, 0};
  g = g - si.ng * dot(g, si.ng);
  check_vec(mp.ns, normalize(si.ns - g * h), 1e-4f);
}

TEST_CASE("material: the footprint filter lowers the pixel variance of a far-away noise plane",
          "[material][procedural][quick]") {
  // A ground plane of fine unlit fBm seen at a grazing angle at 1 sample per pixel: without the
  // filter far pixels alias to the full noise variance; with it they approach the mean.
  Scene s;
  const int mat = add_material(s, {1, 1, 1}, 0, 1, true);
  add_quad_z(s, -400, 400, -50, 2000, 0, mat);
  ProceduralTexture t = gray_ramp(PatternKind::Noise, ProceduralSpace::World, 4);
  t.fractal.detail = 6;
  const int id = attach(s, mat, t);
  const auto accel = make_scene_accelerator("embree", s);
  const Camera cam = look_at({0, -1, 1.5f}, {0, 60, 0}, {0, 0, 1}, 0.5f);
  RenderConfig cfg = small_render_config(48, 32, 1);
  const auto variance_of_far_rows = [&] {
    const Film f = render_whitted(s, *accel, cam, cfg);
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int y = 0; y < f.height; ++y)  // the far part of the plane: rows near the horizon
      for (int x = 0; x < f.width; ++x) {
        const float* px = f.pixel(x, y);
        const Vec3f dir = generate_camera_ray(cam, f.width, f.height, float(x) + 0.5f, float(y) + 0.5f).dir;
        if (px[3] < 1 || -dir.z / length(dir) > 0.05f) continue;  // the sky, or nearer than ~30 units
        const double v = px[0];
        sum += v;
        sum2 += v * v;
        ++n;
      }
    REQUIRE(n > 100);
    const double mean = sum / n;
    return sum2 / n - mean * mean;
  };
  s.procedurals[size_t(id)].filter = false;
  const double aliased = variance_of_far_rows();
  s.procedurals[size_t(id)].filter = true;
  const double filtered = variance_of_far_rows();
  INFO("variance unfiltered " << aliased << " filtered " << filtered);
  CHECK(aliased > 1e-3);
  CHECK(filtered < 0.25 * aliased);
}

TEST_CASE("material: both integrators and the albedo AOV see the procedural colour",
          "[material][procedural][whitted][path]") {
  // A procedural texture whose one-stop ramp replaces the base colour renders exactly as a plain
  // material of that colour, in both integrators and in the albedo AOV.
  const Vec3f color{0.7f, 0.3f, 0.1f};
  auto scene_with = [&](bool procedural) {
    Scene s;
    const int mat = add_lambert(s, procedural ? Vec3f{1, 1, 1} : color);
    add_quad_z(s, -2, 2, -2, 2, 0, mat);
    add_sphere(s, {0, 0, 0.6f}, 0.5f, 3, mat);
    s.lights.push_back(point_light({1, -1, 3}, 20));
    if (procedural) {
      ProceduralTexture t = gray_ramp(PatternKind::Voronoi, ProceduralSpace::Object, 5);
      t.base_color.stops = {{0.3f, color}};
      attach(s, mat, t);
    }
    return s;
  };
  const Scene plain = scene_with(false), proc = scene_with(true);
  const Camera cam = look_at({0, -3, 3}, {0, 0, 0.3f}, {0, 0, 1}, 0.7f);
  const RenderConfig cfg = small_render_config(16, 12, 4);
  const auto a_plain = make_scene_accelerator("embree", plain),
             a_proc = make_scene_accelerator("embree", proc);
  const Film w0 = render_whitted(plain, *a_plain, cam, cfg), w1 = render_whitted(proc, *a_proc, cam, cfg);
  const AreaLights l0 = build_area_lights(plain), l1 = build_area_lights(proc);
  const Environment env = make_constant_environment({0.2f, 0.2f, 0.2f});
  const PathImage p0 = render_path(plain, *a_plain, PathLights{&l0, &env}, cam, cfg);
  const PathImage p1 = render_path(proc, *a_proc, PathLights{&l1, &env}, cam, cfg);
  double lit = 0;
  for (size_t i = 0; i < w0.rgba.size(); ++i) {
    CHECK(w1.rgba[i] == Approx(w0.rgba[i]).margin(1e-5));
    CHECK(p1.film.rgba[i] == Approx(p0.film.rgba[i]).margin(1e-5));
    lit += w0.rgba[i];
  }
  CHECK(lit > 1);
  const DataAovs d = render_data_aovs(proc, *a_proc, cam, cfg, IntegratorType::Path);
  const size_t centre = size_t(6 * 16 + 8) * 3;
  CHECK(d.albedo[centre] == Approx(color.x));
  CHECK(d.albedo[centre + 2] == Approx(color.z));
}

TEST_CASE(
    "material: eval_emission equals eval_material's emissive x alpha, with and without an emissive texture",
    "[material][quick]") {
  // Texels (RGBA): top-left red, top-right green, bottom-left blue (alpha 1), bottom-right white
  // with alpha 0.25. Emissive factor (2, 1, 0.5).
  const float xs[] = {-0.5f, 0.5f, -0.5f, 0.5f}, ys[] = {0.5f, 0.5f, -0.5f, -0.5f};
  for (const bool textured : {false, true}) {
    for (const AlphaMode mode : {AlphaMode::Opaque, AlphaMode::Mask, AlphaMode::Blend}) {
      Probe p;
      const QuadrantQuad q = add_quadrant_quad(p.scene, 0, 1);
      Material& m = p.scene.materials[size_t(q.mat)];
      m.emissive = {2, 1, 0.5f};
      if (textured) m.emissive_tex.texture = q.tex;
      m.alpha_mode = mode;
      p.build();
      for (int k = 0; k < 4; ++k) {
        Ray r;
        r.org = {xs[k], ys[k], 10};
        r.dir = {0, 0, -1};
        Hit h;
        REQUIRE(p.accel->intersect(r, h));
        const SurfaceInteraction si = make_interaction(p.scene, r, h);
        const MaterialPoint mp = eval_material(p.scene, si);
        const Vec3f e = eval_emission(p.scene, si);
        INFO("textured " << textured << " mode " << int(mode) << " point " << k);
        CHECK(e.x == Approx(mp.emissive.x * mp.alpha).margin(1e-7));
        CHECK(e.y == Approx(mp.emissive.y * mp.alpha).margin(1e-7));
        CHECK(e.z == Approx(mp.emissive.z * mp.alpha).margin(1e-7));
      }
      // The bottom-right texel (white, alpha 0.25): emission 2 x 1 x coverage.
      Ray r;
      r.org = {0.5f, -0.5f, 10};
      r.dir = {0, 0, -1};
      Hit h;
      REQUIRE(p.accel->intersect(r, h));
      const float cover = mode == AlphaMode::Opaque ? 1.0f : mode == AlphaMode::Blend ? 0.25f : 0.0f;
      CHECK(eval_emission(p.scene, make_interaction(p.scene, r, h)).x == Approx(2 * cover).margin(kEps));
    }
  }
}
