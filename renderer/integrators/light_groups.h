// Light groups: the path tracer's beauty split into five RGB parts for compositing, their one
// memory layout (kLightGroupCount groups x 3 channels = kLightGroupChannels floats per pixel,
// in kLightGroupNames order) and the one place a contribution is added to the pixel's
// radiance and to its group.
#pragma once

#include <cstddef>

#include "renderer/core/math.h"
#include "renderer/materials/bsdf.h"

namespace penumbra {

inline constexpr int kLightGroupCount = 5;
/// Floats (or doubles) per pixel of a light-group buffer: RGB of each group.
inline constexpr int kLightGroupChannels = kLightGroupCount * 3;
/// Names of the light groups in buffer order.
inline constexpr const char* kLightGroupNames[kLightGroupCount] = {
    "emission", "diffuse_direct", "diffuse_indirect", "specular_direct", "specular_indirect"};

/// The beauty split; the five sum to path_radiance's value.
/// emission: what the camera sees directly (emitters, the environment, unlit surfaces);
/// direct: light arriving at the first hit straight from a light; indirect: light arriving at
/// the first hit after further bounces; diffuse and specular split by the first hit's BRDF
/// terms (thin transmission counts as specular).
struct LightGroups {
  Vec3f emission{0, 0, 0};
  Vec3f diffuse_direct{0, 0, 0}, diffuse_indirect{0, 0, 0};
  Vec3f specular_direct{0, 0, 0}, specular_indirect{0, 0, 0};
};

/// Adds the groups to a buffer of kLightGroupChannels sums, in buffer order.
inline void add_light_groups(const LightGroups& lg, double* sums) {
  const Vec3f parts[kLightGroupCount] = {lg.emission, lg.diffuse_direct, lg.diffuse_indirect,
                                         lg.specular_direct, lg.specular_indirect};
  for (int g = 0; g < kLightGroupCount; ++g)
    for (int c = 0; c < 3; ++c) sums[g * 3 + c] += parts[g][c];
}

/// Per-channel d / (d + s), 0 where both vanish: the diffuse share of a BRDF value.
inline Vec3f diffuse_share(Vec3f d, Vec3f s) {
  Vec3f r;
  for (int c = 0; c < 3; ++c) r[c] = d[c] + s[c] > 0 ? d[c] / (d[c] + s[c]) : 0.0f;
  return r;
}

/// The diffuse share of the BRDF's value towards wi (the light-group split of a direction).
inline Vec3f diffuse_share(const GltfBsdf& brdf, Vec3f wo, Vec3f wi) {
  Vec3f d, sp;
  bsdf_eval_parts(brdf, wo, wi, d, sp);
  return diffuse_share(d, sp);
}

/// A path's radiance and, optionally, its light groups. Every contribution goes through add().
struct PathRadiance {
  Vec3f radiance{0, 0, 0};
  float clamp_indirect = 0;       ///< PathConfig::clamp_indirect
  LightGroups* groups = nullptr;  ///< null: no split
  Vec3f share0{0, 0, 0};          ///< diffuse share of the direction sampled at hit 0

  /// Adds light reaching surface hit `vertex` (-1 = the camera itself). Non-finite
  /// contributions are dropped; indirect ones (vertex >= 1) clamped when clamp_indirect > 0.
  /// `share`: the diffuse share of a light sample at hit 0 (else share0 is used).
  void add(Vec3f c, int vertex, const Vec3f* share = nullptr) {
    if (!is_finite(c)) return;
    if (clamp_indirect > 0 && vertex >= 1) {
      const float m = max_component(c);
      if (m > clamp_indirect) c *= clamp_indirect / m;
    }
    radiance += c;
    if (!groups) return;
    if (vertex < 0) {
      groups->emission += c;
      return;
    }
    const Vec3f d = c * (share ? *share : share0);
    const Vec3f sp = c - d;
    if (vertex == 0) {
      groups->diffuse_direct += d;
      groups->specular_direct += sp;
    } else {
      groups->diffuse_indirect += d;
      groups->specular_indirect += sp;
    }
  }
};

}  // namespace penumbra
