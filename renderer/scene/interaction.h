// Surface data at a ray hit, reconstructed from the Hit record and the scene's meshes or shapes, plus
// the screen-space derivatives (from ray differentials) that texture filtering needs; shared
// by all integrators.
#pragma once

#include "renderer/core/geometry.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// Auxiliary rays one pixel step to the right (x) and down (y) of a ray (pbrt's
/// RayDifferential). valid = false: no footprint known (textures use their finest level).
struct RayDifferential {
  bool valid = false;
  Vec3f rx_org, rx_dir, ry_org, ry_dir;
};

struct SurfaceInteraction {
  Vec3f p;                  ///< hit point, interpolated from the triangle's vertices (on a shape:
                            ///< the object-space hit mapped to world space)
  Vec3f ng;                 ///< unit geometric normal, facing the incoming ray (dot(ng, -dir) >= 0)
  Vec3f ns;                 ///< unit interpolated vertex normal, in the same hemisphere as ng
  Vec2f uv[2];              ///< TEXCOORD_0 and TEXCOORD_1 ((0,0) if absent)
  Vec4f color{1, 1, 1, 1};  ///< COLOR_0 (white if absent)
  Vec4f tangent;            ///< world tangent (xyz) and bitangent sign (w); w == 0 if the mesh has none
  int material = -1;
  uint32_t instance = 0;  ///< index into Scene::instances (the Hit's geom_id)
  uint32_t mesh = 0, prim = 0;
  int shape = -1;          ///< index into Scene::shapes for a shape hit (mesh and prim are then 0)
  bool back_face = false;  ///< true if the ray hit the triangle's back (clockwise) side, or a
                           ///< shape from inside (flat shapes: from -Y)
  float time = 0.5f;       ///< the ray's time (Ray::time): rays spawned here keep it
  float spawn_offset = 0;  ///< extra world distance along ng that spawned rays keep from the
                           ///< surface: the implicit shapes' hit tolerance, 0 otherwise
  // Screen-space derivatives, zero unless compute_differentials() found a footprint.
  Vec3f dpdx, dpdy;          ///< of the hit point
  Vec3f dndx, dndy;          ///< of the (unnormalised) interpolated normal
  Vec2f duvdx[2], duvdy[2];  ///< of each UV set
  WorldTriangle tri{};       ///< the hit triangle in world space, unfaced (meshes only), so
                             ///< derivatives and normal mapping do not rebuild it
};

/// Requires hit.valid() and hit ids inside the scene (as any accelerator over mesh_views()
/// and instance_views() returns). Everything is in world space.
SurfaceInteraction make_interaction(const Scene& scene, const Ray& ray, const Hit& hit);

/// make_interaction for a mesh hit whose world triangle is already known: `tri` must equal
/// world_triangle(scene, scene.instances[hit.geom_id], hit.prim_id) (shape hits ignore it).
SurfaceInteraction make_interaction(const Scene& scene, const Ray& ray, const Hit& hit,
                                    const WorldTriangle& tri);

/// The origin of a ray leaving si.p in direction `dir`: offset_ray_origin() plus si.spawn_offset
/// along the side of ng that `dir` points to, so the ray does not find the same surface again.
Vec3f spawn_origin(const SurfaceInteraction& si, Vec3f dir);

/// The unit world-space front normal of the hit surface: the triangle's counter-clockwise side
/// (as world_triangle), or a shape's outward normal at the hit. Cheaper than make_interaction.
Vec3f hit_front_normal(const Scene& scene, const Ray& ray, const Hit& hit);

/// Fills si's derivatives by intersecting the differential rays with the tangent plane at
/// si.p and expressing the offsets in the triangle's barycentrics (pbrt-v3, 10.1.1), or for a
/// shape as differences of its UV map at the offset points. Leaves
/// them zero when rd is not valid or the plane is parallel to an auxiliary ray.
void compute_differentials(const Scene& scene, SurfaceInteraction& si, const RayDifferential& rd);

/// Fills a triangle hit's derivatives from the screen-space derivatives of its barycentrics
/// (u, v) over one differential step in x (bx) and in y (by), as a rasteriser knows them:
/// dp = e1 du + e2 dv on the world triangle, and the UVs' and normal's derivatives likewise.
/// Leaves shape hits and non-finite input untouched.
void set_barycentric_differentials(const Scene& scene, SurfaceInteraction& si, Vec2f bx, Vec2f by);

/// Differentials of the mirror-reflected ray (pbrt-v3 SpecularReflect): origins move by
/// dp/dx, dp/dy; directions by the change of the view vector and of the normal. `wo` is the
/// unit direction towards the viewer, `n` the unit normal used for reflection, `wi` the
/// reflected direction. Returns an invalid differential if rd is invalid.
RayDifferential reflect_differential(const SurfaceInteraction& si, const RayDifferential& rd, Vec3f wo,
                                     Vec3f n, Vec3f wi);

}  // namespace penumbra
