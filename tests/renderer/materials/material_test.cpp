// Tests for renderer/materials/material: textures, texture transforms, UV sets, vertex colours,
// normal maps and Whitted's blended layers, with analytic answers.
#include "renderer/materials/material.h"

#include <catch2/catch.hpp>

#include "renderer/accel/factory.h"
#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/integrators/whitted.h"
#include "support/material_scenes.h"
#include "support/scene_builder.h"

using namespace penumbra;
using namespace penumbra::test;

TEST_CASE("material: base colour = factor x texel; KHR_texture_transform and TEXCOORD_1 pick texels",
          "[material][quick]") {
  Probe p;
  const int tex = add_quadrant_texture(p.scene);
  const int mat = add_material(p.scene, {0.5f, 1, 1}, 0, 1);
  p.scene.materials[size_t(mat)].base_color_tex.texture = tex;
  add_uv_quad(p.scene, 0, mat);
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
