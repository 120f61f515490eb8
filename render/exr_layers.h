// The EXR channels of a render's layers, as every front end writes them: data AOVs (albedo.RGB
// in the colour type, N.XYZ, P.XYZ, Z, UV.UV, object_id.X and material_id.X as whole-number
// floats with their name manifest) and the path tracer's layers (samples.X, variance.X, the
// light groups' .RGB in the colour type), the motion vectors (vector.XYZW, Blender's Vector
// pass), the camera-space velocity (velocity.XYZ) and the denoiser's halves (even.RGB, odd.RGB,
// even_albedo.RGB, ..., odd_Z.Z in float: io/image/exr_denoise.h), pointing into the render's
// buffers.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "io/image/image_output.h"
#include "renderer/integrators/aov.h"

namespace penumbra {

/// The buffers the channels point into; each must outlive the ExrOptions it is added to.
struct LayerChannels {
  const DataAovs* data = nullptr;                 ///< with any of albedo, N, P, Z, UV, id
  const std::string* id_manifest = nullptr;       ///< with id
  const std::vector<float>* samples = nullptr;    ///< with samples: the counts as floats
  const std::vector<float>* variance = nullptr;   ///< with variance
  const std::vector<float>* groups = nullptr;     ///< with light: kLightGroupChannels per pixel
  const std::vector<float>* vector = nullptr;     ///< with vector: kMotionVectorChannels per pixel
  const std::vector<float>* velocity = nullptr;   ///< with velocity: kVelocityChannels per pixel
  const std::vector<float>* halves = nullptr;     ///< with halves: kHalfChannels per pixel (the
                                                  ///< features from data->halves)
  const std::vector<float>* wireframe = nullptr;  ///< the wireframe's coverage (wireframe.A) when
                                                  ///< non-null and not empty
};

/// Appends the channels of every layer `aovs` names (and the id layer's penumbra:manifest
/// attribute) to `exr`, in the order above, then the wireframe's; `colour` is the type of colour
/// layers (and of the wireframe).
void add_layer_channels(ExrOptions& exr, const std::set<std::string>& aovs, const LayerChannels& buffers,
                        ChannelType colour);

}  // namespace penumbra
