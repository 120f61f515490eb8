// Emissive triangles as area lights for next-event estimation: every triangle of every
// instance whose material emits, picked with probability proportional to an estimate of its
// power and then sampled uniformly by area (pbrt-v4 12.2 "DiffuseAreaLight", with a power
// light sampler, 12.6.2).
#pragma once

// Power estimate: luminance(emissive factor x the emissive texture filtered over the
// triangle's UV footprint) x world area x (2 if double-sided), floored at 1% of the factor's
// so that no emitting triangle is unreachable by light sampling. The estimate only steers
// sampling: the integrator evaluates the true emission at the sampled point.
// One-sided emission: a single-sided (glTF doubleSided = false) material emits only from its
// front (counter-clockwise) side; double-sided materials emit from both.

#include <cstdint>
#include <vector>

#include "renderer/scene/scene.h"

namespace penumbra {

struct EmissiveTriangle {
  uint32_t instance = 0, prim = 0;
  float area = 0;      ///< world-space area at the frame's time
  WorldTriangle tri;   ///< world_triangle() of the triangle, kept so sampling does not rebuild it
  bool moves = false;  ///< its instance moves or its mesh deforms over the shutter: sampled
                       ///< where it is at each sample's time
};

struct AreaLights {
  std::vector<EmissiveTriangle> triangles;
  std::vector<float> cdf;      ///< triangles.size() + 1 entries, cdf[0] = 0, back() = 1
  std::vector<float> pmf;      ///< selection probability of each triangle
  std::vector<int64_t> first;  ///< per instance: index of its triangle 0, or -1 if it emits
                               ///< nothing (an emitting instance lists all its triangles)
};

/// Collects the scene's emissive triangles (emissive shapes are not sampled: they add their
/// emission when a path hits them). Allocates; call once per render.
AreaLights build_area_lights(const Scene& scene);

/// Density (per unit world area) with which sample_area_light() picks a point on triangle
/// `prim` of instance `instance` at the frame's time: pmf / area, or 0 if it is not a light.
float area_light_pdf(const AreaLights& lights, uint32_t instance, uint32_t prim);
/// The same density at the time where the triangle is `tri` (the world triangle a ray hit at
/// its time): pmf / area of `tri` for a light that moves or deforms, else as above.
float area_light_pdf(const AreaLights& lights, uint32_t instance, uint32_t prim, const WorldTriangle& tri);

struct AreaLightSample {
  uint32_t instance = 0, prim = 0;
  float u = 0, v = 0;  ///< barycentrics of the point (Hit convention)
  Vec3f p;             ///< world point
  Vec3f ng;            ///< unit front-side geometric normal
  float pdf_area = 0;  ///< pmf / area
  WorldTriangle tri;   ///< the light's world triangle at the sample's time
};

/// Picks a triangle by power with u1 and a uniform point on it with u, where the triangle is
/// at ray time `time` (instance_at, world_triangle: a light that moves or deforms is sampled
/// where every structure intersects it then). False if there are no lights (or the chosen
/// triangle is degenerate). Never allocates.
bool sample_area_light(const AreaLights& lights, const Scene& scene, float time, float u1, Vec2f u,
                       AreaLightSample& out);

}  // namespace penumbra
