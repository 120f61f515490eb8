// The scene part of a render's identity as the command's flags describe it. The identity itself
// (every setting that decides the pixels) is the render spec's: render_identity in
// render/spec.h. The resume state records it (with the window) and crops and tiles carry it
// (with the sample target and layers), so state or parts of another render are recognised.
#pragma once

#include <string>

#include "apps/penumbra/render_options.h"
#include "render/spec.h"

namespace penumbra::cli {

/// The scene's content hash `scene_sha256`, scene index, flattening, variant, pose (--time, or
/// --frame at --fps unless a turntable's frame turns only the camera) and --camera as given (the
/// session adds the environment map's hash once it has read the map).
SceneIdentity scene_identity(const RenderArgs& args, const RenderRequest& request,
                             const std::string& scene_sha256);

}  // namespace penumbra::cli
