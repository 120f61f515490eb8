// The sheen lobe of KHR_materials_sheen: the "Charlie" distribution and the visibility term of
// Estevez and Kulla, "Production Friendly Microfacet Sheen BRDF" (Sony Pictures Imageworks,
// 2017), and the lobe's directional albedo E(cos) used to scale the layers below it
// (KHR_materials_sheen, "Albedo scaling"). Local frame: the normal is +z.
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// Smallest sheen roughness used: below it the Charlie lobe is a spike at grazing angles that
/// neither quadrature nor sampling resolve.
inline constexpr float kMinSheenRoughness = 0.07f;

/// Charlie distribution D(h) = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi), a = roughness^2 with the
/// roughness clamped to [kMinSheenRoughness, 1]; 0 for h.z <= 0. int D cos = 1.
float charlie_d(Vec3f h, float roughness);
/// Estevez-Kulla visibility 1 / ((1 + Lambda(v) + Lambda(l)) 4 n.v n.l), clamped to [0, 1].
float sheen_visibility(float n_dot_l, float n_dot_v, float roughness);
/// The white sheen BRDF D V at (v, l), both above the surface (else 0).
float sheen_brdf(Vec3f v, Vec3f l, float roughness);
/// Directional albedo int sheen_brdf(v, l) cos(l) dl at cos(theta_v) = n_dot_v, from a table
/// over (cos, roughness) computed by quadrature on first use (thread-safe, no allocation).
float sheen_albedo(float n_dot_v, float roughness);

}  // namespace penumbra
