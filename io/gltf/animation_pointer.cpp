// KHR_animation_pointer channels: pointers parsed, values sampled, written into the model.
#include "io/gltf/animation_pointer.h"

#include <tiny_gltf.h>

#include <cmath>

#include "io/gltf/animation.h"

namespace penumbra::gltf {

namespace {

// The material extension numbers and colours that can be animated, with their widths.
struct ExtensionKey {
  const char* ext;
  const char* key;
  size_t width;
};
constexpr ExtensionKey kMaterialKeys[] = {
    {"KHR_materials_emissive_strength", "emissiveStrength", 1},
    {"KHR_materials_ior", "ior", 1},
    {"KHR_materials_specular", "specularFactor", 1},
    {"KHR_materials_transmission", "transmissionFactor", 1},
    {"KHR_materials_volume", "thicknessFactor", 1},
    {"KHR_materials_volume", "attenuationDistance", 1},
    {"KHR_materials_volume", "attenuationColor", 3},
    {"KHR_materials_clearcoat", "clearcoatFactor", 1},
    {"KHR_materials_clearcoat", "clearcoatRoughnessFactor", 1},
    {"KHR_materials_sheen", "sheenColorFactor", 3},
    {"KHR_materials_sheen", "sheenRoughnessFactor", 1},
    {"KHR_materials_anisotropy", "anisotropyStrength", 1},
    {"KHR_materials_anisotropy", "anisotropyRotation", 1},
    {"KHR_materials_iridescence", "iridescenceFactor", 1},
    {"KHR_materials_iridescence", "iridescenceIor", 1},
    {"KHR_materials_iridescence", "iridescenceThicknessMinimum", 1},
    {"KHR_materials_iridescence", "iridescenceThicknessMaximum", 1},
    {"KHR_materials_dispersion", "dispersion", 1},
    {"KHR_materials_diffuse_transmission", "diffuseTransmissionFactor", 1},
    {"KHR_materials_diffuse_transmission", "diffuseTransmissionColorFactor", 3},
};

std::vector<std::string> split_pointer(const std::string& p) {
  std::vector<std::string> out;
  if (p.empty() || p[0] != '/') return out;
  size_t start = 1;
  for (size_t i = 1; i <= p.size(); ++i)
    if (i == p.size() || p[i] == '/') {
      out.push_back(p.substr(start, i - start));
      start = i + 1;
    }
  return out;
}

// parts[k] as an index below `count`, or an InputError naming the channel.
size_t element(const GltfContext& ctx, const std::vector<std::string>& parts, size_t k, size_t count,
               const std::string& where) {
  const std::string& s = parts[k];
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos ||
      std::stoul(s) >= count)
    ctx.fail(where, "pointer element '" + s + "' is not an index below " + std::to_string(count));
  return std::stoul(s);
}

// Writes v into extension `ext` of `extensions` at `key` (a number or an array of numbers).
void set_extension_value(tinygltf::ExtensionMap& extensions, const char* ext, const char* key,
                         const std::vector<double>& v) {
  tinygltf::Value::Object obj;
  if (auto it = extensions.find(ext); it != extensions.end() && it->second.IsObject())
    obj = it->second.Get<tinygltf::Value::Object>();
  if (v.size() == 1) {
    obj[key] = tinygltf::Value(v[0]);
  } else {
    tinygltf::Value::Array a;
    for (double x : v) a.emplace_back(x);
    obj[key] = tinygltf::Value(std::move(a));
  }
  extensions[ext] = tinygltf::Value(std::move(obj));
}

// The width the target at parts (after the element index) takes, 0 if it is not animated here;
// `rotation` for quaternions.
size_t material_width(const std::vector<std::string>& rest) {
  const std::string path = [&] {
    std::string s;
    for (const auto& r : rest) s += (s.empty() ? "" : "/") + r;
    return s;
  }();
  if (path == "pbrMetallicRoughness/baseColorFactor") return 4;
  if (path == "pbrMetallicRoughness/metallicFactor" || path == "pbrMetallicRoughness/roughnessFactor" ||
      path == "alphaCutoff" || path == "normalTexture/scale" || path == "occlusionTexture/strength")
    return 1;
  if (path == "emissiveFactor") return 3;
  if (rest.size() == 3 && rest[0] == "extensions")
    for (const auto& k : kMaterialKeys)
      if (rest[1] == k.ext && rest[2] == k.key) return k.width;
  return 0;
}

void write_material(tinygltf::Material& m, const std::vector<std::string>& rest,
                    const std::vector<double>& v) {
  if (rest[0] == "pbrMetallicRoughness") {
    if (rest[1] == "baseColorFactor") m.pbrMetallicRoughness.baseColorFactor = v;
    if (rest[1] == "metallicFactor") m.pbrMetallicRoughness.metallicFactor = v[0];
    if (rest[1] == "roughnessFactor") m.pbrMetallicRoughness.roughnessFactor = v[0];
  } else if (rest[0] == "emissiveFactor") {
    m.emissiveFactor = v;
  } else if (rest[0] == "alphaCutoff") {
    m.alphaCutoff = v[0];
  } else if (rest[0] == "normalTexture") {
    m.normalTexture.scale = v[0];
  } else if (rest[0] == "occlusionTexture") {
    m.occlusionTexture.strength = v[0];
  } else {
    for (const auto& k : kMaterialKeys)
      if (rest[1] == k.ext && rest[2] == k.key) set_extension_value(m.extensions, k.ext, k.key, v);
  }
}

// Light, camera and node targets: their width (0: not animated here).
size_t light_width(const std::vector<std::string>& rest) {
  if (rest.size() == 1 && rest[0] == "color") return 3;
  if (rest.size() == 1 && (rest[0] == "intensity" || rest[0] == "range")) return 1;
  if (rest.size() == 2 && rest[0] == "spot" && (rest[1] == "innerConeAngle" || rest[1] == "outerConeAngle"))
    return 1;
  return 0;
}

size_t camera_width(const std::vector<std::string>& rest) {
  if (rest.size() != 2) return 0;
  if (rest[0] == "perspective" &&
      (rest[1] == "yfov" || rest[1] == "znear" || rest[1] == "zfar" || rest[1] == "aspectRatio"))
    return 1;
  if (rest[0] == "orthographic" &&
      (rest[1] == "xmag" || rest[1] == "ymag" || rest[1] == "znear" || rest[1] == "zfar"))
    return 1;
  return 0;
}

void write_camera(tinygltf::Camera& c, const std::vector<std::string>& rest, double v) {
  if (rest[0] == "perspective") {
    if (rest[1] == "yfov") c.perspective.yfov = v;
    if (rest[1] == "znear") c.perspective.znear = v;
    if (rest[1] == "zfar") c.perspective.zfar = v;
    if (rest[1] == "aspectRatio") c.perspective.aspectRatio = v;
  } else {
    if (rest[1] == "xmag") c.orthographic.xmag = v;
    if (rest[1] == "ymag") c.orthographic.ymag = v;
    if (rest[1] == "znear") c.orthographic.znear = v;
    if (rest[1] == "zfar") c.orthographic.zfar = v;
  }
}

// One parsed pointer: what it targets and how many values it takes.
struct Target {
  enum Kind { None, Material, Light, Camera, Node } kind = None;
  size_t index = 0;
  std::vector<std::string> rest;  // the path after the element index
  size_t width = 0;               // 0 with kind Node and "weights": from the sampler
  bool rotation = false;
};

Target parse_target(const GltfContext& ctx, const tinygltf::Model& model, const std::string& pointer,
                    const std::string& where) {
  const std::vector<std::string> parts = split_pointer(pointer);
  Target t;
  if (parts.size() >= 3 && parts[0] == "materials") {
    t.kind = Target::Material;
    t.index = element(ctx, parts, 1, model.materials.size(), where);
    t.rest.assign(parts.begin() + 2, parts.end());
    t.width = material_width(t.rest);
  } else if (parts.size() >= 5 && parts[0] == "extensions" && parts[1] == "KHR_lights_punctual" &&
             parts[2] == "lights") {
    t.kind = Target::Light;
    t.index = element(ctx, parts, 3, model.lights.size(), where);
    t.rest.assign(parts.begin() + 4, parts.end());
    t.width = light_width(t.rest);
  } else if (parts.size() == 4 && parts[0] == "cameras") {
    t.kind = Target::Camera;
    t.index = element(ctx, parts, 1, model.cameras.size(), where);
    t.rest.assign(parts.begin() + 2, parts.end());
    t.width = camera_width(t.rest);
  } else if (parts.size() == 3 && parts[0] == "nodes") {
    t.kind = Target::Node;
    t.index = element(ctx, parts, 1, model.nodes.size(), where);
    t.rest.assign(parts.begin() + 2, parts.end());
    const std::string& p = t.rest[0];
    t.width = p == "translation" || p == "scale" ? 3 : (p == "rotation" ? 4 : 0);
    t.rotation = p == "rotation";
    if (t.width == 0 && p != "weights") t.kind = Target::None;
  }
  if (t.kind != Target::Node && t.width == 0) t.kind = Target::None;
  return t;
}

void write_target(tinygltf::Model& model, const Target& t, const std::vector<double>& v) {
  switch (t.kind) {
    case Target::Material:
      write_material(model.materials[t.index], t.rest, v);
      break;
    case Target::Light: {
      tinygltf::Light& l = model.lights[t.index];
      if (t.rest[0] == "color") l.color = v;
      if (t.rest[0] == "intensity") l.intensity = v[0];
      if (t.rest[0] == "range") l.range = v[0];
      if (t.rest[0] == "spot" && t.rest[1] == "innerConeAngle") l.spot.innerConeAngle = v[0];
      if (t.rest[0] == "spot" && t.rest[1] == "outerConeAngle") l.spot.outerConeAngle = v[0];
      break;
    }
    case Target::Camera:
      write_camera(model.cameras[t.index], t.rest, v[0]);
      break;
    case Target::Node: {
      tinygltf::Node& n = model.nodes[t.index];
      if (t.rest[0] == "translation") n.translation = v;
      if (t.rest[0] == "rotation") n.rotation = v;
      if (t.rest[0] == "scale") n.scale = v;
      if (t.rest[0] == "weights") n.weights = v;
      break;
    }
    case Target::None:
      break;
  }
}

}  // namespace

bool has_animation_pointers(const tinygltf::Model& model) {
  for (const auto& a : model.animations)
    for (const auto& ch : a.channels)
      if (ch.target_path == "pointer") return true;
  return false;
}

void apply_animation_pointers(const GltfContext& ctx, tinygltf::Model& model, double time) {
  std::vector<std::pair<Target, std::vector<double>>> values;
  for (size_t ai = 0; ai < ctx.model.animations.size(); ++ai) {
    const auto& anim = ctx.model.animations[ai];
    for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
      const auto& ch = anim.channels[ci];
      if (ch.target_path != "pointer") continue;
      const std::string cw = idx("animations", ai) + "." + idx("channels", ci);
      const std::string tw = cw + ".target.extensions.KHR_animation_pointer";
      const auto it = ch.target_extensions.find("KHR_animation_pointer");
      if (it == ch.target_extensions.end() || !it->second.Get("pointer").IsString())
        ctx.fail(tw + ".pointer", "is required (a JSON pointer string) for the path 'pointer'");
      const std::string pointer = it->second.Get("pointer").Get<std::string>();
      if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
        ctx.fail(cw + ".sampler", "sampler index " + std::to_string(ch.sampler) + " out of range (" +
                                      std::to_string(anim.samplers.size()) + " samplers)");
      const Target t = parse_target(ctx, ctx.model, pointer, tw + ".pointer");
      if (t.kind == Target::None) {
        ctx.warn(tw + ".pointer", "'" + pointer + "' is not a property Penumbra animates; channel ignored");
        continue;
      }
      std::vector<double> v = sample_animation(ctx, ai, ch.sampler, t.width, t.rotation, time);
      if (v.empty()) ctx.fail(cw, "the sampler has no values for '" + pointer + "'");
      values.emplace_back(t, std::move(v));
    }
  }
  for (const auto& [t, v] : values) write_target(model, t, v);
}

}  // namespace penumbra::gltf
