// Area lights: the emissive triangle and shape table, power-proportional selection, uniform
// sampling of triangles, cone or area sampling of shapes.
#include "renderer/lights/area.h"

#include <algorithm>
#include <cmath>

#include "renderer/materials/material.h"
#include "renderer/scene/interaction.h"
#include "renderer/shapes/shape_sampling.h"

namespace penumbra {

namespace {
float triangle_area(const WorldTriangle& tri) {
  const float area = 0.5f * length(cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]));
  return std::isfinite(area) ? area : 0.0f;
}

// Luminance of the emission averaged over the triangle: the material evaluated at the
// centroid with the triangle's UV edges as the footprint (so the texture lookup reads the MIP
// level where the triangle is about one texel).
float emission_estimate(const Scene& scene, uint32_t instance, uint32_t prim, const WorldTriangle& tri,
                        const Material& mat) {
  const float factor = luminance(mat.emissive);
  if (mat.emissive_tex.texture < 0) return factor;
  const Vec3f c = (tri.p[0] + tri.p[1] + tri.p[2]) / 3.0f;
  Ray ray;
  ray.org = c + tri.ng;
  ray.dir = -tri.ng;
  Hit hit;
  hit.t = 1;
  hit.u = hit.v = 1.0f / 3.0f;
  hit.geom_id = instance;
  hit.prim_id = prim;
  SurfaceInteraction si = make_interaction(scene, ray, hit);
  const Mesh& mesh = scene.meshes[size_t(scene.instances[instance].mesh)];
  for (int set = 0; set < 2; ++set) {
    const auto& uvs = set == 0 ? mesh.uvs : mesh.uvs1;
    if (uvs.empty()) continue;
    const Vec2f a = uvs[tri.index[0]], b = uvs[tri.index[1]], d = uvs[tri.index[2]];
    si.duvdx[set] = {b.x - a.x, b.y - a.y};
    si.duvdy[set] = {d.x - a.x, d.y - a.y};
  }
  const float estimate = luminance(eval_material(scene, si).emissive);
  return std::isfinite(estimate) ? std::max(estimate, 0.01f * factor) : factor;
}
}  // namespace

namespace {

// World area of a shape under its placement: exact for similarities, else the object area
// times the mean area scale over the three axis normals (the estimate only steers sampling).
float placed_shape_area(const Shape& shape, const Instance& inst) {
  const float area = shape_area(shape);
  if (inst.identity) return area;
  if (const float s = similarity_scale(inst.to_world); s > 0) return area * s * s;
  const float j = area_scale(inst.to_world, inst.to_object, {1, 0, 0}) +
                  area_scale(inst.to_world, inst.to_object, {0, 1, 0}) +
                  area_scale(inst.to_world, inst.to_object, {0, 0, 1});
  return area * j / 3;
}

// Appends the emitting triangles of mesh instance i with their power estimates.
void add_mesh_lights(const Scene& scene, size_t i, AreaLights& lights, std::vector<double>& power) {
  const Instance& inst = scene.instances[i];
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const Material& mat = material_of(scene, mesh.material);
  if (!(max_component(mat.emissive) > 0) || mat.unlit) return;
  lights.first[i] = int64_t(lights.triangles.size());
  const bool moves =
      mesh.motion_steps > 0 || (i < scene.instance_motion.size() && !scene.instance_motion[i].empty());
  const uint32_t n = uint32_t(mesh.indices.size() / 3);
  for (uint32_t prim = 0; prim < n; ++prim) {
    const WorldTriangle tri = world_triangle(scene, inst, prim);
    EmissiveTriangle t{uint32_t(i), prim, triangle_area(tri), tri, moves};
    double p = 0;
    if (t.area > 0)
      p = double(emission_estimate(scene, t.instance, prim, tri, mat)) * t.area * (mat.double_sided ? 2 : 1);
    lights.triangles.push_back(t);
    power.push_back(std::isfinite(p) ? p : 0.0);
  }
}

// Appends shape instance i if its material emits and the shape can be sampled. The power is
// the emissive factor's luminance times the area (both sides of a double-sided flat shape).
void add_shape_light(const Scene& scene, size_t i, AreaLights& lights, std::vector<double>& power) {
  const Instance& inst = scene.instances[i];
  const SceneShape& ss = scene.shapes[size_t(inst.shape)];
  const Material& mat = material_of(scene, ss.material);
  if (!(max_component(mat.emissive) > 0) || mat.unlit || !(shape_area(ss.shape) > 0)) return;
  const bool flat = ss.shape.kind == ShapeKind::Plane || ss.shape.kind == ShapeKind::Disk;
  EmissiveShape e{uint32_t(i), placed_shape_area(ss.shape, inst),
                  i < scene.instance_motion.size() && !scene.instance_motion[i].empty()};
  const double p = double(luminance(mat.emissive)) * e.area * (flat && mat.double_sided ? 2 : 1);
  lights.shapes.push_back(e);
  power.push_back(std::isfinite(p) && p > 0 ? p : 0.0);
}

// Appends the point and spot lights as entries when there are more than `evaluated` of them.
// The power: 4 x luminance(colour) x intensity, a point light's flux 4 pi I over pi (the area
// lights' unit); a spot's cone is left to its bounds, as pbrt-v4's SpotLight::Bounds does.
void add_punctual_lights(const Scene& scene, size_t evaluated, AreaLights& lights,
                         std::vector<double>& power) {
  size_t count = 0;
  for (const Light& l : scene.lights) count += l.type != LightType::Directional;
  if (count <= evaluated) return;
  lights.sampled.assign(scene.lights.size(), 0);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (l.type == LightType::Directional) continue;
    // A moving light: its brightest colour and intensity over the steps (interpolated apart,
    // their product between two steps may exceed both steps').
    double lum = double(luminance(l.color)), intensity = double(l.intensity);
    if (i < scene.light_motion.size())
      for (const Light& step : scene.light_motion[i]) {
        lum = std::max(lum, double(luminance(step.color)));
        intensity = std::max(intensity, double(step.intensity));
      }
    const double phi = 4 * lum * intensity;
    // A light of no estimated power stays evaluated at every vertex.
    if (!(std::isfinite(phi) && phi > 0)) continue;
    lights.punctual.push_back(uint32_t(i));
    lights.sampled[i] = 1;
    power.push_back(phi);
  }
}

// A light's box over the shutter: its box at 33 times, grown by the largest step between two
// of them (so that motion between the samples stays inside).
template <typename BoxAt>
Bounds3f shutter_bounds(BoxAt&& box_at) {
  Bounds3f all, prev;
  float step = 0;
  for (int k = 0; k <= 32; ++k) {
    const Bounds3f b = box_at(float(k) / 32);
    if (k > 0)
      step = std::max({step, max_component(abs(b.lo - prev.lo)), max_component(abs(b.hi - prev.hi))});
    all = merge(all, b);
    prev = b;
  }
  const Vec3f g{step, step, step};
  return {all.lo - g, all.hi + g};
}

Bounds3f triangle_box(const WorldTriangle& t) {
  return merge(merge(Bounds3f{t.p[0], t.p[0]}, t.p[1]), t.p[2]);
}

// The bounds the light tree sees for entry k (power `phi`).
LightBounds entry_bounds(const Scene& scene, const AreaLights& lights, size_t k, float phi) {
  LightBounds b;
  b.phi = phi;
  b.cos_e = 0;  // diffuse emission
  if (k < lights.triangles.size()) {
    const EmissiveTriangle& t = lights.triangles[k];
    const Instance& inst = scene.instances[t.instance];
    b.two_sided = material_of(scene, scene.meshes[size_t(inst.mesh)].material).double_sided;
    if (!t.moves) {
      b.bounds = triangle_box(t.tri);
      b.w = t.tri.ng;
      b.cos_o = dot(b.w, b.w) > 0 ? 1.0f : -1.0f;
      return b;
    }
    b.bounds = shutter_bounds([&](float time) {
      Instance posed;
      return triangle_box(world_triangle(scene, instance_at(scene, t.instance, time, posed), t.prim, time));
    });
    b.cos_o = -1;
    return b;
  }
  if (k >= lights.triangles.size() + lights.shapes.size()) {
    const size_t i = lights.punctual[k - lights.triangles.size() - lights.shapes.size()];
    const Light& l = scene.lights[i];
    const bool moves = i < scene.light_motion.size() && !scene.light_motion[i].empty();
    b.two_sided = false;
    if (moves) {
      for (const Light& step : scene.light_motion[i]) b.bounds = merge(b.bounds, step.position);
      // Linear steps: the segments between them lie in the box of their ends.
      b.cos_o = -1;
      b.cos_e = 0;
      return b;
    }
    b.bounds = {l.position, l.position};
    if (l.type == LightType::Spot) {
      b.w = l.direction;
      b.cos_o = std::cos(l.inner_cone);
      b.cos_e = std::cos(std::max(l.outer_cone - l.inner_cone, 0.0f));
    } else {
      b.cos_o = -1;
    }
    return b;
  }
  const EmissiveShape& e = lights.shapes[k - lights.triangles.size()];
  const Instance& inst = scene.instances[e.instance];
  const SceneShape& ss = scene.shapes[size_t(inst.shape)];
  b.two_sided = material_of(scene, ss.material).double_sided;
  const Bounds3f object = shape_bounds(ss.shape);
  const auto box_at = [&](float time) {
    Instance posed;
    const Instance& at = instance_at(scene, e.instance, time, posed);
    return at.identity ? object : transform_bounds(at.to_world, object);
  };
  b.bounds = e.moves ? shutter_bounds(box_at) : box_at(0);
  const bool flat = ss.shape.kind == ShapeKind::Plane || ss.shape.kind == ShapeKind::Disk;
  if (flat && !e.moves) {
    b.w = world_normal(inst, {0, 1, 0});
    b.cos_o = 1;
  } else {
    b.cos_o = -1;  // a closed shape's normals, or a moving shape's, point every way
  }
  return b;
}

}  // namespace

AreaLights build_area_lights(const Scene& scene, size_t evaluated_punctual) {
  AreaLights lights;
  lights.first.assign(scene.instances.size(), -1);
  std::vector<double> power;
  for (size_t i = 0; i < scene.instances.size(); ++i)
    if (scene.instances[i].shape < 0) add_mesh_lights(scene, i, lights, power);
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    if (scene.instances[i].shape < 0) continue;
    const size_t before = lights.shapes.size();
    add_shape_light(scene, i, lights, power);
    if (lights.shapes.size() > before) lights.first[i] = int64_t(lights.triangles.size() + before);
  }
  add_punctual_lights(scene, evaluated_punctual, lights, power);
  double total = 0;
  for (double p : power) total += p;
  if (!(total > 0)) {
    AreaLights none;
    none.first.assign(scene.instances.size(), -1);
    return none;
  }
  lights.cdf.resize(power.size() + 1);
  lights.pmf.resize(power.size());
  double acc = 0;
  lights.cdf[0] = 0;
  std::vector<LightBounds> bounds(power.size());
  for (size_t k = 0; k < power.size(); ++k) {
    acc += power[k];
    lights.cdf[k + 1] = float(acc / total);
    lights.pmf[k] = float(power[k] / total);
    if (lights.pmf[k] > 0) lights.positive.push_back(uint32_t(k));
    // The tree sees the power relative to the total, as the table does (no float overflow).
    bounds[k] = entry_bounds(scene, lights, k, lights.pmf[k]);
  }
  lights.cdf.back() = 1;
  lights.tree = build_light_tree(bounds);
  return lights;
}

namespace {
const EmissiveTriangle* find_light(const AreaLights& lights, uint32_t instance, uint32_t prim, size_t& k) {
  if (lights.pmf.empty() || instance >= lights.first.size() || lights.first[instance] < 0) return nullptr;
  k = size_t(lights.first[instance]) + prim;
  return k < lights.triangles.size() && lights.triangles[k].instance == instance ? &lights.triangles[k]
                                                                                 : nullptr;
}

// A sphere placed by a similarity, seen from outside: sampled by its cone. Sets its world
// centre and radius.
bool cone_sampled(const Shape& shape, const Instance& inst, Vec3f ref, Vec3f& centre, float& radius) {
  if (shape.kind != ShapeKind::Sphere) return false;
  const float s = inst.identity ? 1.0f : similarity_scale(inst.to_world);
  if (!(s > 0)) return false;
  centre = inst.identity ? Vec3f{0, 0, 0} : apply_point(inst.to_world, {0, 0, 0});
  radius = shape.radius * s;
  return sphere_cone_one_minus_cos(radius, length(centre - ref)) > 0;
}

// Density per unit solid angle of the cone's directions.
float cone_pdf(float radius, float distance) {
  const float omc = sphere_cone_one_minus_cos(radius, distance);
  return omc > 0 ? 1 / (2 * kPi * omc) : 0.0f;
}

// The density per unit area of a cone sample at p (normal n) seen from ref.
float cone_area_pdf(Vec3f centre, float radius, Vec3f ref, Vec3f p, Vec3f n) {
  const Vec3f d = ref - p;
  const float dist2 = dot(d, d);
  if (!(dist2 > 0)) return 0;
  const float cos_l = std::fabs(dot(n, d)) / std::sqrt(dist2);
  return cone_pdf(radius, length(centre - ref)) * cos_l / dist2;
}

// The density per unit world area of an area sample at object point q (object normal n).
float shape_area_pdf(const Shape& shape, const Instance& inst, Vec3f n) {
  const float j = inst.identity ? 1.0f : area_scale(inst.to_world, inst.to_object, n);
  const float a = shape_area(shape) * j;
  return a > 0 && std::isfinite(a) ? 1 / a : 0.0f;
}

// A point on shape entry `e` seen from `ref` at `time`; out.pdf_area is the point's density
// on the shape (without the entry's pmf).
bool sample_shape_light(const EmissiveShape& e, const Scene& scene, Vec3f ref, float time, Vec2f u,
                        AreaLightSample& out) {
  Instance posed;
  const Instance& inst = e.moves ? instance_at(scene, e.instance, time, posed) : scene.instances[e.instance];
  const Shape& shape = scene.shapes[size_t(inst.shape)].shape;
  out.instance = e.instance;
  out.prim = 0;
  out.u = out.v = 0;
  out.shape = true;
  Vec3f centre;
  float radius = 0;
  if (cone_sampled(shape, inst, ref, centre, radius)) {
    ShapePoint sp;
    if (!sample_sphere_cone(centre, radius, ref, u, sp)) return false;
    out.p = sp.p;
    out.ng = sp.n;
    out.pdf_area = cone_area_pdf(centre, radius, ref, sp.p, sp.n);
    return true;
  }
  const ShapePoint sp = sample_shape_area(shape, u);
  out.p = inst.identity ? sp.p : apply_point(inst.to_world, sp.p);
  out.ng = world_normal(inst, sp.n);
  out.pdf_area = shape_area_pdf(shape, inst, sp.n);
  return true;
}

}  // namespace

float light_pmf(const AreaLights& lights, const LightChoice& choice, size_t entry) {
  if (entry >= lights.pmf.size() || !(lights.pmf[entry] > 0)) return 0;
  switch (choice.sampler) {
    case LightSampler::Power:
      return lights.pmf[entry];
    case LightSampler::Uniform:
      return 1.0f / float(lights.positive.size());
    case LightSampler::Tree:
      return light_tree_pmf(lights.tree, choice.p, choice.n, uint32_t(entry));
  }
  return 0;
}

float area_light_pdf(const AreaLights& lights, const LightChoice& choice, uint32_t instance, uint32_t prim,
                     const WorldTriangle& tri) {
  size_t k = 0;
  const EmissiveTriangle* t = find_light(lights, instance, prim, k);
  if (!t) return 0;
  const float area = t->moves ? triangle_area(tri) : t->area;
  return area > 0 ? light_pmf(lights, choice, k) / area : 0.0f;
}

float shape_light_pdf(const AreaLights& lights, const Scene& scene, const LightChoice& choice,
                      uint32_t instance, Vec3f p, float time) {
  const Vec3f ref = choice.p;
  if (lights.pmf.empty() || instance >= lights.first.size() || lights.first[instance] < 0) return 0;
  const size_t k = size_t(lights.first[instance]);
  if (k < lights.triangles.size() || k >= lights.pmf.size()) return 0;
  const EmissiveShape& e = lights.shapes[k - lights.triangles.size()];
  Instance posed;
  const Instance& inst = e.moves ? instance_at(scene, e.instance, time, posed) : scene.instances[e.instance];
  const Shape& shape = scene.shapes[size_t(inst.shape)].shape;
  Vec3f centre;
  float radius = 0;
  const float pmf = light_pmf(lights, choice, k);
  if (!(pmf > 0)) return 0;
  if (cone_sampled(shape, inst, ref, centre, radius))
    return pmf * cone_area_pdf(centre, radius, ref, p, normalize(p - centre));
  const Vec3f q = inst.identity ? p : apply_point(inst.to_object, p);
  const Bounds3f b = shape_bounds(shape);
  const Vec3f n = shape_surface(shape, snap_to_shape(shape, q), 1e-4f * max_component(b.extent())).n;
  return pmf * shape_area_pdf(shape, inst, n);
}

namespace {
// Chooses an entry as `choice` says; false if none can be chosen.
bool choose_entry(const AreaLights& lights, const LightChoice& choice, float u1, size_t& k, float& pmf) {
  if (lights.pmf.empty()) return false;
  if (choice.sampler == LightSampler::Tree) {
    uint32_t entry = 0;
    if (!sample_light_tree(lights.tree, choice.p, choice.n, u1, entry, pmf)) return false;
    k = entry;
    return true;
  }
  if (choice.sampler == LightSampler::Uniform) {
    const size_t n = lights.positive.size();
    if (n == 0) return false;
    k = lights.positive[std::min(size_t(u1 * float(n)), n - 1)];
    pmf = 1.0f / float(n);
    return true;
  }
  const size_t n = lights.pmf.size();
  auto it = std::upper_bound(lights.cdf.begin(), lights.cdf.end(), u1);
  k = size_t(std::clamp<ptrdiff_t>(it - lights.cdf.begin() - 1, 0, ptrdiff_t(n) - 1));
  while (k + 1 < n && !(lights.pmf[k] > 0)) ++k;  // rounding may land on a zero-power entry
  pmf = lights.pmf[k];
  return pmf > 0;
}
}  // namespace

bool sample_area_light(const AreaLights& lights, const Scene& scene, const LightChoice& choice, float time,
                       float u1, Vec2f u, AreaLightSample& out) {
  size_t k = 0;
  float pmf = 0;
  if (!choose_entry(lights, choice, u1, k, pmf)) return false;
  out.light = -1;
  if (const size_t areas = lights.triangles.size() + lights.shapes.size(); k >= areas) {
    out.light = int32_t(lights.punctual[k - areas]);
    out.shape = false;
    out.pdf_area = pmf;
    return pmf > 0;
  }
  if (k >= lights.triangles.size()) {
    if (!sample_shape_light(lights.shapes[k - lights.triangles.size()], scene, choice.p, time, u, out))
      return false;
    out.pdf_area *= pmf;
    return out.pdf_area > 0 && std::isfinite(out.pdf_area) && dot(out.ng, out.ng) > 0;
  }
  const EmissiveTriangle& t = lights.triangles[k];
  float area = t.area;
  if (t.moves) {
    Instance posed;
    out.tri = world_triangle(scene, instance_at(scene, t.instance, time, posed), t.prim, time);
    area = triangle_area(out.tri);
  } else {
    out.tri = t.tri;
  }
  const WorldTriangle& tri = out.tri;
  // Uniform point: b0 = 1 - sqrt(u.x), b1 = u.y sqrt(u.x), b2 = (1 - u.y) sqrt(u.x)
  // (pbrt-v3 UniformSampleTriangle); the Hit convention's (u, v) are (b1, b2).
  const float su = std::sqrt(u.x);
  out.instance = t.instance;
  out.prim = t.prim;
  out.shape = false;
  out.u = u.y * su;
  out.v = (1 - u.y) * su;
  out.p = tri.p[0] * (1 - out.u - out.v) + tri.p[1] * out.u + tri.p[2] * out.v;
  out.ng = tri.ng;
  out.pdf_area = area > 0 ? pmf / area : 0.0f;
  return out.pdf_area > 0 && dot(out.ng, out.ng) > 0;
}

}  // namespace penumbra
