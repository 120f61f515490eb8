// Punctual light evaluation (KHR_lights_punctual, "Range Property" and "Inner and Outer Cone
// Angles" sections of the extension's README).
#include "renderer/lights/punctual.h"

namespace penumbra {

float spot_attenuation(const Light& light, float cos_angle) {
  const float cos_outer = std::cos(light.outer_cone), cos_inner = std::cos(light.inner_cone);
  const float scale = 1.0f / std::max(0.001f, cos_inner - cos_outer);
  const float offset = -cos_outer * scale;
  const float a = std::clamp(cos_angle * scale + offset, 0.0f, 1.0f);
  return a * a;
}

bool sample_light(const Light& light, Vec3f p, LightSample& out) {
  const Vec3f power = light.color * light.intensity;
  if (light.type == LightType::Directional) {
    out.wi = -light.direction;
    out.distance = kInfinity;
    out.irradiance = power;
    return max_component(power) > 0;
  }
  const Vec3f to_light = light.position - p;
  const float d2 = dot(to_light, to_light);
  if (!(d2 > 0)) return false;
  const float d = std::sqrt(d2);
  out.wi = to_light / d;
  out.distance = d;
  float falloff = 1.0f / d2;
  if (std::isfinite(light.range)) {
    const float r = d / light.range, r4 = r * r * r * r;
    falloff *= std::clamp(1.0f - r4, 0.0f, 1.0f);
  }
  if (light.type == LightType::Spot) falloff *= spot_attenuation(light, dot(light.direction, -out.wi));
  out.irradiance = power * falloff;
  return falloff > 0 && max_component(power) > 0;
}

}  // namespace penumbra
