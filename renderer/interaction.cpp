// Hit -> surface reconstruction.
#include "renderer/interaction.h"

namespace penumbra {

SurfaceInteraction make_interaction(const Scene& scene, const Ray& ray, const Hit& hit) {
  const Mesh& mesh = scene.meshes[hit.geom_id];
  const size_t base = size_t(hit.prim_id) * 3;
  const uint32_t i0 = mesh.indices[base], i1 = mesh.indices[base + 1], i2 = mesh.indices[base + 2];
  const float w = 1.0f - hit.u - hit.v;
  const Vec3f a = mesh.positions[i0], b = mesh.positions[i1], c = mesh.positions[i2];
  SurfaceInteraction si;
  si.p = a * w + b * hit.u + c * hit.v;
  si.material = mesh.material;
  si.ng = triangle_normal(a, b, c);
  if (!(dot(si.ng, si.ng) > 0)) si.ng = normalize(-ray.dir);
  Vec3f ns = si.ng;
  if (!mesh.normals.empty()) {
    ns = normalize(mesh.normals[i0] * w + mesh.normals[i1] * hit.u + mesh.normals[i2] * hit.v);
    if (!(dot(ns, ns) > 0)) ns = si.ng;
  }
  if (!mesh.uvs.empty()) {
    const Vec2f t0 = mesh.uvs[i0], t1 = mesh.uvs[i1], t2 = mesh.uvs[i2];
    si.uv = {t0.x * w + t1.x * hit.u + t2.x * hit.v, t0.y * w + t1.y * hit.u + t2.y * hit.v};
  }
  // Face-forward: both normals towards the viewer, so back faces shade like front faces.
  si.back_face = dot(si.ng, ray.dir) > 0;
  if (si.back_face) {
    si.ng = -si.ng;
    ns = -ns;
  }
  if (dot(ns, si.ng) < 0) ns = si.ng;  // interpolated normal flipped by the geometry
  si.ns = ns;
  return si;
}

}  // namespace penumbra
