// Shadow maps (Williams, "Casting Curved Shadows on Curved Surfaces", SIGGRAPH 1978): for each
// punctual light, depth maps rendered by the rasteriser from the light (directional: one
// orthographic map over the scene's bounds; spot with a cone of at most 60 degrees: one
// perspective map over the cone; point and wider spots: a cube of six faces), looked up with a
// normal offset and slope-scaled depth bias and 3x3 percentage-closer filtering (Reeves,
// Salesin and Cook, "Rendering Antialiased Shadows with Depth Maps", SIGGRAPH 1987). Every face
// of every surface casts shadows (no back-face culling), Mask holes let light through, and a
// Blend surface casts a shadow where its coverage is at least 0.5.
#pragma once

#include <cstdint>
#include <vector>

#include "renderer/scene/scene.h"

namespace penumbra {

/// One depth map: the light's view as a camera (square image) and the view depth of the
/// nearest surface at each texel centre (+inf where there is none).
struct ShadowFace {
  Camera view;
  int size = 0;
  float tan_half = 0;        ///< perspective: tan(view.yfov / 2); 0 for an orthographic face
  std::vector<float> depth;  ///< size x size, row-major, top row first
};

/// A light's maps: one face, or six for a cube (faces +X, -X, +Y, -Y, +Z, -Z of the light).
struct ShadowMap {
  std::vector<ShadowFace> faces;
  bool cube = false;
};

/// One ShadowMap per scene light, in Scene::lights order.
struct ShadowMaps {
  std::vector<ShadowMap> lights;
};

/// Bytes the shadow maps of `scene` take at `size` texels on a side (for memory budgets).
uint64_t shadow_map_bytes(const Scene& scene, int size);

/// Renders every light's depth maps at size x size texels (size >= 1) on `threads` (as
/// thread_count()). Deterministic for any thread count.
ShadowMaps build_shadow_maps(const Scene& scene, int size, int threads);

/// The fraction in [0, 1] of light `light` that reaches world point p on a surface with unit
/// geometric normal ng, by percentage-closer filtering of the light's map (points outside
/// every map are lit). Never allocates, throws or logs.
float shadow_map_visibility(const ShadowMaps& maps, int light, Vec3f p, Vec3f ng);

}  // namespace penumbra
