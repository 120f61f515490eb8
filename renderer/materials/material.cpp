// Material evaluation: textures, factors, vertex colours, normal mapping, procedural textures,
// coverage.
#include "renderer/materials/material.h"

#include <algorithm>
#include <cmath>

namespace penumbra {

namespace {
// KHR_texture_transform's affine map applied to a point (with offset) or a derivative.
Vec2f transform_uv(const TextureRef& ref, Vec2f uv, bool offset) {
  const auto& m = ref.m;
  return {m[0][0] * uv.x + m[0][1] * uv.y + (offset ? m[0][2] : 0.0f),
          m[1][0] * uv.x + m[1][1] * uv.y + (offset ? m[1][2] : 0.0f)};
}
// Surface gradients of u and v of UV set `set` at si (world space, in the tangent plane): for a
// triangle from its vertices' UVs, for a shape by differences of its UV map along two tangents.
// False where the map is degenerate.
bool uv_surface_gradients(const Scene& scene, const SurfaceInteraction& si, int set, Vec3f& gu, Vec3f& gv) {
  const Instance& inst = scene.instances[si.instance];
  if (si.shape >= 0) {
    const Shape& shape = scene.shapes[size_t(si.shape)].shape;
    const Vec3f t1 = normalize(std::fabs(si.ng.x) < 0.9f ? cross(si.ng, {1, 0, 0}) : cross(si.ng, {0, 1, 0}));
    const Vec3f t2 = cross(si.ng, t1);
    // A step of 1e-4 of the shape's world-space size.
    Bounds3f b = shape_bounds(shape);
    if (!inst.identity && !b.empty()) b = transform_bounds(inst.to_world, b);
    const float h = 1e-4f * (b.empty() ? 1.0f : std::max(max_component(b.extent()), 1e-12f));
    const auto uv_at = [&](Vec3f p) {
      return shape_surface(shape, inst.identity ? p : apply_point(inst.to_object, p), h).uv;
    };
    const Vec2f u0 = uv_at(si.p), u1 = uv_at(si.p + t1 * h), u2 = uv_at(si.p + t2 * h);
    const Vec2f d1 = shape_uv_delta(shape, u0, u1), d2 = shape_uv_delta(shape, u0, u2);
    gu = (t1 * d1.x + t2 * d2.x) / h;
    gv = (t1 * d1.y + t2 * d2.y) / h;
    return is_finite(gu) && is_finite(gv);
  }
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const auto& uvs = set == 1 ? mesh.uvs1 : mesh.uvs;
  if (uvs.empty()) return false;
  const WorldTriangle& tri = si.tri;
  const Vec3f e1 = tri.p[1] - tri.p[0], e2 = tri.p[2] - tri.p[0];
  const float a11 = dot(e1, e1), a12 = dot(e1, e2), a22 = dot(e2, e2);
  const float det = a11 * a22 - a12 * a12;
  if (!(det > 0) || !std::isfinite(det)) return false;
  const Vec2f w0 = uvs[tri.index[0]], w1 = uvs[tri.index[1]], w2 = uvs[tri.index[2]];
  // The gradient of a linear function with differences (d1, d2) along (e1, e2), in their plane.
  auto gradient = [&](float d1, float d2) {
    return e1 * ((a22 * d1 - a12 * d2) / det) + e2 * ((a11 * d2 - a12 * d1) / det);
  };
  gu = gradient(w1.x - w0.x, w2.x - w0.x);
  gv = gradient(w1.y - w0.y, w2.y - w0.y);
  return true;
}

// A procedural texture's point at si in pattern space and the pixel footprint there.
struct PatternPoint {
  Vec3f q;
  float footprint = 0;
};

// The world -> object map of the surface at si: its instance's, or for a mesh moved into world
// space its node's; nullptr for the identity.
const Affine3f* object_map(const Scene& scene, const SurfaceInteraction& si) {
  const Instance& inst = scene.instances[si.instance];
  if (!inst.identity) return &inst.to_object;
  if (si.shape >= 0) return nullptr;
  const Affine3f& m = scene.meshes[size_t(inst.mesh)].object_from_world;
  return is_identity(m) ? nullptr : &m;
}

PatternPoint pattern_point(const Scene& scene, const ProceduralTexture& tex, const SurfaceInteraction& si) {
  Vec3f x = si.p, dx = si.dpdx, dy = si.dpdy;
  const Affine3f* to_object = tex.space == ProceduralSpace::Object ? object_map(scene, si) : nullptr;
  if (to_object) {
    x = apply_point(*to_object, x);
    dx = apply_vector(*to_object, dx);
    dy = apply_vector(*to_object, dy);
  } else if (tex.space == ProceduralSpace::Uv) {
    const int set = tex.texcoord == 1 ? 1 : 0;
    x = {si.uv[set].x, si.uv[set].y, 0};
    dx = {si.duvdx[set].x, si.duvdx[set].y, 0};
    dy = {si.duvdy[set].x, si.duvdy[set].y, 0};
  }
  PatternPoint pp;
  pp.q = apply_point(tex.mapping, x);
  pp.footprint = std::max(length(apply_vector(tex.mapping, dx)), length(apply_vector(tex.mapping, dy)));
  return pp;
}

// The world-space gradient of the pattern along the surface at si, from its pattern-space
// gradient g (chain rule through the mapping and the space).
Vec3f surface_gradient(const Scene& scene, const ProceduralTexture& tex, const SurfaceInteraction& si,
                       Vec3f g) {
  const Vec3f gx = apply_normal(tex.mapping, g);  // mapping^T g: gradient in the texture's space
  Vec3f gw = gx;
  if (tex.space == ProceduralSpace::Uv) {
    Vec3f gu, gv;
    if (!uv_surface_gradients(scene, si, tex.texcoord == 1 ? 1 : 0, gu, gv)) return {};
    gw = gu * gx.x + gv * gx.y;
  } else if (tex.space == ProceduralSpace::Object) {
    if (const Affine3f* to_object = object_map(scene, si)) gw = apply_normal(*to_object, gx);
  }
  return gw - si.ng * dot(gw, si.ng);
}

float drive(const ScalarDrive& d, float own, float t) {
  const float v = eval_drive(d, t);
  return d.compose == Compose::Replace ? v : own * v;
}

// Applies a material's procedural texture to the evaluated inputs: base colour through the ramp,
// the scalar drives, and the bump of height bump_height x t (pbrt's bump mapping with the
// pattern's analytic gradient instead of finite differences).
void apply_procedural(const Scene& scene, const Material& mat, const SurfaceInteraction& si,
                      MaterialPoint& mp) {
  const ProceduralTexture& tex = scene.procedurals[size_t(mat.procedural)];
  const PatternPoint pp = pattern_point(scene, tex, si);
  const PatternSample s = eval_pattern(tex, pp.q, pp.footprint);
  if (tex.drives_base_color) {
    const Vec3f c = eval_ramp(tex.base_color, s.t);
    mp.base_color = tex.base_color_compose == Compose::Replace ? c : mp.base_color * c;
  }
  if (tex.roughness.enabled) mp.roughness = std::clamp(drive(tex.roughness, mp.roughness, s.t), 0.0f, 1.0f);
  if (tex.metallic.enabled) mp.metallic = std::clamp(drive(tex.metallic, mp.metallic, s.t), 0.0f, 1.0f);
  if (tex.emission_strength.enabled) {
    const float strength = std::max(eval_drive(tex.emission_strength, s.t), 0.0f);
    mp.emissive = (tex.emission_strength.compose == Compose::Replace ? mat.emissive : mp.emissive) * strength;
  }
  if (tex.bump_height != 0) {
    // The surface displaced by h t along its outward normal has normal n - grad(h t); seen from
    // behind, the outward normal is -ns.
    const Vec3f g = surface_gradient(scene, tex, si, s.grad) * tex.bump_height;
    const Vec3f n = normalize(mp.ns - g * (si.back_face ? -1.0f : 1.0f));
    if (is_finite(n) && dot(n, si.ng) > 0) mp.ns = n;
  }
}

}  // namespace

const Material& default_material() {
  static const Material m{};
  return m;
}

Vec4f eval_texture(const Scene& scene, const TextureRef& ref, const SurfaceInteraction& si) {
  if (ref.texture < 0) return {1, 1, 1, 1};
  const Texture& tex = scene.textures[size_t(ref.texture)];
  const int set = ref.texcoord == 1 ? 1 : 0;
  return sample_texture(
      tex, transform_uv(ref, si.uv[set], true),
      texture_lod(tex, transform_uv(ref, si.duvdx[set], false), transform_uv(ref, si.duvdy[set], false)));
}

namespace {
// Coverage from the base colour texture's alpha bc_a (see MaterialPoint::alpha).
float coverage(const Material& mat, const SurfaceInteraction& si, float bc_a) {
  if (mat.alpha_mode == AlphaMode::Opaque) return 1;
  const float alpha = mat.alpha * bc_a * si.color.w;
  if (mat.alpha_mode == AlphaMode::Mask) return alpha >= mat.alpha_cutoff ? 1.0f : 0.0f;
  return alpha;
}

Vec3f emission(const Scene& scene, const Material& mat, const SurfaceInteraction& si) {
  const Vec4f em = eval_texture(scene, mat.emissive_tex, si);
  return mat.emissive * Vec3f{em.x, em.y, em.z};
}
}  // namespace

Vec3f eval_emission(const Scene& scene, const SurfaceInteraction& si) {
  const Material& mat = material_of(scene, si.material);
  if (mat.procedural >= 0) {  // a procedural texture may drive the emission
    const MaterialPoint mp = eval_material(scene, si, false);
    return mp.emissive * mp.alpha;
  }
  const Vec3f emissive = emission(scene, mat, si);
  if (mat.alpha_mode == AlphaMode::Opaque) return emissive;  // alpha 1
  return emissive * coverage(mat, si, eval_texture(scene, mat.base_color_tex, si).w);
}

namespace {

// The surface's tangent frame as authored (t, b) around shading normal n; false without
// tangents. si.ns was flipped for back faces, so the tangent and bitangent flip with it (as the
// Khronos sample viewer does).
bool tangent_frame(const SurfaceInteraction& si, Vec3f n, Vec3f& t, Vec3f& b) {
  if (si.tangent.w == 0) return false;
  const float side = si.back_face ? -1.0f : 1.0f;
  t = Vec3f{si.tangent.x, si.tangent.y, si.tangent.z} * side;
  t = t - n * dot(n, t);
  if (!(dot(t, t) > 0)) return false;
  t = normalize(t);
  b = cross(n, t) * (si.tangent.w * side);
  return true;
}

// Normal n perturbed by tangent-space normal map `ref` (X and Y scaled by `scale`); n where
// there is no map, no tangent frame, or the result faces away from the geometric normal.
Vec3f normal_mapped(const Scene& scene, const SurfaceInteraction& si, const TextureRef& ref, float scale,
                    Vec3f n) {
  Vec3f t, b;
  if (ref.texture < 0 || !tangent_frame(si, n, t, b)) return n;
  const Vec4f tn = eval_texture(scene, ref, si);
  const Vec3f m{(tn.x * 2 - 1) * scale, (tn.y * 2 - 1) * scale, tn.z * 2 - 1};
  const Vec3f out = normalize(t * m.x + b * m.y + n * m.z);
  return is_finite(out) && dot(out, si.ng) > 0 ? out : n;
}

float texture_channel(const Scene& scene, const TextureRef& ref, const SurfaceInteraction& si, int c) {
  if (ref.texture < 0) return 1;
  const Vec4f v = eval_texture(scene, ref, si);
  return c == 0 ? v.x : (c == 1 ? v.y : (c == 2 ? v.z : v.w));
}

Vec3f texture_rgb(const Scene& scene, const TextureRef& ref, const SurfaceInteraction& si) {
  if (ref.texture < 0) return {1, 1, 1};
  const Vec4f v = eval_texture(scene, ref, si);
  return {v.x, v.y, v.z};
}

// The anisotropy strength and direction (KHR_materials_anisotropy): the texture's RG direction
// in tangent space rotated by the material's rotation, strength x texture B.
void eval_anisotropy(const Scene& scene, const Material& mat, const SurfaceInteraction& si,
                     MaterialPoint& mp) {
  Vec2f dir{1, 0};
  float strength = mat.anisotropy;
  if (mat.anisotropy_tex.texture >= 0) {
    const Vec4f a = eval_texture(scene, mat.anisotropy_tex, si);
    const Vec2f d{a.x * 2 - 1, a.y * 2 - 1};
    const float len = std::sqrt(d.x * d.x + d.y * d.y);
    if (len > 0) dir = {d.x / len, d.y / len};
    strength *= a.z;
  }
  const float c = std::cos(mat.anisotropy_rotation), s = std::sin(mat.anisotropy_rotation);
  const Vec2f r{c * dir.x - s * dir.y, s * dir.x + c * dir.y};
  Vec3f t, b;
  if (!tangent_frame(si, mp.ns, t, b)) make_frame(mp.ns, t, b);
  const Vec3f a = t * r.x + b * r.y;
  const Vec3f at = a - mp.ns * dot(mp.ns, a);
  if (!(dot(at, at) > 1e-12f)) return;
  mp.tangent = normalize(at);
  mp.anisotropy = std::clamp(strength, 0.0f, 1.0f);
}

// The KHR extensions' layers and lobes at si (after the base normal is known).
void eval_extensions(const Scene& scene, const Material& mat, const SurfaceInteraction& si,
                     MaterialPoint& mp) {
  mp.ior = mat.ior;
  mp.volume = mat.volume && (mat.transmission > 0 || mat.diffuse_transmission > 0);
  if (mp.volume && std::isfinite(mat.attenuation_distance) && mat.attenuation_distance > 0)
    for (int c = 0; c < 3; ++c)
      mp.sigma_a[c] = -std::log(std::max(mat.attenuation_color[c], 1e-6f)) / mat.attenuation_distance;
  mp.dispersion = mat.dispersion;
  if (mat.clearcoat > 0) {
    mp.clearcoat = std::clamp(mat.clearcoat * texture_channel(scene, mat.clearcoat_tex, si, 0), 0.0f, 1.0f);
    mp.clearcoat_roughness = std::clamp(
        mat.clearcoat_roughness * texture_channel(scene, mat.clearcoat_roughness_tex, si, 1), 0.0f, 1.0f);
    mp.ns_coat = normal_mapped(scene, si, mat.clearcoat_normal_tex, mat.clearcoat_normal_scale, si.ns);
  }
  if (max_component(mat.sheen_color) > 0) {
    mp.sheen_color = mat.sheen_color * texture_rgb(scene, mat.sheen_color_tex, si);
    mp.sheen_roughness =
        std::clamp(mat.sheen_roughness * texture_channel(scene, mat.sheen_roughness_tex, si, 3), 0.0f, 1.0f);
  }
  if (mat.anisotropy > 0) eval_anisotropy(scene, mat, si, mp);
  if (mat.iridescence > 0) {
    mp.iridescence =
        std::clamp(mat.iridescence * texture_channel(scene, mat.iridescence_tex, si, 0), 0.0f, 1.0f);
    mp.iridescence_ior = mat.iridescence_ior;
    const float w = mat.iridescence_thickness_tex.texture >= 0
                        ? texture_channel(scene, mat.iridescence_thickness_tex, si, 1)
                        : 1.0f;
    mp.iridescence_thickness =
        mat.iridescence_thickness_min + (mat.iridescence_thickness_max - mat.iridescence_thickness_min) * w;
  }
  if (mat.diffuse_transmission > 0) {
    mp.diffuse_transmission = std::clamp(
        mat.diffuse_transmission * texture_channel(scene, mat.diffuse_transmission_tex, si, 3), 0.0f, 1.0f);
    mp.diffuse_transmission_color =
        mat.diffuse_transmission_color * texture_rgb(scene, mat.diffuse_transmission_color_tex, si);
  }
}

}  // namespace

MaterialPoint eval_material(const Scene& scene, const SurfaceInteraction& si, bool with_occlusion) {
  const Material& mat = material_of(scene, si.material);
  MaterialPoint mp;
  mp.unlit = mat.unlit;
  const Vec4f bc = eval_texture(scene, mat.base_color_tex, si);
  mp.base_color = mat.base_color * Vec3f{bc.x, bc.y, bc.z} * Vec3f{si.color.x, si.color.y, si.color.z};
  mp.alpha = coverage(mat, si, bc.w);
  const Vec4f mr = eval_texture(scene, mat.metallic_roughness_tex, si);
  mp.metallic = std::clamp(mat.metallic * mr.z, 0.0f, 1.0f);
  mp.roughness = std::clamp(mat.roughness * mr.y, 0.0f, 1.0f);
  mp.emissive = emission(scene, mat, si);
  mp.f0 = ior_to_f0(mat.ior);
  mp.specular = mat.specular * texture_channel(scene, mat.specular_tex, si, 3);
  mp.specular_color = mat.specular_color * texture_rgb(scene, mat.specular_color_tex, si);
  mp.transmission = mat.transmission;
  if (mat.transmission > 0 && mat.transmission_tex.texture >= 0)
    mp.transmission *= eval_texture(scene, mat.transmission_tex, si).x;
  if (with_occlusion && mat.occlusion_tex.texture >= 0)
    mp.occlusion = 1 + mat.occlusion_strength * (eval_texture(scene, mat.occlusion_tex, si).x - 1);
  mp.ns = normal_mapped(scene, si, mat.normal_tex, mat.normal_scale, si.ns);
  mp.ns_coat = mp.ns;
  if (mat.procedural >= 0) apply_procedural(scene, mat, si, mp);
  eval_extensions(scene, mat, si, mp);
  return mp;
}

float dispersion_ior(float ior, float dispersion, int channel) {
  if (channel < 0 || channel > 2 || !(dispersion > 0) || !(ior > 1)) return ior;
  constexpr float kLambda[3] = {610, 550, 465};
  const float abbe = 20 / dispersion;
  const float l = kLambda[channel];
  return std::max(1.0f, ior + (ior - 1) / abbe * (523655 / (l * l) - 1.5168f));
}

GltfBsdf make_bsdf(const MaterialPoint& mp, bool back_face, int channel) {
  GltfBsdf b;
  b.base_color = mp.base_color;
  b.metallic = mp.metallic;
  b.roughness = mp.roughness;
  b.n = mp.ns;
  b.f0 = mp.f0;
  b.specular = mp.specular;
  b.specular_color = mp.specular_color;
  b.transmission = std::clamp(mp.transmission, 0.0f, 1.0f);
  if (mp.volume) {
    const float ior = std::max(1.0f, dispersion_ior(mp.ior, mp.dispersion, channel));
    b.eta = back_face ? 1 / ior : ior;
    b.volume = ior != 1;  // index 1 does not bend light: the thin lobe passes it straight through
  }
  if (mp.anisotropy > 0) {
    b.anisotropy = mp.anisotropy;
    b.t = mp.tangent;
  }
  b.iridescence = mp.iridescence;
  b.iridescence_ior = mp.iridescence_ior;
  b.iridescence_thickness = mp.iridescence_thickness;
  b.sheen_color = mp.sheen_color;
  b.sheen_roughness = mp.sheen_roughness;
  b.clearcoat = mp.clearcoat;
  b.clearcoat_roughness = mp.clearcoat_roughness;
  if (mp.clearcoat > 0) b.clearcoat_n = mp.ns_coat;
  b.diffuse_transmission = mp.diffuse_transmission;
  b.diffuse_transmission_color = mp.diffuse_transmission_color;
  return b;
}

float eval_alpha(const Scene& scene, uint32_t instance, uint32_t prim, float u, float v) {
  const Instance& inst = scene.instances[instance];
  if (inst.shape >= 0) {
    const Material& mat = material_of(scene, scene.shapes[size_t(inst.shape)].material);
    if (mat.alpha_mode == AlphaMode::Opaque) return 1;
    if (mat.alpha_mode == AlphaMode::Mask) return mat.alpha >= mat.alpha_cutoff ? 1.0f : 0.0f;
    return std::clamp(mat.alpha, 0.0f, 1.0f);
  }
  const Mesh& mesh = scene.meshes[size_t(inst.mesh)];
  const Material& mat = material_of(scene, mesh.material);
  if (mat.alpha_mode == AlphaMode::Opaque) return 1;
  const size_t base = size_t(prim) * 3;
  const uint32_t i0 = mesh.indices[base], i1 = mesh.indices[base + 1], i2 = mesh.indices[base + 2];
  const float w = 1 - u - v;
  float alpha = mat.alpha;
  if (!mesh.colors.empty()) alpha *= mesh.colors[i0].w * w + mesh.colors[i1].w * u + mesh.colors[i2].w * v;
  const TextureRef& ref = mat.base_color_tex;
  if (ref.texture >= 0) {
    const auto& uvs = ref.texcoord == 1 ? mesh.uvs1 : mesh.uvs;
    Vec2f uv;
    if (!uvs.empty())
      uv = {uvs[i0].x * w + uvs[i1].x * u + uvs[i2].x * v, uvs[i0].y * w + uvs[i1].y * u + uvs[i2].y * v};
    alpha *= sample_texture(scene.textures[size_t(ref.texture)], transform_uv(ref, uv, true), 0).w;
  }
  if (mat.alpha_mode == AlphaMode::Mask) return alpha >= mat.alpha_cutoff ? 1.0f : 0.0f;
  return std::clamp(alpha, 0.0f, 1.0f);
}

}  // namespace penumbra
