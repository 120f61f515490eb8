// Raw-JSON checks of a glTF document: index ranges, offsets and strides, enums and array types.
#include "io/gltf/json_checks.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <initializer_list>

#include "io/files/error.h"

namespace penumbra::gltf {

namespace {

using nlohmann::json;

std::string idx(const std::string& array, size_t i) {
  return array + "[" + std::to_string(i) + "]";
}

/// A value for messages, cut to 40 characters.
std::string shown(const json& v) {
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

class JsonChecks {
 public:
  JsonChecks(const json& doc, const std::string& file) : m_doc(doc), m_file(file) {}
  void run();

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    throw InputError(m_file, where, message);
  }
  /// obj[key], or null if obj is not an object or has no such member.
  static const json& member(const json& obj, const char* key) {
    static const json null_value;
    if (!obj.is_object()) return null_value;
    const auto it = obj.find(key);
    return it == obj.end() ? null_value : *it;
  }
  /// The top-level array `name` (empty if absent); each element must be an object.
  const json& collection(const json& parent, const char* name, const std::string& where) const {
    static const json empty = json::array();
    const json& a = member(parent, name);
    if (a.is_null()) return empty;
    if (!a.is_array()) fail(where, "must be an array (got " + shown(a) + ")");
    for (size_t i = 0; i < a.size(); ++i)
      if (!a[i].is_object()) fail(idx(where, i), "must be an object (got " + shown(a[i]) + ")");
    return a;
  }
  size_t count(const char* name) const {
    const json& a = member(m_doc, name);
    return a.is_array() ? a.size() : 0;
  }
  void index_value(const json& v, const std::string& where, size_t n, const char* target) const;
  void index(const json& obj, const char* key, const std::string& path, size_t n, const char* target) const {
    const json& v = member(obj, key);
    if (!v.is_null()) index_value(v, path + "." + key, n, target);
  }
  void index_array(const json& obj, const char* key, const std::string& path, size_t n,
                   const char* target) const;
  void unsigned_int(const json& obj, const char* key, const std::string& path, uint64_t max) const;
  void enum_value(const json& obj, const char* key, const std::string& path,
                  std::initializer_list<int> allowed) const;
  void texture_info(const json& obj, const char* key, const std::string& path) const;
  void extension_names();
  void buffers_and_accessors();
  void samplers_textures_materials();
  size_t morph_targets(const json& mesh, const std::string& where) const;
  void meshes_and_nodes();
  void skins_and_animations();

  const json& m_doc;
  const std::string& m_file;
};

void JsonChecks::index_value(const json& v, const std::string& where, size_t n, const char* target) const {
  if (!v.is_number_integer()) {
    const std::string noun(target);  // "accessors" -> "an integer accessor index"
    fail(where, "must be an integer " + noun.substr(0, noun.size() - 1) + " index (got " + shown(v) + ")");
  }
  if (!v.is_number_unsigned()) fail(where, "index " + std::to_string(v.get<int64_t>()) + " is negative");
  const uint64_t u = v.get<uint64_t>();
  if (u > uint64_t(INT_MAX))
    fail(where, "index " + std::to_string(u) + " does not fit a 32-bit integer (" + std::to_string(n) + " " +
                    target + ")");
  if (u >= n)
    fail(where, "index " + std::to_string(u) + " out of range (" + std::to_string(n) + " " + target + ")");
}

void JsonChecks::index_array(const json& obj, const char* key, const std::string& path, size_t n,
                             const char* target) const {
  const json& a = member(obj, key);
  if (a.is_null()) return;
  const std::string where = path + "." + key;
  if (!a.is_array())
    fail(where, std::string("must be an array of indices into ") + target + " (got " + shown(a) + ")");
  for (size_t i = 0; i < a.size(); ++i) index_value(a[i], idx(where, i), n, target);
}

void JsonChecks::unsigned_int(const json& obj, const char* key, const std::string& path, uint64_t max) const {
  const json& v = member(obj, key);
  if (v.is_null()) return;
  const std::string where = path + "." + key;
  if (!v.is_number_integer()) fail(where, "must be a non-negative integer (got " + shown(v) + ")");
  if (!v.is_number_unsigned()) fail(where, "must be a non-negative integer (got " + shown(v) + ")");
  if (v.get<uint64_t>() > max)
    fail(where,
         std::to_string(v.get<uint64_t>()) + " is over " + std::to_string(max) + ", the largest supported");
}

void JsonChecks::enum_value(const json& obj, const char* key, const std::string& path,
                            std::initializer_list<int> allowed) const {
  const json& v = member(obj, key);
  if (v.is_null()) return;
  std::string list;
  for (int a : allowed) list += (list.empty() ? "" : ", ") + std::to_string(a);
  const bool ok = v.is_number_integer() && v.is_number_unsigned() && v.get<uint64_t>() <= uint64_t(INT_MAX) &&
                  std::find(allowed.begin(), allowed.end(), int(v.get<uint64_t>())) != allowed.end();
  if (!ok) fail(path + "." + key, shown(v) + " is not one of the allowed values (" + list + ")");
}

void JsonChecks::texture_info(const json& obj, const char* key, const std::string& path) const {
  const json& info = member(obj, key);
  if (info.is_null()) return;
  const std::string where = path + "." + key;
  if (!info.is_object()) fail(where, "must be an object (got " + shown(info) + ")");
  if (member(info, "index").is_null()) fail(where + ".index", "is required");
  index(info, "index", where, count("textures"), "textures");
  unsigned_int(info, "texCoord", where, INT_MAX);
  unsigned_int(member(member(info, "extensions"), "KHR_texture_transform"), "texCoord",
               where + ".extensions.KHR_texture_transform", INT_MAX);
}

void JsonChecks::extension_names() {
  for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
    const json& a = member(m_doc, key);
    if (a.is_null()) continue;
    if (!a.is_array()) fail(key, "must be an array of extension names (got " + shown(a) + ")");
    for (size_t i = 0; i < a.size(); ++i)
      if (!a[i].is_string()) fail(idx(key, i), "must be a string (got " + shown(a[i]) + ")");
  }
}

void JsonChecks::buffers_and_accessors() {
  const json& buffers = collection(m_doc, "buffers", "buffers");
  for (size_t i = 0; i < buffers.size(); ++i)
    unsigned_int(buffers[i], "byteLength", idx("buffers", i), UINT64_MAX);
  const json& views = collection(m_doc, "bufferViews", "bufferViews");
  for (size_t i = 0; i < views.size(); ++i) {
    const std::string where = idx("bufferViews", i);
    index(views[i], "buffer", where, buffers.size(), "buffers");
    unsigned_int(views[i], "byteOffset", where, UINT64_MAX);
    unsigned_int(views[i], "byteLength", where, UINT64_MAX);
    unsigned_int(views[i], "byteStride", where, UINT64_MAX);
    const json& stride = member(views[i], "byteStride");
    if (!stride.is_null() &&
        (stride.get<uint64_t>() < 4 || stride.get<uint64_t>() > 252 || stride.get<uint64_t>() % 4))
      fail(where + ".byteStride",
           std::to_string(stride.get<uint64_t>()) + " is not a multiple of 4 in [4, 252]");
  }
  const json& accessors = collection(m_doc, "accessors", "accessors");
  for (size_t i = 0; i < accessors.size(); ++i) {
    const std::string where = idx("accessors", i);
    index(accessors[i], "bufferView", where, views.size(), "bufferViews");
    unsigned_int(accessors[i], "byteOffset", where, UINT64_MAX);
    unsigned_int(accessors[i], "count", where, UINT64_MAX);
    const json& sparse = member(accessors[i], "sparse");
    if (sparse.is_null()) continue;
    const std::string sw = where + ".sparse";
    if (!sparse.is_object()) fail(sw, "must be an object (got " + shown(sparse) + ")");
    unsigned_int(sparse, "count", sw, INT_MAX);
    for (const char* part : {"indices", "values"}) {
      const json& p = member(sparse, part);
      const std::string pw = sw + "." + part;
      if (!p.is_object()) fail(pw, "must be an object (got " + shown(p) + ")");
      if (member(p, "bufferView").is_null()) fail(pw + ".bufferView", "is required");
      index(p, "bufferView", pw, views.size(), "bufferViews");
      unsigned_int(p, "byteOffset", pw, INT_MAX);
    }
  }
}

void JsonChecks::samplers_textures_materials() {
  const json& samplers = collection(m_doc, "samplers", "samplers");
  for (size_t i = 0; i < samplers.size(); ++i) {
    const std::string where = idx("samplers", i);
    enum_value(samplers[i], "magFilter", where, {9728, 9729});                          // NEAREST, LINEAR
    enum_value(samplers[i], "minFilter", where, {9728, 9729, 9984, 9985, 9986, 9987});  // + the MIPMAP modes
    enum_value(samplers[i], "wrapS", where, {33071, 33648, 10497});  // CLAMP_TO_EDGE, MIRRORED_REPEAT, REPEAT
    enum_value(samplers[i], "wrapT", where, {33071, 33648, 10497});
  }
  const json& images = collection(m_doc, "images", "images");
  for (size_t i = 0; i < images.size(); ++i)
    index(images[i], "bufferView", idx("images", i), count("bufferViews"), "bufferViews");
  const json& textures = collection(m_doc, "textures", "textures");
  for (size_t i = 0; i < textures.size(); ++i) {
    index(textures[i], "source", idx("textures", i), images.size(), "images");
    index(textures[i], "sampler", idx("textures", i), samplers.size(), "samplers");
  }
  const json& materials = collection(m_doc, "materials", "materials");
  for (size_t i = 0; i < materials.size(); ++i) {
    const std::string where = idx("materials", i);
    const json& pbr = member(materials[i], "pbrMetallicRoughness");
    texture_info(pbr, "baseColorTexture", where + ".pbrMetallicRoughness");
    texture_info(pbr, "metallicRoughnessTexture", where + ".pbrMetallicRoughness");
    for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"})
      texture_info(materials[i], key, where);
    texture_info(member(member(materials[i], "extensions"), "KHR_materials_transmission"),
                 "transmissionTexture", where + ".extensions.KHR_materials_transmission");
  }
}

size_t JsonChecks::morph_targets(const json& mesh, const std::string& where) const {
  const json& prims = member(mesh, "primitives");
  if (!prims.is_array()) fail(where + ".primitives", "must be an array (got " + shown(prims) + ")");
  size_t targets = 0;
  for (size_t p = 0; p < prims.size(); ++p) {
    const std::string pw = where + "." + idx("primitives", p);
    if (!prims[p].is_object()) fail(pw, "must be an object (got " + shown(prims[p]) + ")");
    const json& t = member(prims[p], "targets");
    if (!t.is_null() && !t.is_array()) fail(pw + ".targets", "must be an array (got " + shown(t) + ")");
    const size_t n = t.is_array() ? t.size() : 0;
    if (p > 0 && n != targets)
      fail(pw + ".targets", "has " + std::to_string(n) + " morph targets but primitives[0] has " +
                                std::to_string(targets) +
                                " (all primitives of a mesh must have the same number)");
    targets = n;
  }
  return targets;
}

void JsonChecks::meshes_and_nodes() {
  const size_t accessors = count("accessors");
  const json& meshes = collection(m_doc, "meshes", "meshes");
  std::vector<size_t> targets(meshes.size());
  for (size_t m = 0; m < meshes.size(); ++m) {
    const std::string where = idx("meshes", m);
    targets[m] = morph_targets(meshes[m], where);
    const json& prims = member(meshes[m], "primitives");
    for (size_t p = 0; p < prims.size(); ++p) {
      const std::string pw = where + "." + idx("primitives", p);
      index(prims[p], "indices", pw, accessors, "accessors");
      index(prims[p], "material", pw, count("materials"), "materials");
      const json& attributes = member(prims[p], "attributes");
      if (!attributes.is_object())
        fail(pw + ".attributes", "must be an object (got " + shown(attributes) + ")");
      for (const auto& [name, value] : attributes.items())
        index_value(value, pw + ".attributes." + name, accessors, "accessors");
      const json& t = member(prims[p], "targets");
      for (size_t k = 0; k < t.size(); ++k) {
        const std::string tw = pw + "." + idx("targets", k);
        if (!t[k].is_object()) fail(tw, "must be an object (got " + shown(t[k]) + ")");
        for (const auto& [name, value] : t[k].items())
          index_value(value, tw + "." + name, accessors, "accessors");
      }
    }
    const json& weights = member(meshes[m], "weights");
    if (!weights.is_null() && (!weights.is_array() || weights.size() != targets[m]))
      fail(where + ".weights", "has " +
                                   (weights.is_array() ? std::to_string(weights.size()) : shown(weights)) +
                                   " entries for " + std::to_string(targets[m]) + " morph targets");
  }
  const json& nodes = collection(m_doc, "nodes", "nodes");
  const size_t lights = [&] {
    const json& l = member(member(member(m_doc, "extensions"), "KHR_lights_punctual"), "lights");
    return l.is_array() ? l.size() : size_t(0);
  }();
  for (size_t i = 0; i < nodes.size(); ++i) {
    const json& n = nodes[i];
    const std::string where = idx("nodes", i);
    index(n, "camera", where, count("cameras"), "cameras");
    index(n, "mesh", where, meshes.size(), "meshes");
    index(n, "skin", where, count("skins"), "skins");
    index_array(n, "children", where, nodes.size(), "nodes");
    const json& ext = member(n, "extensions");
    index(member(ext, "KHR_lights_punctual"), "light", where + ".extensions.KHR_lights_punctual", lights,
          "lights");
    const json& attributes = member(member(ext, "EXT_mesh_gpu_instancing"), "attributes");
    if (attributes.is_object())
      for (const auto& [name, value] : attributes.items())
        index_value(value, where + ".extensions.EXT_mesh_gpu_instancing.attributes." + name, accessors,
                    "accessors");
    const json& weights = member(n, "weights");
    if (weights.is_null()) continue;
    if (member(n, "mesh").is_null())
      fail(where + ".weights", "morph weights need a mesh (node.mesh is not set)");
    const size_t expected = targets[member(n, "mesh").get<size_t>()];
    if (!weights.is_array() || weights.size() != expected)
      fail(where + ".weights",
           "has " + (weights.is_array() ? std::to_string(weights.size()) : shown(weights)) +
               " entries for the " + std::to_string(expected) + " morph targets of meshes[" +
               std::to_string(member(n, "mesh").get<size_t>()) + "]");
  }
  const json& scenes = collection(m_doc, "scenes", "scenes");
  for (size_t i = 0; i < scenes.size(); ++i)
    index_array(scenes[i], "nodes", idx("scenes", i), nodes.size(), "nodes");
  if (!member(m_doc, "scene").is_null())
    index_value(member(m_doc, "scene"), "scene", scenes.size(), "scenes");
}

void JsonChecks::skins_and_animations() {
  const size_t nodes = count("nodes"), accessors = count("accessors");
  const json& skins = collection(m_doc, "skins", "skins");
  for (size_t i = 0; i < skins.size(); ++i) {
    const std::string where = idx("skins", i);
    index_array(skins[i], "joints", where, nodes, "nodes");
    index(skins[i], "skeleton", where, nodes, "nodes");
    index(skins[i], "inverseBindMatrices", where, accessors, "accessors");
  }
  bool pointer_extension = false;
  const json& used = member(m_doc, "extensionsUsed");
  for (const json& e : used) pointer_extension = pointer_extension || e == "KHR_animation_pointer";
  const json& animations = collection(m_doc, "animations", "animations");
  for (size_t a = 0; a < animations.size(); ++a) {
    const std::string aw = idx("animations", a);
    const json& samplers = collection(animations[a], "samplers", aw + ".samplers");
    for (size_t s = 0; s < samplers.size(); ++s) {
      const std::string sw = aw + "." + idx("samplers", s);
      for (const char* key : {"input", "output"}) {
        if (member(samplers[s], key).is_null()) fail(sw + "." + key, "is required");
        index(samplers[s], key, sw, accessors, "accessors");
      }
      const json& interp = member(samplers[s], "interpolation");
      if (!interp.is_null() && interp != "LINEAR" && interp != "STEP" && interp != "CUBICSPLINE")
        fail(sw + ".interpolation", shown(interp) + " is not LINEAR, STEP or CUBICSPLINE");
    }
    const json& channels = collection(animations[a], "channels", aw + ".channels");
    for (size_t c = 0; c < channels.size(); ++c) {
      const std::string cw = aw + "." + idx("channels", c);
      if (member(channels[c], "sampler").is_null()) fail(cw + ".sampler", "is required");
      index(channels[c], "sampler", cw, samplers.size(), "samplers");
      const json& target = member(channels[c], "target");
      if (!target.is_object()) fail(cw + ".target", "must be an object (got " + shown(target) + ")");
      index(target, "node", cw + ".target", nodes, "nodes");
      const json& path = member(target, "path");
      const bool known = path == "translation" || path == "rotation" || path == "scale" ||
                         path == "weights" || (pointer_extension && path == "pointer");
      if (!known) fail(cw + ".target.path", shown(path) + " is not translation, rotation, scale or weights");
    }
  }
}

void JsonChecks::run() {
  if (!m_doc.is_object()) fail("JSON", "the document must be an object (got " + shown(m_doc) + ")");
  extension_names();
  buffers_and_accessors();
  samplers_textures_materials();
  meshes_and_nodes();
  skins_and_animations();
}

}  // namespace

void check_gltf_json(const json& doc, const std::string& file) {
  JsonChecks(doc, file).run();
}

}  // namespace penumbra::gltf
