// The raster integrator: primary visibility by the rasteriser (raster/rasterize.h) at the
// Whitted integrator's camera sample positions, each visible surface shaded with the Whitted
// integrator's local terms (ambient, emission, Lambert and Blinn-Phong per light), lights
// made visible by shadow rays, shadow maps or not at all, Blend layers composited front to
// back; and the data AOVs of the same samples. No mirror reflection or refraction: a preview
// and an independent check of the ray tracer's primary visibility.
#pragma once

#include "renderer/integrators/aov.h"
#include "renderer/integrators/render.h"
#include "renderer/raster/rasterize.h"

namespace penumbra {

/// The camera as a raster view for a width x height image: view_matrix(), projection_matrix()
/// with the image's aspect, far clipping when zfar is finite, and the camera's rays (raster_ray,
/// bit for bit generate_camera_ray's) for shapes. view.ray_context points at the CameraView
/// itself: it must stay where make_camera_view() filled it in.
struct CameraView {
  Camera camera;
  int width = 0, height = 0;
  CameraRaster raster;  ///< the camera's per-image terms
  RasterView view;
};
void make_camera_view(const Camera& camera, int width, int height, CameraView& out);

/// The raster pass of a render: its window, tiles, threads and samples at
/// camera_sample_position(config, Raster, ...), the filter's reach as margin, back faces of
/// single-sided materials culled, Blend surfaces as layers up to whitted.max_blend_layers.
RasterPass camera_raster_pass(const RenderConfig& config);

/// Renders the scene with the raster integrator. Requires a config that passes validate();
/// `accel` (built by make_scene_accelerator over the scene) answers the shadow rays of
/// RasterShadows::Ray, must be non-null then and is not used otherwise. Each pixel is the plain mean of its
/// samples' composited radiance (RGBA, premultiplied; background = whitted.background with alpha 0),
/// bit-identical for any thread count or tile size. stats->rays counts shadow rays; the
/// camera samples are rasterised, not traced.
Film render_raster(const Scene& scene, const Accelerator* accel, const Camera& camera,
                   const RenderConfig& config, RenderStats* stats = nullptr, const ProgressFn& progress = {});

/// The data AOVs of render_data_aovs from the rasterised samples (the first visible surface of
/// each sample is its nearest fragment, Blend layers included). Same layout and reductions.
DataAovs render_raster_aovs(const Scene& scene, const Camera& camera, const RenderConfig& config);

}  // namespace penumbra
