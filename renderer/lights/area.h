// Emissive triangles and emissive analytic shapes as area lights for next-event estimation:
// every triangle of every instance whose material emits and every placed sphere, plane, disk,
// box or capsule whose material emits (pbrt-v4 12.2 "DiffuseAreaLight"), and the point and spot
// lights of a scene with many of them, chosen through a light
// BVH by their importance at the shading point (light_tree.h), or in proportion to an estimate
// of their power (pbrt-v4 12.6.2), or uniformly (LightSampler). Triangles
// are then sampled uniformly by area; a sphere placed by a similarity (rotation, uniform
// scale, translation) by the cone of directions it subtends from the shading point when that
// point is outside it (pbrt-v4 6.2.4); other shapes uniformly by object-space area, their
// world-space density divided by the placement's area scale at the point (exact under any
// scale or shear). Implicit (SDF) shapes are not sampled: they add their emission only when a
// path hits them, and their light then arrives by BSDF sampling alone.
#pragma once

// Power estimate: luminance(emissive factor x the emissive texture filtered over the
// triangle's UV footprint) x world area x (2 if double-sided), floored at 1% of the factor's
// so that no emitting triangle is unreachable by light sampling. The estimate only steers
// sampling: the integrator evaluates the true emission at the sampled point.
// One-sided emission: a single-sided (glTF doubleSided = false) material emits only from its
// front (counter-clockwise) side; double-sided materials emit from both.

#include <cstdint>
#include <vector>

#include "renderer/lights/light_tree.h"
#include "renderer/scene/scene.h"

namespace penumbra {

struct EmissiveTriangle {
  uint32_t instance = 0, prim = 0;
  float area = 0;      ///< world-space area at the frame's time
  WorldTriangle tri;   ///< world_triangle() of the triangle, kept so sampling does not rebuild it
  bool moves = false;  ///< its instance moves or its mesh deforms over the shutter: sampled
                       ///< where it is at each sample's time
};

struct EmissiveShape {
  uint32_t instance = 0;
  float area = 0;      ///< world-space area at the frame's time (estimated under shear: power only)
  bool moves = false;  ///< its instance moves over the shutter: sampled where it is at each sample's time
};

/// How sample_area_light() chooses among the lights.
enum class LightSampler : uint8_t {
  Tree,    ///< the light BVH (light_tree.h): by importance at the shading point (default)
  Power,   ///< in proportion to power, wherever the shading point is
  Uniform  ///< every light of non-zero power equally (for tests)
};

/// A scene with at most this many point and spot lights evaluates each of them at every
/// shading point (no variance); one with more samples them among the area lights.
inline constexpr size_t kEvaluatedPunctualLights = 8;

/// The lights: entry k < triangles.size() is triangles[k], entry triangles.size() + j is
/// shapes[j], entry triangles.size() + shapes.size() + j is the punctual light
/// scene.lights[punctual[j]]; cdf, pmf and the tree run over all entries.
struct AreaLights {
  std::vector<EmissiveTriangle> triangles;
  std::vector<EmissiveShape> shapes;
  std::vector<uint32_t> punctual;  ///< the point and spot lights chosen like the others, when the
                                   ///< scene has more than its evaluated limit; else empty
  std::vector<uint8_t> sampled;    ///< per scene light: 1 when it is an entry (chosen, not
                                   ///< evaluated at every point); empty when none is
  std::vector<float> cdf;          ///< entries + 1 values, cdf[0] = 0, back() = 1
  std::vector<float> pmf;          ///< selection probability of each entry by power
  std::vector<uint32_t> positive;  ///< the entries of non-zero power (LightSampler::Uniform)
  LightTree tree;                  ///< over the entries of non-zero power
  std::vector<int64_t> first;      ///< per instance: its entry (a mesh instance: the entry of its
                                   ///< triangle 0, all its triangles following), or -1 if it emits
                                   ///< nothing or is not sampled (an implicit shape)
};

/// Collects the scene's emissive triangles and analytic shapes, and its point and spot lights
/// when there are more than `evaluated_punctual` of them, their power table and their light
/// tree (each light's bounds: a triangle's box and normal, a flat shape's box and normal, a
/// closed shape's box with normals in every direction; a point light's position and every
/// direction, a spot's axis with its inner cone and the falloff to the outer one as pbrt-v4's
/// SpotLight::Bounds; a light that moves: its box over the shutter and every direction).
/// Powers: the emission's luminance times the area (twice for two sides), 4 x the luminance of
/// a point or spot light's colour x intensity (its flux over pi, the area lights' unit).
/// Allocates; call once per render.
AreaLights build_area_lights(const Scene& scene, size_t evaluated_punctual = kEvaluatedPunctualLights);

/// Where and how a light is chosen: the shading point, its geometric normal (zero: none) and
/// the sampler.
struct LightChoice {
  Vec3f p;
  Vec3f n;
  LightSampler sampler = LightSampler::Power;
};

/// The probability that sample_area_light(lights, scene, choice, ...) chooses entry `entry`.
float light_pmf(const AreaLights& lights, const LightChoice& choice, size_t entry);

/// Density (per unit world area) with which sample_area_light() picks a point on triangle
/// `prim` of instance `instance`, where the triangle is `tri` (the world triangle a ray hit at
/// its time): the light's pmf / the area of the triangle, or 0 if it is not a light.
float area_light_pdf(const AreaLights& lights, const LightChoice& choice, uint32_t instance, uint32_t prim,
                     const WorldTriangle& tri);

/// Density (per unit world area) with which sample_area_light() picks the point `p` (world) of
/// the shape placed by instance `instance` at ray time `time`: 0 if that instance is not a
/// sampled light. `p` is a point on the shape as intersected then.
float shape_light_pdf(const AreaLights& lights, const Scene& scene, const LightChoice& choice,
                      uint32_t instance, Vec3f p, float time);

struct AreaLightSample {
  uint32_t instance = 0, prim = 0;
  float u = 0, v = 0;  ///< barycentrics of the point (Hit convention); 0 on shapes
  Vec3f p;             ///< world point
  Vec3f ng;            ///< unit front-side geometric normal (outward on closed shapes)
  float pdf_area = 0;  ///< density per unit world area: pmf x the point's density on its light
  WorldTriangle tri;   ///< the light's world triangle at the sample's time (triangles only)
  bool shape = false;  ///< the light is a shape (instance places it), not a triangle
  int32_t light = -1;  ///< >= 0: the punctual light scene.lights[light] was chosen, with
                       ///< probability pdf_area; no point is sampled (the caller evaluates it)
};

/// Chooses a light as `choice` says with u1 and a point on it with u (a punctual light: see
/// AreaLightSample::light), where the light is at ray
/// time `time` (instance_at, world_triangle: a light that moves or deforms is sampled where
/// every structure intersects it then). False if there are no lights, none reaches the point,
/// or the chosen light is degenerate. Never allocates.
bool sample_area_light(const AreaLights& lights, const Scene& scene, const LightChoice& choice, float time,
                       float u1, Vec2f u, AreaLightSample& out);

}  // namespace penumbra
