// Material evaluation: textures, factors, vertex colours, normal mapping, coverage.
#include "renderer/materials/material.h"

namespace penumbra {

namespace {
// KHR_texture_transform's affine map applied to a point (with offset) or a derivative.
Vec2f transform_uv(const TextureRef& ref, Vec2f uv, bool offset) {
  const auto& m = ref.m;
  return {m[0][0] * uv.x + m[0][1] * uv.y + (offset ? m[0][2] : 0.0f),
          m[1][0] * uv.x + m[1][1] * uv.y + (offset ? m[1][2] : 0.0f)};
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

MaterialPoint eval_material(const Scene& scene, const SurfaceInteraction& si) {
  const Material& mat = material_of(scene, si.material);
  MaterialPoint mp;
  mp.unlit = mat.unlit;
  const Vec4f bc = eval_texture(scene, mat.base_color_tex, si);
  mp.base_color = mat.base_color * Vec3f{bc.x, bc.y, bc.z} * Vec3f{si.color.x, si.color.y, si.color.z};
  mp.alpha = mat.alpha_mode == AlphaMode::Opaque ? 1.0f : mat.alpha * bc.w * si.color.w;
  if (mat.alpha_mode == AlphaMode::Mask) mp.alpha = mp.alpha >= mat.alpha_cutoff ? 1.0f : 0.0f;
  const Vec4f mr = eval_texture(scene, mat.metallic_roughness_tex, si);
  mp.metallic = std::clamp(mat.metallic * mr.z, 0.0f, 1.0f);
  mp.roughness = std::clamp(mat.roughness * mr.y, 0.0f, 1.0f);
  const Vec4f em = eval_texture(scene, mat.emissive_tex, si);
  mp.emissive = mat.emissive * Vec3f{em.x, em.y, em.z};
  mp.f0 = ior_to_f0(mat.ior);
  mp.specular = mat.specular;
  mp.transmission = mat.transmission;
  if (mat.transmission > 0 && mat.transmission_tex.texture >= 0)
    mp.transmission *= eval_texture(scene, mat.transmission_tex, si).x;
  if (mat.occlusion_tex.texture >= 0)
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
