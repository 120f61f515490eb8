// Area lights: the emissive-triangle table, power-proportional selection, uniform sampling.
#include "renderer/lights/area.h"

#include <algorithm>
#include <cmath>

#include "renderer/materials/material.h"
#include "renderer/scene/interaction.h"

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

AreaLights build_area_lights(const Scene& scene) {
  AreaLights lights;
  lights.first.assign(scene.instances.size(), -1);
  std::vector<double> power;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.shape >= 0) continue;  // emissive shapes shine when hit but are not sampled
    const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
    const Material& mat = material_of(scene, mesh.material);
    if (!(max_component(mat.emissive) > 0) || mat.unlit) continue;
    lights.first[i] = int64_t(lights.triangles.size());
    const bool moves =
        mesh.motion_steps > 0 || (i < scene.instance_motion.size() && !scene.instance_motion[i].empty());
    const uint32_t n = uint32_t(mesh.indices.size() / 3);
    for (uint32_t prim = 0; prim < n; ++prim) {
      const WorldTriangle tri = world_triangle(scene, inst, prim);
      EmissiveTriangle t{uint32_t(i), prim, triangle_area(tri), tri, moves};
      double p = 0;
      if (t.area > 0)
        p = double(emission_estimate(scene, t.instance, prim, tri, mat)) * t.area *
            (mat.double_sided ? 2 : 1);
      lights.triangles.push_back(t);
      power.push_back(std::isfinite(p) ? p : 0.0);
    }
  }
  double total = 0;
  for (double p : power) total += p;
  if (!(total > 0)) return AreaLights{{}, {}, {}, std::vector<int64_t>(scene.instances.size(), -1)};
  lights.cdf.resize(power.size() + 1);
  lights.pmf.resize(power.size());
  double acc = 0;
  lights.cdf[0] = 0;
  for (size_t k = 0; k < power.size(); ++k) {
    acc += power[k];
    lights.cdf[k + 1] = float(acc / total);
    lights.pmf[k] = float(power[k] / total);
  }
  lights.cdf.back() = 1;
  return lights;
}

namespace {
const EmissiveTriangle* find_light(const AreaLights& lights, uint32_t instance, uint32_t prim, size_t& k) {
  if (lights.pmf.empty() || instance >= lights.first.size() || lights.first[instance] < 0) return nullptr;
  k = size_t(lights.first[instance]) + prim;
  return k < lights.triangles.size() ? &lights.triangles[k] : nullptr;
}
}  // namespace

float area_light_pdf(const AreaLights& lights, uint32_t instance, uint32_t prim) {
  size_t k = 0;
  const EmissiveTriangle* t = find_light(lights, instance, prim, k);
  return t && t->area > 0 ? lights.pmf[k] / t->area : 0.0f;
}

float area_light_pdf(const AreaLights& lights, uint32_t instance, uint32_t prim, const WorldTriangle& tri) {
  size_t k = 0;
  const EmissiveTriangle* t = find_light(lights, instance, prim, k);
  if (!t) return 0;
  const float area = t->moves ? triangle_area(tri) : t->area;
  return area > 0 ? lights.pmf[k] / area : 0.0f;
}

bool sample_area_light(const AreaLights& lights, const Scene& scene, float time, float u1, Vec2f u,
                       AreaLightSample& out) {
  if (lights.pmf.empty()) return false;
  const size_t n = lights.triangles.size();
  auto it = std::upper_bound(lights.cdf.begin(), lights.cdf.end(), u1);
  size_t k = size_t(std::clamp<ptrdiff_t>(it - lights.cdf.begin() - 1, 0, ptrdiff_t(n) - 1));
  while (k + 1 < n && !(lights.pmf[k] > 0)) ++k;  // rounding may land on a zero-power entry
  if (!(lights.pmf[k] > 0)) return false;
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
  out.u = u.y * su;
  out.v = (1 - u.y) * su;
  out.p = tri.p[0] * (1 - out.u - out.v) + tri.p[1] * out.u + tri.p[2] * out.v;
  out.ng = tri.ng;
  out.pdf_area = area > 0 ? lights.pmf[k] / area : 0.0f;
  return out.pdf_area > 0 && dot(out.ng, out.ng) > 0;
}

}  // namespace penumbra
