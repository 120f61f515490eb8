// EXT_lights_image_based: the image-based light a scene references, its prefiltered cube map's
// first mip (six faces: JPEG as LDR sRGB, PNG as RGBD-packed HDR, per the extension) resampled
// into the path tracer's equirectangular environment with the light's rotation and intensity.
// The spherical-harmonic irradiance and the lower mips are not needed by a path tracer, which
// integrates the radiance itself. Internal to io/gltf/.
#pragma once

#include "io/gltf/context.h"
#include "io/gltf/images.h"

namespace penumbra::gltf {

/// Sets ctx.out.environment from the EXT_lights_image_based light of the loaded scene, if it
/// has one. Throws InputError naming the element for a malformed light (indices out of range,
/// not six faces, faces of different or non-square sizes); an unreadable face is a warning and
/// no environment.
void load_image_light(const GltfContext& ctx, TextureCache& cache);

}  // namespace penumbra::gltf
