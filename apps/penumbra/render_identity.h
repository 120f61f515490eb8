// What a render is, in canonical form: the content hash of its scene and every setting that
// decides its pixels. The resume state records it (with the window) and crops and tiles carry it
// (with the sample target and layers), so state or parts of another render are recognised.
#pragma once

#include <string>

#include "apps/penumbra/render_options.h"
#include "io/farm/render_settings.h"
#include "renderer/scene/camera.h"

namespace penumbra::cli {

/// Everything that decides the pixels of a render except its window and sample target: the
/// scene (content hash, scene index, flattening, pose), camera, image size and every sampling
/// and integrator setting; `env_sha256` is the --env map's hash (empty for a colour or none).
RenderSettings pixel_settings(const RenderArgs& args, const RenderConfig& cfg, const Camera& camera,
                              const std::string& scene_sha256, const std::string& env_sha256);

}  // namespace penumbra::cli
