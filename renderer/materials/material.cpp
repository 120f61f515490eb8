// Material evaluation: textures, factors, vertex colours, normal mapping, procedural textures,
// coverage.
#include "renderer/materials/material.h"

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
  mp.specular = mat.specular;
  mp.transmission = mat.transmission;
  if (mat.transmission > 0 && mat.transmission_tex.texture >= 0)
    mp.transmission *= eval_texture(scene, mat.transmission_tex, si).x;
  if (with_occlusion && mat.occlusion_tex.texture >= 0)
    mp.occlusion = 1 + mat.occlusion_strength * (eval_texture(scene, mat.occlusion_tex, si).x - 1);
  mp.ns = si.ns;
  if (mat.normal_tex.texture >= 0 && si.tangent.w != 0) {
    const Vec4f tn = eval_texture(scene, mat.normal_tex, si);
    const Vec3f m{(tn.x * 2 - 1) * mat.normal_scale, (tn.y * 2 - 1) * mat.normal_scale, tn.z * 2 - 1};
    // Tangent frame of the surface as authored; si.ns was flipped for back faces, so flip
    // the tangent and bitangent with it (as the Khronos sample viewer does).
    const float side = si.back_face ? -1.0f : 1.0f;
    Vec3f t = Vec3f{si.tangent.x, si.tangent.y, si.tangent.z} * side;
    t = normalize(t - si.ns * dot(si.ns, t));
    const Vec3f b = cross(si.ns, t) * (si.tangent.w * side);
    const Vec3f n = normalize(t * m.x + b * m.y + si.ns * m.z);
    if (dot(t, t) > 0 && dot(n, si.ng) > 0) mp.ns = n;
  }
  if (mat.procedural >= 0) apply_procedural(scene, mat, si, mp);
  return mp;
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
