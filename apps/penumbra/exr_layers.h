// The EXR of a render: its metadata (render settings, OpenEXR's camera matrices, the id name
// manifest, the identity of crops and tiles) and its AOV layers, typed per layer (half colour,
// float data, uint ids), in ExrOptions for io/image_output's write_exr.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf/loader.h"
#include "io/image/image_output.h"
#include "render/session.h"
#include "renderer/film/cryptomatte.h"
#include "renderer/integrators/aov.h"
#include "renderer/integrators/cost_map.h"

namespace penumbra::cli {

struct RenderJob;

/// The per-pixel layers an EXR points into; must outlive the ExrOptions made from it.
struct LayerBuffers {
  RenderLayers layers;         ///< the render session's layers (data AOVs, Cryptomatte, cost)
  std::vector<float> samples;  ///< the path tracer's sample counts as floats
  /// Manifests too large for the header, written beside the EXR: (path, JSON text).
  std::vector<std::pair<std::filesystem::path, std::string>> sidecars;
};

/// Manifests up to this size go into the EXR header; larger ones into a sidecar JSON file
/// beside it ("OUT.CryptoObject.json"), named by the layer's manif_file attribute.
inline constexpr size_t kInlineManifestBytes = 64 * 1024;

/// The sidecar manifest path of Cryptomatte layer `layer` of the EXR `exr`.
std::filesystem::path crypto_sidecar_path(const std::filesystem::path& exr, const std::string& layer);

/// The beauty's EXR options: compression, part layout, every metadata attribute, and one channel
/// per requested AOV, pointing into `buffers` and job.image.
ExrOptions make_exr_options(const RenderJob& job, LayerBuffers& buffers);

}  // namespace penumbra::cli
