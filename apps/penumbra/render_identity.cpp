// The scene part of a render's identity.
#include "apps/penumbra/render_identity.h"

#include "apps/penumbra/cli_support.h"

namespace penumbra::cli {

SceneIdentity scene_identity(const RenderArgs& a, const RenderRequest&, const std::string& scene_sha256) {
  SceneIdentity s;
  s.sha256 = scene_sha256;
  s.index = a.scene;
  s.flatten = a.flatten;
  s.variant = a.variant;
  const bool frame_is_time = a.frame && a.cam.turntable.empty();  // a turntable's frame turns the camera
  s.time = a.time ? exact(*a.time)
                  : (frame_is_time ? "frame " + *a.frame + " at " + exact(a.spec.fps) + " fps" : "static");
  s.camera = a.camera;
  return s;
}

}  // namespace penumbra::cli
