// Microfacet and Fresnel building blocks of the glTF BSDF, in a local frame where the normal is
// +z and the x axis is the anisotropy direction: the anisotropic Trowbridge-Reitz (GGX)
// distribution with Smith's height-correlated masking-shadowing (Heitz, "Understanding the
// Masking-Shadowing Function in Microfacet-Based BRDFs", JCGT 3(2), 2014), sampling of its
// visible normals (Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018),
// Schlick's and the exact unpolarised dielectric Fresnel, and refraction by Snell's law.
// Pure functions of their arguments: no allocation, no state.
#pragma once

#include "renderer/core/math.h"

namespace penumbra {

/// Smallest alpha used: roughness 0 would make D a Dirac delta (below 1e-3 the lobe is
/// narrower than float directions resolve anyway).
inline constexpr float kMinGgxAlpha = 1e-3f;

/// Anisotropic GGX roughness: alpha along the local x (tangent) and y (bitangent) axes.
struct GgxAlpha {
  float x = 1, y = 1;
};

/// D(h) = 1 / (pi ax ay (hx^2/ax^2 + hy^2/ay^2 + hz^2)^2); 0 for h.z <= 0. int D cos = 1.
float ggx_d(Vec3f h, GgxAlpha a);
/// Smith's Lambda(v) = (sqrt(1 + (ax^2 vx^2 + ay^2 vy^2) / vz^2) - 1) / 2.
float smith_lambda(Vec3f v, GgxAlpha a);
/// Masking G1(v) = 1 / (1 + Lambda(v)); 0 for v.z <= 0.
float smith_g1(Vec3f v, GgxAlpha a);
/// Height-correlated masking-shadowing G2(v, l) = 1 / (1 + Lambda(v) + Lambda(l)) (either side).
float smith_g2(Vec3f v, Vec3f l, GgxAlpha a);
/// A visible normal for view v (local, v.z > 0) from u in [0,1)^2; density G1(v) max(0,v.h) D(h) / v.z.
Vec3f sample_ggx_vndf(Vec3f v, GgxAlpha a, Vec2f u);

/// The isotropic forms (alpha along both axes).
inline float ggx_d(Vec3f h, float alpha) {
  return ggx_d(h, GgxAlpha{alpha, alpha});
}
inline float smith_g1(Vec3f v, float alpha) {
  return smith_g1(v, GgxAlpha{alpha, alpha});
}
inline Vec3f sample_ggx_vndf(Vec3f v, float alpha, Vec2f u) {
  return sample_ggx_vndf(v, GgxAlpha{alpha, alpha}, u);
}
/// Height-correlated visibility V = G2 / (4 |n.l| |n.v|) (Heitz 2014, eq. 99), isotropic.
float smith_visibility(float n_dot_l, float n_dot_v, float alpha);

/// Schlick's approximation f0 + (1 - f0)(1 - cos)^5, per channel.
Vec3f schlick(Vec3f f0, float cos_theta);
inline float schlick(float f0, float cos_theta) {
  return schlick(Vec3f{f0, f0, f0}, cos_theta).x;
}

/// Exact Fresnel reflectance of unpolarised light at a smooth dielectric interface, arriving
/// with cos_i = |cos| of the angle to the normal from the side of index 1 into relative index
/// eta = n_other / n_this (> 0). 1 beyond the critical angle (total internal reflection).
float fresnel_dielectric(float cos_i, float eta);

/// The refracted direction of unit v (pointing away from the surface, v.m > 0) through the
/// microfacet normal m into relative index eta; false on total internal reflection.
bool refract(Vec3f v, Vec3f m, float eta, Vec3f& out);

/// An orthonormal basis (t, b, n) around unit n (Duff et al., "Building an Orthonormal Basis,
/// Revisited", JCGT 6(1), 2017).
void make_frame(Vec3f n, Vec3f& t, Vec3f& b);

/// Cosine-weighted direction in the local frame (+z up) from u in [0,1)^2 (Malley's method).
Vec3f sample_cosine_hemisphere(Vec2f u);

}  // namespace penumbra
