// The wireframe overlay: the triangle edges of chosen nodes drawn as anti-aliased lines of a
// width in pixels, depth-tested against what each pixel's centre ray sees (hidden edges
// dropped, dimmed or dashed), as a coverage image that composites over the beauty and is
// written as its own layer (wireframe.A). Works with every integrator: the depth test traces
// one pinhole ray per pixel through the structure the render built.
#pragma once

#include <vector>

#include "renderer/accel/accelerator.h"
#include "renderer/film/film.h"
#include "renderer/integrators/render_config.h"
#include "renderer/scene/camera.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// How edges behind a surface are drawn.
enum class WireframeHidden : uint8_t {
  Off,     ///< not drawn
  Dim,     ///< at a quarter of their coverage
  Dashed,  ///< in dashes of 4 pixels every 8 along the edge on screen
};

/// What the overlay draws.
struct WireframeConfig {
  float width = 1;  ///< line width in pixels, > 0
  WireframeHidden hidden = WireframeHidden::Off;
  /// glTF nodes whose instances' edges are drawn (Instance::node); empty: every mesh instance.
  std::vector<int> nodes;
};

/// The wireframe's coverage (0..1) of each pixel of render_window(config), row-major: for each
/// triangle edge of the chosen triangle meshes (point and line sets and shapes have none), the
/// box-filtered coverage of a band `width` pixels wide about its projection (near-clipped),
/// the largest over all edges. A pixel of an edge is visible when its centre ray hits nothing,
/// hits a triangle of the same instance that has the edge, or hits no nearer than the edge's
/// depth there (within 1e-3 of it and two pixel footprints); otherwise `hidden` applies.
/// Deterministic for any thread count and window split. Never throws but std::bad_alloc.
std::vector<float> render_wireframe(const Scene& scene, const Accelerator& accel, const Camera& camera,
                                    const RenderConfig& config, const WireframeConfig& wire);

/// Composites `colour` with coverage `alpha` (one per pixel of film) over the premultiplied film:
/// rgb = colour a + rgb (1 - a), alpha = a + alpha (1 - a).
void overlay_wireframe(Film& film, const std::vector<float>& alpha, Vec3f colour);

}  // namespace penumbra
