// The EXR channels of a render's layers.
#include "render/exr_layers.h"

#include "io/image/exr_denoise.h"
#include "renderer/integrators/light_groups.h"
#include "renderer/integrators/motion_vectors.h"

namespace penumbra {

void add_layer_channels(ExrOptions& exr, const std::set<std::string>& aovs, const LayerChannels& b,
                        ChannelType colour) {
  const auto vec = [&](const char* layer, const char* axes, const std::vector<float>* data, ChannelType type,
                       int n) {
    for (int c = 0; c < n; ++c) exr.extra.push_back({std::string(layer) + "." + axes[c], data, type, n, c});
  };
  if (aovs.count("albedo")) vec("albedo", "RGB", &b.data->albedo, colour, 3);
  if (aovs.count("N")) vec("N", "XYZ", &b.data->normal, ChannelType::Float, 3);
  if (aovs.count("P")) vec("P", "XYZ", &b.data->position, ChannelType::Float, 3);
  if (aovs.count("Z")) exr.extra.push_back({"Z", &b.data->depth, ChannelType::Float});
  if (aovs.count("UV")) vec("UV", "UV", &b.data->uv, ChannelType::Float, 2);
  if (aovs.count("id")) {
    exr.extra.push_back({"object_id.X", &b.data->object_id, ChannelType::Float});
    exr.extra.push_back({"material_id.X", &b.data->material_id, ChannelType::Float});
    exr.metadata.push_back({"penumbra:manifest", *b.id_manifest});
  }
  if (aovs.count("samples")) exr.extra.push_back({"samples.X", b.samples, ChannelType::Float});
  if (aovs.count("variance")) exr.extra.push_back({"variance.X", b.variance, ChannelType::Float});
  if (aovs.count("light"))
    for (int g = 0; g < kLightGroupCount; ++g)
      for (int c = 0; c < 3; ++c)
        exr.extra.push_back({std::string(kLightGroupNames[g]) + "." + "RGB"[c], b.groups, colour,
                             kLightGroupChannels, g * 3 + c});
  if (aovs.count("vector")) vec("vector", "XYZW", b.vector, ChannelType::Float, kMotionVectorChannels);
  if (aovs.count("velocity")) vec("velocity", "XYZ", b.velocity, ChannelType::Float, kVelocityChannels);
  if (b.wireframe && !b.wireframe->empty()) exr.extra.push_back({"wireframe.A", b.wireframe, colour});
  if (aovs.count("halves"))
    for (int h = 0; h < 2; ++h)
      for (int k = 0; k < kDenoiseChannelsPerHalf; ++k) {
        const std::string name = denoise_channel_name(h, k);
        if (k < 3)
          exr.extra.push_back({name, b.halves, ChannelType::Float, kHalfChannels, h * 3 + k});
        else
          exr.extra.push_back({name, &b.data->halves, ChannelType::Float, 2 * kDenoiseFeatures,
                               h * kDenoiseFeatures + k - 3});
      }
}

}  // namespace penumbra
