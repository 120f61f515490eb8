// Evaluation of KHR_lights_punctual lights at a shading point, following the extension's
// recommended falloff: inverse square with the smooth range window
// max(min(1 - (d/range)^4, 1), 0) / d^2, and the spot cone's squared linear ramp in cos angle.
#pragma once

#include "renderer/scene/scene.h"

namespace penumbra {

/// What reaches a point from one punctual light.
struct LightSample {
  Vec3f wi;          ///< unit direction from the point towards the light
  float distance;    ///< to the light (kInfinity for directional)
  Vec3f irradiance;  ///< colour x intensity x falloff: irradiance on a surface facing the light
};

/// Returns false when the light contributes nothing at p (outside range or cone, zero power).
bool sample_light(const Light& light, Vec3f p, LightSample& out);

/// The spot cone attenuation for cos of the angle to the spot axis (spec formula).
float spot_attenuation(const Light& light, float cos_angle);

}  // namespace penumbra
