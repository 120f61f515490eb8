// KHR_animation_pointer: animation channels whose target is a JSON pointer into the file,
// sampled at the load time and written into the parsed model before it is converted, so that
// every converter reads the animated value as it reads a static one. Animated: material factors
// (the core ones and those of the KHR material extensions Penumbra implements), KHR_lights_punctual
// colour, intensity, range and cone angles, camera projections, and node TRS and weights.
// Internal to io/gltf/.
#pragma once

#include "io/gltf/context.h"

namespace tinygltf {
class Model;
}

namespace penumbra::gltf {

/// Samples every KHR_animation_pointer channel of ctx.model at `time` and writes the values into
/// `model` (the same model ctx reads, writable). A pointer to a property Penumbra does not animate
/// is a warning naming the channel; a pointer to an element that does not exist, or a value of
/// the wrong width, is an InputError naming it.
void apply_animation_pointers(const GltfContext& ctx, tinygltf::Model& model, double time);

/// True if any channel of the model is a KHR_animation_pointer channel.
bool has_animation_pointers(const tinygltf::Model& model);

}  // namespace penumbra::gltf
