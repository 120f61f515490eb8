// Surface data at a ray hit, reconstructed from the Hit record and the scene's meshes; shared
// by all integrators.
#pragma once

#include "renderer/geometry.h"
#include "renderer/scene.h"

namespace penumbra {

struct SurfaceInteraction {
  Vec3f p;        ///< hit point, interpolated from the triangle's vertices
  Vec3f ng;       ///< unit geometric normal, facing the incoming ray (dot(ng, -dir) >= 0)
  Vec3f ns;       ///< unit shading normal, in the same hemisphere as ng
  Vec2f uv;       ///< TEXCOORD_0 (0,0 if absent)
  int material = -1;
  bool back_face = false;  ///< true if the ray hit the triangle's back (clockwise) side
};

/// Requires hit.valid() and hit ids inside the scene (as any accelerator over mesh_views()
/// returns).
SurfaceInteraction make_interaction(const Scene& scene, const Ray& ray, const Hit& hit);

}  // namespace penumbra
