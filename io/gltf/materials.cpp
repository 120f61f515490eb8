// Materials: factors, alpha modes, texture infos (KHR_texture_transform) and the KHR material
// extensions, each converted into the renderer's Material.
#include "io/gltf/materials.h"

#include <tiny_gltf.h>

#include <cmath>

namespace penumbra::gltf {

std::vector<std::string> material_extensions() {
  return {"KHR_materials_emissive_strength",
          "KHR_materials_unlit",
          "KHR_materials_ior",
          "KHR_materials_specular",
          "KHR_materials_transmission",
          "KHR_materials_volume",
          "KHR_materials_clearcoat",
          "KHR_materials_sheen",
          "KHR_materials_anisotropy",
          "KHR_materials_iridescence",
          "KHR_materials_dispersion",
          "KHR_materials_diffuse_transmission",
          "KHR_texture_transform"};
}

namespace {

double finite_or_fail(const GltfContext& ctx, double v, const std::string& where) {
  if (!std::isfinite(v)) ctx.fail(where, "value is not finite");
  return v;
}

// KHR_texture_transform: uv' = T R S uv (spec: offset, rotation counter-clockwise, scale) into
// ref.m; its texCoord, if present, replaces `texcoord`. A member of the wrong type is an error
// naming it.
void read_texture_transform(const GltfContext& ctx, const tinygltf::Value& x, const std::string& where,
                            TextureRef& ref, int& texcoord) {
  const std::string xw = where + ".extensions.KHR_texture_transform";
  double off[2] = {0, 0}, sc[2] = {1, 1}, rot = 0;
  auto read_pair = [&](const char* key, double* v) {
    const auto& a = x.Get(key);
    if (a.Type() == tinygltf::NULL_TYPE) return;
    if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber())
      ctx.fail(xw + "." + key, "must be an array of 2 numbers");
    v[0] = a.Get(0).GetNumberAsDouble();
    v[1] = a.Get(1).GetNumberAsDouble();
  };
  read_pair("offset", off);
  read_pair("scale", sc);
  if (const auto& r = x.Get("rotation"); r.Type() != tinygltf::NULL_TYPE) {
    if (!r.IsNumber()) ctx.fail(xw + ".rotation", "must be a number");
    rot = r.GetNumberAsDouble();
  }
  if (!std::isfinite(off[0] + off[1] + sc[0] + sc[1] + rot)) ctx.fail(xw, "values must be finite");
  if (const auto& t = x.Get("texCoord"); t.Type() != tinygltf::NULL_TYPE) {
    if (!t.IsInt() || t.Get<int>() < 0) ctx.fail(xw + ".texCoord", "must be a non-negative integer");
    texcoord = t.Get<int>();
  }
  const double c = std::cos(rot), sn = std::sin(rot);
  ref.m[0][0] = float(sc[0] * c);
  ref.m[0][1] = float(sc[1] * sn);
  ref.m[0][2] = float(off[0]);
  ref.m[1][0] = float(-sc[0] * sn);
  ref.m[1][1] = float(sc[1] * c);
  ref.m[1][2] = float(off[1]);
}

// A texture info (index, texCoord, extensions) at `where` as a TextureRef; texture -1 if it is
// absent or unusable (with a warning where the file is at fault).
TextureRef texture_ref(const GltfContext& ctx, TextureCache& cache, int texture, int texcoord,
                       const tinygltf::ExtensionMap& extensions, bool srgb, const std::string& where) {
  TextureRef ref;
  const tinygltf::Model& model = ctx.model;
  if (texture < 0 || size_t(texture) >= model.textures.size())
    return ref;  // warned by validate_material_textures
  const int image = texture_image(ctx, texture);
  if (image < 0) return ref;
  if (auto it = extensions.find("KHR_texture_transform"); it != extensions.end())
    read_texture_transform(ctx, it->second, where, ref, texcoord);
  if (texcoord < 0 || texcoord > 1) {
    ctx.warn(where + ".texCoord",
             "TEXCOORD_" + std::to_string(texcoord) + " is not supported (only 0 and 1); texture ignored");
    return ref;
  }
  ref.texcoord = texcoord;
  ref.texture = scene_texture(ctx, cache, texture, image, srgb, where);
  return ref;
}

// Factors and alpha of the core material (pbrMetallicRoughness, emissiveFactor, alphaMode).
void read_core_factors(const GltfContext& ctx, const tinygltf::Material& src, const std::string& where,
                       Material& m) {
  const auto& pbr = src.pbrMetallicRoughness;
  const std::string pw = where + ".pbrMetallicRoughness";
  if (pbr.baseColorFactor.size() != 4) ctx.fail(pw + ".baseColorFactor", "must have 4 values");
  for (int c = 0; c < 3; ++c)
    m.base_color[c] = float(
        std::clamp(finite_or_fail(ctx, pbr.baseColorFactor[size_t(c)], pw + ".baseColorFactor"), 0.0, 1.0));
  m.alpha = float(std::clamp(finite_or_fail(ctx, pbr.baseColorFactor[3], pw + ".baseColorFactor"), 0.0, 1.0));
  m.metallic = float(std::clamp(finite_or_fail(ctx, pbr.metallicFactor, pw + ".metallicFactor"), 0.0, 1.0));
  m.roughness =
      float(std::clamp(finite_or_fail(ctx, pbr.roughnessFactor, pw + ".roughnessFactor"), 0.0, 1.0));
  if (!src.emissiveFactor.empty()) {
    if (src.emissiveFactor.size() != 3) ctx.fail(where + ".emissiveFactor", "must have 3 values");
    for (int c = 0; c < 3; ++c)
      m.emissive[c] = float(std::clamp(
          finite_or_fail(ctx, src.emissiveFactor[size_t(c)], where + ".emissiveFactor"), 0.0, 1.0));
  }
}

// A number in [lo, hi] at extensions.<ext>.<key> (absent: `out` keeps its default).
void extension_number(const GltfContext& ctx, const tinygltf::Material& src, const std::string& where,
                      const char* ext, const char* key, float& out, double lo, double hi, const char* range) {
  auto it = src.extensions.find(ext);
  if (it == src.extensions.end()) return;
  const auto& v = it->second.Get(key);
  if (v.Type() == tinygltf::NULL_TYPE) return;
  const std::string w = where + ".extensions." + ext + "." + key;
  if (!v.IsNumber()) ctx.fail(w, "must be a number");
  const double x = finite_or_fail(ctx, v.GetNumberAsDouble(), w);
  if (x < lo || x > hi) ctx.fail(w, std::string("must be ") + range);
  out = float(x);
}

// Three numbers at extensions.<ext>.<key>, clamped to [0, hi] (absent: `out` keeps its default).
void extension_color(const GltfContext& ctx, const tinygltf::Material& src, const std::string& where,
                     const char* ext, const char* key, Vec3f& out, double hi = 1) {
  auto it = src.extensions.find(ext);
  if (it == src.extensions.end()) return;
  const auto& v = it->second.Get(key);
  if (v.Type() == tinygltf::NULL_TYPE) return;
  const std::string w = where + ".extensions." + ext + "." + key;
  if (!v.IsArray() || v.ArrayLen() != 3) ctx.fail(w, "must be 3 numbers");
  for (int c = 0; c < 3; ++c) {
    const auto& x = v.Get(c);
    if (!x.IsNumber()) ctx.fail(w, "must be 3 numbers");
    out[c] = float(std::clamp(finite_or_fail(ctx, x.GetNumberAsDouble(), w), 0.0, hi));
  }
}

// The texture info at extensions.<ext>.<key> (none: texture -1); `scale`, if given, receives a
// normal texture's scale.
TextureRef extension_texture(const GltfContext& ctx, TextureCache& cache, const tinygltf::Material& src,
                             const std::string& where, const char* ext, const char* key, bool srgb,
                             float* scale = nullptr) {
  auto it = src.extensions.find(ext);
  if (it == src.extensions.end()) return {};
  const auto& info = it->second.Get(key);
  const std::string w = where + ".extensions." + ext + "." + key;
  if (info.Type() == tinygltf::NULL_TYPE) return {};
  if (!info.IsObject() || !info.Get("index").IsInt())
    ctx.fail(w, "must be a texture info with an integer index");
  const int index = info.Get("index").GetNumberAsInt();
  if (index < 0 || size_t(index) >= ctx.model.textures.size()) {
    ctx.warn(w, "texture index " + std::to_string(index) + " out of range (" +
                    std::to_string(ctx.model.textures.size()) + " textures); ignored");
    return {};
  }
  if (scale && info.Get("scale").IsNumber())
    *scale = float(finite_or_fail(ctx, info.Get("scale").GetNumberAsDouble(), w + ".scale"));
  tinygltf::ExtensionMap texture_extensions;
  const auto& e = info.Get("extensions");
  if (e.IsObject())
    for (const auto& k : e.Keys()) texture_extensions[k] = e.Get(k);
  const int tc = info.Get("texCoord").IsInt() ? info.Get("texCoord").GetNumberAsInt() : 0;
  return texture_ref(ctx, cache, index, tc, texture_extensions, srgb, w);
}

// KHR_materials_emissive_strength, _unlit, _ior, _specular and _transmission.
void read_khr_extensions(const GltfContext& ctx, TextureCache& cache, const tinygltf::Material& src,
                         const std::string& where, Material& m) {
  if (auto it = src.extensions.find("KHR_materials_emissive_strength"); it != src.extensions.end()) {
    const auto& s = it->second.Get("emissiveStrength");
    if (s.IsNumber()) {
      const std::string sw = where + ".extensions.KHR_materials_emissive_strength";
      const double strength = finite_or_fail(ctx, s.GetNumberAsDouble(), sw);
      if (strength < 0) ctx.fail(sw, "emissiveStrength must be >= 0");
      m.emissive *= float(strength);
    }
  }
  m.unlit = src.extensions.count("KHR_materials_unlit") > 0;
  // ior: >= 1, or 0 (the extension's special case: f0 = 1).
  extension_number(ctx, src, where, "KHR_materials_ior", "ior", m.ior, 0.0, 1e6, "0 or in [1, 1e6]");
  if (m.ior > 0 && m.ior < 1)
    ctx.fail(where + ".extensions.KHR_materials_ior.ior", "must be 0 or in [1, 1e6]");
  extension_number(ctx, src, where, "KHR_materials_specular", "specularFactor", m.specular, 0.0, 1.0,
                   "in [0, 1]");
  extension_color(ctx, src, where, "KHR_materials_specular", "specularColorFactor", m.specular_color, 1e6);
  m.specular_tex =
      extension_texture(ctx, cache, src, where, "KHR_materials_specular", "specularTexture", false);
  m.specular_color_tex =
      extension_texture(ctx, cache, src, where, "KHR_materials_specular", "specularColorTexture", true);
  extension_number(ctx, src, where, "KHR_materials_transmission", "transmissionFactor", m.transmission, 0.0,
                   1.0, "in [0, 1]");
  if (m.transmission > 0)
    m.transmission_tex =
        extension_texture(ctx, cache, src, where, "KHR_materials_transmission", "transmissionTexture", false);
}

// KHR_materials_volume (a volume when thicknessFactor > 0) and KHR_materials_dispersion.
void read_volume(const GltfContext& ctx, const tinygltf::Material& src, const std::string& where,
                 Material& m) {
  float thickness = 0;
  extension_number(ctx, src, where, "KHR_materials_volume", "thicknessFactor", thickness, 0.0, 1e30, ">= 0");
  m.volume = thickness > 0;
  extension_number(ctx, src, where, "KHR_materials_volume", "attenuationDistance", m.attenuation_distance,
                   0.0, 1e30, "> 0");
  if (src.extensions.count("KHR_materials_volume") && !(m.attenuation_distance > 0))
    ctx.fail(where + ".extensions.KHR_materials_volume.attenuationDistance", "must be > 0");
  extension_color(ctx, src, where, "KHR_materials_volume", "attenuationColor", m.attenuation_color);
  extension_number(ctx, src, where, "KHR_materials_dispersion", "dispersion", m.dispersion, 0.0, 1e3, ">= 0");
}

// KHR_materials_clearcoat, _sheen, _anisotropy, _iridescence and _diffuse_transmission.
void read_layers(const GltfContext& ctx, TextureCache& cache, const tinygltf::Material& src,
                 const std::string& where, Material& m) {
  const char* cc = "KHR_materials_clearcoat";
  extension_number(ctx, src, where, cc, "clearcoatFactor", m.clearcoat, 0.0, 1.0, "in [0, 1]");
  extension_number(ctx, src, where, cc, "clearcoatRoughnessFactor", m.clearcoat_roughness, 0.0, 1.0,
                   "in [0, 1]");
  if (m.clearcoat > 0) {
    m.clearcoat_tex = extension_texture(ctx, cache, src, where, cc, "clearcoatTexture", false);
    m.clearcoat_roughness_tex =
        extension_texture(ctx, cache, src, where, cc, "clearcoatRoughnessTexture", false);
    m.clearcoat_normal_tex = extension_texture(ctx, cache, src, where, cc, "clearcoatNormalTexture", false,
                                               &m.clearcoat_normal_scale);
  }
  const char* sh = "KHR_materials_sheen";
  extension_color(ctx, src, where, sh, "sheenColorFactor", m.sheen_color);
  extension_number(ctx, src, where, sh, "sheenRoughnessFactor", m.sheen_roughness, 0.0, 1.0, "in [0, 1]");
  if (max_component(m.sheen_color) > 0) {
    m.sheen_color_tex = extension_texture(ctx, cache, src, where, sh, "sheenColorTexture", true);
    m.sheen_roughness_tex = extension_texture(ctx, cache, src, where, sh, "sheenRoughnessTexture", false);
  }
  const char* an = "KHR_materials_anisotropy";
  extension_number(ctx, src, where, an, "anisotropyStrength", m.anisotropy, 0.0, 1.0, "in [0, 1]");
  extension_number(ctx, src, where, an, "anisotropyRotation", m.anisotropy_rotation, -1e6, 1e6, "finite");
  if (m.anisotropy > 0)
    m.anisotropy_tex = extension_texture(ctx, cache, src, where, an, "anisotropyTexture", false);
  const char* ir = "KHR_materials_iridescence";
  extension_number(ctx, src, where, ir, "iridescenceFactor", m.iridescence, 0.0, 1.0, "in [0, 1]");
  extension_number(ctx, src, where, ir, "iridescenceIor", m.iridescence_ior, 1.0, 1e3, ">= 1");
  extension_number(ctx, src, where, ir, "iridescenceThicknessMinimum", m.iridescence_thickness_min, 0.0, 1e6,
                   "in [0, 1e6] nm");
  extension_number(ctx, src, where, ir, "iridescenceThicknessMaximum", m.iridescence_thickness_max, 0.0, 1e6,
                   "in [0, 1e6] nm");
  if (m.iridescence > 0) {
    m.iridescence_tex = extension_texture(ctx, cache, src, where, ir, "iridescenceTexture", false);
    m.iridescence_thickness_tex =
        extension_texture(ctx, cache, src, where, ir, "iridescenceThicknessTexture", false);
  }
  const char* dt = "KHR_materials_diffuse_transmission";
  extension_number(ctx, src, where, dt, "diffuseTransmissionFactor", m.diffuse_transmission, 0.0, 1.0,
                   "in [0, 1]");
  extension_color(ctx, src, where, dt, "diffuseTransmissionColorFactor", m.diffuse_transmission_color);
  if (m.diffuse_transmission > 0) {
    m.diffuse_transmission_tex =
        extension_texture(ctx, cache, src, where, dt, "diffuseTransmissionTexture", false);
    m.diffuse_transmission_color_tex =
        extension_texture(ctx, cache, src, where, dt, "diffuseTransmissionColorTexture", true);
  }
}

// Perceived brightness of a colour (the specular-glossiness converter's measure).
double perceived(const double c[3]) {
  return std::sqrt(0.299 * c[0] * c[0] + 0.587 * c[1] * c[1] + 0.114 * c[2] * c[2]);
}

// KHR_materials_pbrSpecularGlossiness (archived), converted to metallic-roughness from its
// factors by the Khronos converter's rule: metallic solves the dielectric/metal mix of the two
// colours' brightness, the base colour blends the colour each explains by metallic^2, roughness
// = 1 - glossiness. diffuseTexture becomes the base colour texture; the specular-glossiness
// texture has no per-texel equivalent and is not used. Warns that the material is converted.
void read_specular_glossiness(const GltfContext& ctx, TextureCache& cache, const tinygltf::Material& src,
                              const std::string& where, Material& m) {
  const char* ext = "KHR_materials_pbrSpecularGlossiness";
  auto it = src.extensions.find(ext);
  if (it == src.extensions.end()) return;
  const std::string xw = where + ".extensions." + ext;
  double diffuse[4] = {1, 1, 1, 1}, specular[3] = {1, 1, 1}, gloss = 1;
  auto read = [&](const char* key, double* out, int n) {
    const auto& v = it->second.Get(key);
    if (v.Type() == tinygltf::NULL_TYPE) return;
    if (n == 1) {
      if (!v.IsNumber()) ctx.fail(xw + "." + key, "must be a number");
      out[0] = std::clamp(finite_or_fail(ctx, v.GetNumberAsDouble(), xw + "." + key), 0.0, 1.0);
      return;
    }
    if (!v.IsArray() || int(v.ArrayLen()) != n)
      ctx.fail(xw + "." + key, "must be " + std::to_string(n) + " numbers");
    for (int c = 0; c < n; ++c) {
      if (!v.Get(c).IsNumber()) ctx.fail(xw + "." + key, "must be " + std::to_string(n) + " numbers");
      out[c] = std::clamp(finite_or_fail(ctx, v.Get(c).GetNumberAsDouble(), xw + "." + key), 0.0, 1.0);
    }
  };
  read("diffuseFactor", diffuse, 4);
  read("specularFactor", specular, 3);
  read("glossinessFactor", &gloss, 1);
  constexpr double kDielectric = 0.04, kEps = 1e-6;
  const double one_minus = 1 - std::max({specular[0], specular[1], specular[2]});
  const double d = perceived(diffuse), s = perceived(specular);
  double metallic = 0;
  if (s >= kDielectric) {
    const double a = kDielectric, b = d * one_minus / (1 - kDielectric) + s - 2 * kDielectric,
                 c = kDielectric - s;
    metallic = std::clamp((-b + std::sqrt(std::max(0.0, b * b - 4 * a * c))) / (2 * a), 0.0, 1.0);
  }
  for (int k = 0; k < 3; ++k) {
    const double from_diffuse = diffuse[k] * one_minus / (1 - kDielectric) / std::max(1 - metallic, kEps);
    const double from_specular = (specular[k] - kDielectric * (1 - metallic)) / std::max(metallic, kEps);
    const double t = metallic * metallic;
    m.base_color[k] = float(std::clamp(from_diffuse * (1 - t) + from_specular * t, 0.0, 1.0));
  }
  m.alpha = float(diffuse[3]);
  m.metallic = float(metallic);
  m.roughness = float(1 - gloss);
  m.metallic_roughness_tex = {};
  m.base_color_tex = extension_texture(ctx, cache, src, where, ext, "diffuseTexture", true);
  ctx.warn(
      xw,
      "archived extension converted to metallic-roughness (metallic " + std::to_string(m.metallic) +
          ", roughness " + std::to_string(m.roughness) + ")" +
          (it->second.Has("specularGlossinessTexture") ? "; its specularGlossinessTexture is not used" : ""));
}

// Alpha mode and cutoff, sidedness, and the core textures (baseColor and emissive in sRGB).
void read_alpha_and_textures(const GltfContext& ctx, TextureCache& cache, const tinygltf::Material& src,
                             const std::string& where, Material& m) {
  if (src.alphaMode == "OPAQUE" || src.alphaMode.empty())
    m.alpha_mode = AlphaMode::Opaque;
  else if (src.alphaMode == "MASK")
    m.alpha_mode = AlphaMode::Mask;
  else if (src.alphaMode == "BLEND")
    m.alpha_mode = AlphaMode::Blend;
  else
    ctx.fail(where + ".alphaMode", "'" + src.alphaMode + "' is not OPAQUE, MASK or BLEND");
  m.alpha_cutoff = float(finite_or_fail(ctx, src.alphaCutoff, where + ".alphaCutoff"));
  if (m.alpha_cutoff < 0) ctx.fail(where + ".alphaCutoff", "must be >= 0");
  m.double_sided = src.doubleSided;
  const auto& pbr = src.pbrMetallicRoughness;
  m.base_color_tex =
      texture_ref(ctx, cache, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                  pbr.baseColorTexture.extensions, true, where + ".pbrMetallicRoughness.baseColorTexture");
  m.metallic_roughness_tex =
      texture_ref(ctx, cache, pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                  pbr.metallicRoughnessTexture.extensions, false,
                  where + ".pbrMetallicRoughness.metallicRoughnessTexture");
  m.normal_tex = texture_ref(ctx, cache, src.normalTexture.index, src.normalTexture.texCoord,
                             src.normalTexture.extensions, false, where + ".normalTexture");
  m.normal_scale = float(finite_or_fail(ctx, src.normalTexture.scale, where + ".normalTexture.scale"));
  m.occlusion_tex = texture_ref(ctx, cache, src.occlusionTexture.index, src.occlusionTexture.texCoord,
                                src.occlusionTexture.extensions, false, where + ".occlusionTexture");
  m.occlusion_strength = float(std::clamp(
      finite_or_fail(ctx, src.occlusionTexture.strength, where + ".occlusionTexture.strength"), 0.0, 1.0));
  if (max_component(m.emissive) > 0)
    m.emissive_tex = texture_ref(ctx, cache, src.emissiveTexture.index, src.emissiveTexture.texCoord,
                                 src.emissiveTexture.extensions, true, where + ".emissiveTexture");
}

}  // namespace

void validate_material_textures(const GltfContext& ctx) {
  const int n = int(ctx.model.textures.size());
  for (size_t i = 0; i < ctx.model.materials.size(); ++i) {
    const auto& m = ctx.model.materials[i];
    const std::pair<const char*, int> refs[] = {
        {"pbrMetallicRoughness.baseColorTexture", m.pbrMetallicRoughness.baseColorTexture.index},
        {"pbrMetallicRoughness.metallicRoughnessTexture",
         m.pbrMetallicRoughness.metallicRoughnessTexture.index},
        {"normalTexture", m.normalTexture.index},
        {"occlusionTexture", m.occlusionTexture.index},
        {"emissiveTexture", m.emissiveTexture.index}};
    for (const auto& [field, index] : refs)
      if (index < -1 || index >= n)
        ctx.warn(idx("materials", i) + "." + field, "texture index " + std::to_string(index) +
                                                        " out of range (" + std::to_string(n) +
                                                        " textures); ignored");
  }
}

void convert_materials(const GltfContext& ctx, TextureCache& cache) {
  for (size_t i = 0; i < ctx.model.materials.size(); ++i) {
    const auto& src = ctx.model.materials[i];
    const std::string where = idx("materials", i);
    Material m;
    m.name = src.name.empty() ? where : src.name;
    read_core_factors(ctx, src, where, m);
    read_khr_extensions(ctx, cache, src, where, m);
    read_volume(ctx, src, where, m);
    read_layers(ctx, cache, src, where, m);
    read_alpha_and_textures(ctx, cache, src, where, m);
    read_specular_glossiness(ctx, cache, src, where, m);
    ctx.out.scene.materials.push_back(m);
  }
}

}  // namespace penumbra::gltf
