// The rasteriser: every instance's triangles through the projection pipeline (world -> camera
// -> clip space, homogeneous clipping, perspective divide, viewport), binned into screen tiles
// and rasterised tile by tile in parallel with fixed-point edge functions (top-left rule) into
// a z-buffer of camera samples: a visibility buffer holding, per sample, the nearest surface's
// instance, triangle and perspective-correct barycentrics, and the Blend surfaces in front of
// it sorted front to back. Analytic and implicit shapes are ray-cast in the fragment stage
// over their projected bounds (impostors); rendered point and line sets as stand-ins facing the
// viewer on the silhouettes of their spheres and capsules (a disc per point; a quad per segment
// with a disc at each end), through the same z-buffer and top-left rule. Shading is the caller's: the
// visibility buffer of each tile is handed to a callback. No ray queries against an accelerator, no materials
// beyond coverage (alpha test and alpha mode).
#pragma once

#include <cstdint>
#include <functional>

#include "renderer/core/geometry.h"
#include "renderer/core/parallel.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// The view a raster pass sees through.
struct RasterView {
  Transform view;             ///< world -> view space; the view looks down -Z, depth = -z
  Transform projection;       ///< view -> clip space (as projection_matrix(): near at z + w = 0)
  bool far_plane = true;      ///< clip at a finite far plane (z <= w); false: no far clipping
  int width = 0, height = 0;  ///< viewport in pixels: raster x = (x/w + 1) width / 2,
                              ///< y = (1 - y/w) height / 2 (y down, pixel corners at integers)
  /// The world-space ray through raster position (x, y), for shapes: its depth at parameter t
  /// must be -view.z of org + t dir, and its [tnear, tfar] the range the projection clips to.
  Ray (*ray)(const void* context, float x, float y) = nullptr;
  const void* ray_context = nullptr;
};

/// How Blend-mode surfaces enter the visibility buffer.
enum class RasterBlend : uint8_t {
  Layers,     ///< kept as sorted layers in front of the nearest opaque surface
  Threshold,  ///< opaque where their coverage (eval_alpha) is >= 0.5, holes elsewhere
};

/// One raster pass: which pixels, how many samples where, and the fragment stage's rules.
struct RasterPass {
  PixelWindow window;  ///< the pixels produced: non-empty, inside the viewport
  int tile_size = 32;  ///< screen tiles (pixels), >= 1; also the unit of parallel work
  int threads = 0;     ///< as thread_count()
  int spp = 1;         ///< samples per pixel, >= 1
  /// Where sample s of pixel (x, y) lies (raster position), within `margin` pixels of the
  /// pixel's square; a pure function of (x, y, s). Null: the pixel centre (spp must be 1).
  Vec2f (*position)(const void* context, int x, int y, uint32_t s) = nullptr;
  const void* position_context = nullptr;
  float margin = 0;             ///< >= 0, see `position`
  bool cull_back_faces = true;  ///< drop the back faces of single-sided materials
  RasterBlend blend = RasterBlend::Layers;
  bool depth_only = false;    ///< fragments carry only depth and ids (no barycentrics or derivatives),
                              ///< Blend surfaces as Threshold: the passes of shadow maps
  int max_blend_layers = 16;  ///< Layers: at most this many per sample (>= 0); the next
                              ///< Blend surface, if any, counts as opaque
};

/// What one sample sees of one surface.
struct RasterFragment {
  /// geom_id = instance index, prim_id = triangle (0 for a shape), u, v = perspective-correct
  /// barycentrics in the source triangle (0 for a shape); t = the ray parameter along
  /// RasterView::ray for a shape, unset (infinity) for a triangle.
  Hit hit;
  float depth = kInfinity;  ///< view-space depth (distance along the view axis)
  /// Screen-space derivatives of (u, v) per pixel step in x and in y (0 for shapes).
  Vec2f duv_dx, duv_dy;
};

/// The visibility buffer of one tile. Samples are numbered (pixel row-major in `pixels`,
/// then sample index): sample i of pixel (x, y) is ((y - y0) * width + (x - x0)) * spp + i.
struct RasterTile {
  PixelWindow pixels;
  int spp = 1;
  const Vec2f* positions = nullptr;        ///< raster position of each sample
  const RasterFragment* opaque = nullptr;  ///< per sample; hit.valid() false: nothing opaque
  const uint32_t* blend_begin = nullptr;   ///< per sample, plus one: the sample's range in `blend`
  const RasterFragment* blend = nullptr;   ///< Blend layers, front to back, each in front of
                                           ///< the sample's opaque fragment
};

/// Figures of a raster pass.
struct RasterStats {
  uint64_t triangles_in = 0;     ///< triangles submitted (each instance's)
  uint64_t triangles_setup = 0;  ///< triangles rasterised after culling and clipping (fans counted)
  uint64_t clipped = 0;          ///< source triangles that needed clipping
  uint64_t culled = 0;           ///< source triangles culled (outside a plane or back-facing)
  uint64_t bin_references = 0;   ///< (tile, triangle) pairs
  uint64_t shapes = 0;           ///< shape instances ray-cast
  double setup_seconds = 0;      ///< vertex stage, clipping and triangle setup
  double bin_seconds = 0;        ///< binning into tiles
  double tile_seconds = 0;       ///< rasterising, resolving and shading the tiles
};

/// Bytes a raster pass over `scene` may hold at once beyond the caller's own buffers: setup
/// triangles (up to kRasterClipFactor per source triangle), bin references and each thread's
/// tile buffers. For memory budgets.
uint64_t raster_memory_bytes(const Scene& scene, const RasterPass& pass);

/// Rasterises every instance of `scene` (meshes and shapes) seen through `view` and calls
/// shade(tile) once per tile of pass.window, concurrently from worker threads. The buffer a
/// tile sees depends only on the scene, view and pass (never on threads, tile order or the
/// order of triangles in the scene): the nearest fragment per sample is the least (depth,
/// submission index) pair, with every triangle's submission index fixed by its instance and
/// index, and the inside test is exact. Back faces of single-sided materials are culled when
/// pass.cull_back_faces; Mask surfaces are alpha-tested (eval_alpha) per sample. Requires
/// a valid view (ray set when the scene has shapes) and pass. Allocates its working memory;
/// never throws but std::bad_alloc.
void rasterize(const Scene& scene, const RasterView& view, const RasterPass& pass,
               const std::function<void(const RasterTile& tile)>& shade, RasterStats* stats = nullptr);

}  // namespace penumbra
