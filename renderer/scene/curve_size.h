// The sizes of point and line sets the file does not give: a point's diameter and a line's width
// in scene units, or in pixels converted at each vertex's depth through the render's camera, so
// that a 2-pixel point is two pixels across wherever it lies (as viewers draw them).
#pragma once

#include <string>

#include "renderer/scene/camera.h"
#include "renderer/scene/scene.h"

namespace penumbra {

/// A point's diameter or a line's width.
struct CurveSize {
  float value = 1;     ///< > 0 and finite
  bool pixels = true;  ///< true: image pixels (at the vertex's depth); false: scene units
};

/// "2px" (pixels) or "0.01" (scene units): a finite positive number, optionally followed by
/// "px". Throws std::invalid_argument naming `setting` otherwise.
CurveSize parse_curve_size(const std::string& text, const std::string& setting);

/// The world-space length one image pixel spans at `p` seen by `camera` in an image
/// `height` pixels high: 2 depth tan(yfov / 2) / height (perspective, depth along the view
/// axis, at least the near distance or 1e-6) or 2 ymag / height (orthographic).
float pixel_footprint(const Camera& camera, int height, Vec3f p);

/// Sets the radii of the scene's point sets (Mesh::points) and line sets (Mesh::lines) whose
/// file gave none (Mesh::file_radii false): half of `points` or `lines`, a pixel size converted
/// at each vertex through its first instance's placement. Point sets without any instance keep
/// no radii. Never allocates beyond one radius per vertex.
void set_curve_radii(Scene& scene, const Camera& camera, int height, CurveSize points, CurveSize lines);

}  // namespace penumbra
