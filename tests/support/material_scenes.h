// Small material scenes for material and visibility tests: a 2x2 quadrant texture, a UV quad
// and a probe that shades the first visible surface straight down at (x, y).
#pragma once

#include <catch2/catch.hpp>
#include <memory>

#include "renderer/integrators/scene_accel.h"
#include "renderer/integrators/visibility.h"
#include "renderer/materials/material.h"
#include "support/scene_builder.h"

namespace penumbra::test {

inline constexpr float kEps = 2e-4f;

// 2x2 nearest-filtered texture: top-left red, top-right green, bottom-left blue, bottom-right
// white with alpha 0.25.
inline int add_quadrant_texture(Scene& s) {
  const std::vector<float> px = {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 0.25f};
  TextureSampler smp;
  smp.mag = TextureFilter::Nearest;
  smp.min = TextureFilter::Nearest;
  smp.mipmaps = false;
  s.textures.push_back(make_texture("quadrants", 2, 2, px, smp));
  return int(s.textures.size()) - 1;
}

// A 2x2 quad at height z facing +z with uv = ((x+1)/2, (1-y)/2) on both UV sets, the second
// mirrored in u.
inline int add_uv_quad(Scene& s, float z, int material, bool flip = false) {
  const int id = add_quad_z(s, -1, 1, -1, 1, z, material, flip);
  Mesh& m = s.meshes[size_t(id)];
  for (Vec3f p : m.positions) {
    m.uvs.push_back({(p.x + 1) / 2, (1 - p.y) / 2});
    m.uvs1.push_back({1 - (p.x + 1) / 2, (1 - p.y) / 2});
  }
  return id;
}

struct Probe {
  Scene scene;
  std::unique_ptr<Accelerator> accel;
  void build() { accel = make_scene_accelerator("embree", scene); }
  // Material at the first visible surface straight down at (x, y).
  MaterialPoint at(float x, float y, Hit* out = nullptr) {
    Ray r;
    r.org = {x, y, 10};
    r.dir = {0, 0, -1};
    Hit h;
    REQUIRE(intersect_visible(scene, *accel, r, h, true));
    if (out) *out = h;
    return eval_material(scene, make_interaction(scene, r, h));
  }
};

}  // namespace penumbra::test
