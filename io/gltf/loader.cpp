// glTF 2.0 loader in phases: the scene file and the GLB container (file_access), the JSON
// depth guard, checks on the raw JSON (json_checks) with the memory budget charged for what
// parsing will hold, URI resolution, tinygltf with sandboxed file callbacks, then validation and
// flattening of the node hierarchy into world-space meshes.
#include "io/gltf/loader.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <cstring>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <set>
#include <span>

#include "io/error.h"
#include "io/file_checks.h"
#include "io/gltf/file_access.h"
#include "io/gltf/json_checks.h"
#include "renderer/scene/animation.h"

namespace penumbra {

namespace fs = std::filesystem;

std::vector<std::string> supported_gltf_extensions() {
  return {"KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_unlit",
          "KHR_materials_ior", "KHR_materials_specular", "KHR_materials_transmission",
          "KHR_texture_transform", "EXT_mesh_gpu_instancing"};
}

int json_nesting_depth(std::string_view json, int limit) {
  int depth = 0, max_depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\') ++i;  // skip the escaped character
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      max_depth = std::max(max_depth, ++depth);
      if (max_depth > limit) return limit + 1;
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
  return max_depth;
}

namespace {

// ---------------------------------------------------------------------------------------------
// Overflow-safe arithmetic for sizes read from the file.
bool add_ok(uint64_t a, uint64_t b, uint64_t& r) { return !__builtin_add_overflow(a, b, &r); }
bool mul_ok(uint64_t a, uint64_t b, uint64_t& r) { return !__builtin_mul_overflow(a, b, &r); }

std::string idx(const char* array, size_t i) { return std::string(array) + "[" + std::to_string(i) + "]"; }

// ---------------------------------------------------------------------------------------------
// The memory budget (GltfLoadOptions::max_memory_bytes): everything that grows with the file is
// charged here before it is allocated.
class MemoryBudget {
 public:
  MemoryBudget(std::string file, uint64_t limit) : m_file(std::move(file)), m_limit(limit) {}
  /// Adds `bytes`, or throws InputError(file, element, "<subject> <bytes>, over the <limit>
  /// budget[ with the rest of the scene]") if the total would exceed the limit.
  void charge(uint64_t bytes, const std::string& element, const std::string& subject) {
    uint64_t total = 0;
    if (!add_ok(m_used, bytes, total) || total > m_limit)
      throw InputError(m_file, element,
                       subject + " " + format_bytes(bytes) + ", over the " + format_bytes(m_limit) +
                           " budget" + (m_used > 0 ? " with the rest of the scene" : ""));
    m_used = total;
  }
  void release(uint64_t bytes) { m_used -= std::min(bytes, m_used); }
  uint64_t used() const { return m_used; }
  uint64_t limit() const { return m_limit; }

 private:
  std::string m_file;
  uint64_t m_limit;
  uint64_t m_used = 0;
};

// Parsing a JSON text of n bytes holds about kParsedBytesPerJsonByte * n bytes: the text itself
// (1x) and tinygltf's copy of a GLB JSON chunk (1x); the nlohmann DOM (kJsonDomBytesPerByte,
// built once by the loader's own checks, then again by tinygltf); the strings and number arrays
// tinygltf copies into its Model (3x; the fixed-size part of each element is charged per element,
// see Converter::charge_elements()). Measured with mallinfo2 and the peak RSS on generated files: the
// DOM is 7.8x the text for 10^5 named nodes with TRS (12 MB), 9.9x for 10^6 bare nodes ("{}",
// 9.4 MB) and 10.8x for 10^6 {"mesh":0} nodes (17 MB); the Model's variable part 2.3x.
constexpr uint64_t kJsonDomBytesPerByte = 11;
constexpr uint64_t kParsedBytesPerJsonByte = 1 + 1 + kJsonDomBytesPerByte + 3;

// Bytes an accelerator allocates per non-identity instance, measured with the peak RSS of
// `penumbra info` on 10^5 and 10^6 EXT_mesh_gpu_instancing instances of one triangle: Embree
// (an instance geometry per placement and the top-level BVH) about 450 bytes, the two-level BVH
// about 400, beyond the scene's Instance.
constexpr uint64_t kAccelBytesPerInstance = 460;

// ---------------------------------------------------------------------------------------------
// File access for tinygltf: it may read only the external files the loader resolved and checked
// before parsing (resolve_uri), each under the name tinygltf will ask for (the base folder
// joined to the decoded URI), and every file read is recorded for GltfInfo::source_files.
struct FsSandbox {
  std::map<std::string, fs::path> served;  // tinygltf's path -> the checked file
  uint64_t max_bytes = 0;
  std::vector<fs::path>* read = nullptr;  // files read, in order
};

// tinygltf's JoinPath: "base/uri" (or "base" + uri if base ends with '/').
std::string tinygltf_join(const std::string& base, const std::string& uri) {
  if (base.empty()) return uri;
  return base.back() == '/' ? base + uri : base + "/" + uri;
}

bool sandbox_file_exists(const std::string& path, void* user) {
  return static_cast<FsSandbox*>(user)->served.count(path) > 0;
}

std::string sandbox_expand(const std::string& path, void*) { return path; }  // no ~ or $VAR

bool sandbox_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  auto& box = *static_cast<FsSandbox*>(user);
  const auto it = box.served.find(path);
  if (it == box.served.end()) {
    if (err) *err = "not a file the loader checked";
    return false;
  }
  try {
    *out = read_input_file(it->second, "", box.max_bytes);
  } catch (const InputError& e) {
    if (err) *err = e.what();
    return false;
  }
  if (std::find(box.read->begin(), box.read->end(), it->second) == box.read->end())
    box.read->push_back(it->second);
  return true;
}

bool sandbox_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

// Images are decoded later through OpenImageIO; tinygltf's decoding is switched off. For URI
// images (files, data URIs) tinygltf hands over the bytes it read: keep them, encoded, in
// Image::image. For bufferView images it passes a pointer computed without a bounds check,
// so those bytes are not touched here; the converter reads the validated bufferView itself.
bool capture_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                   const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

// Decoded image: linear-or-encoded RGBA floats in [0,1] exactly as stored in the file.
struct DecodedImage {
  bool ok = false;
  int width = 0, height = 0;
  std::vector<float> rgba;
};

// Largest texture edge accepted (larger images are ignored with a warning).
constexpr int kMaxTextureSize = 16384;

// ---------------------------------------------------------------------------------------------
// Validated accessor access.
struct AccessorLayout {
  const unsigned char* data = nullptr;  // nullptr: all zeros (no bufferView)
  uint64_t stride = 0;
  uint64_t count = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
  std::vector<std::pair<uint64_t, std::vector<double>>> sparse;  // (index, values), indices increasing
};

class Converter {
 public:
  Converter(const tinygltf::Model& model, std::string file, const GltfLoadOptions& options,
            MemoryBudget& budget, LoadedScene& out)
      : m_model(model), m_file(std::move(file)), m_options(options), m_budget(budget), m_out(out) {}

  void run();
  /// Charges the fixed-size part of every element tinygltf's Model and the converter will hold
  /// for it, counted on the DOM before tinygltf parses. The variable part (names, number arrays)
  /// is in the JSON text's estimate (kParsedBytesPerJsonByte).
  static void charge_elements(const nlohmann::json& doc, MemoryBudget& budget);

 private:
  [[noreturn]] void fail(const std::string& element, const std::string& message) const {
    throw InputError(m_file, element, message);
  }
  void warn(const std::string& element, const std::string& message) {
    m_out.warnings.push_back(element + ": " + message);
  }
  void charge_memory(uint64_t bytes, const std::string& element,
                     const std::string& subject = "its decoded data needs") {
    m_budget.charge(bytes, element, subject);
  }

  /// The bytes of bufferViews[view] after checking that the view and its buffer exist and that
  /// byteOffset + byteLength lies within the buffer; a bad view index names `user`.
  std::span<const unsigned char> buffer_view_bytes(int view, const std::string& user) const;
  AccessorLayout layout(int accessor, const std::string& user);
  double component(const AccessorLayout& l, uint64_t element, int c) const;
  std::vector<double> read(int accessor, const std::string& user, std::initializer_list<int> types,
                           std::initializer_list<int> component_types, bool allow_normalized,
                           bool allow_integer = false);
  std::vector<uint32_t> read_indices(int accessor, const std::string& user);

  /// One glTF primitive decoded and validated in its mesh's local space.
  struct LocalPrimitive {
    std::vector<Vec3f> positions, normals;  // normals empty if absent or unusable
    std::vector<Vec4f> tangents, colors;    // empty if absent
    std::vector<Vec2f> uvs, uvs1;
    std::vector<uint32_t> indices;          // triangle list
    std::vector<std::vector<Vec3f>> target_positions, target_normals;  // morph target deltas
    std::vector<std::array<uint16_t, 4>> joints;  // JOINTS_0 (skinning), empty if absent
    std::vector<Vec4f> weights;                   // WEIGHTS_0
    int material = -1;
    bool usable = false;                    // false: skipped with a warning
  };

  /// Animated values of one node at the requested time (unset fields keep the file's).
  struct NodePose {
    bool has_t = false, has_r = false, has_s = false, has_w = false;
    std::array<double, 3> t{}, s{};
    Quat r;
    std::vector<double> weights;
  };
  void evaluate_animations(double time);
  const Transform& world_of(int node);
  std::vector<NodePose> m_pose;                  // per node
  std::vector<Transform> m_world;                // per node, valid where m_has_world
  std::vector<uint8_t> m_has_world;
  std::vector<int> m_parent;

  void check_extensions();
  const DecodedImage& decoded_image(int image, const std::string& user);
  TextureRef texture_ref(int texture, int texcoord, const tinygltf::ExtensionMap& extensions,
                         bool srgb, const std::string& where);
  void validate_accessors();
  void validate_textures();
  void decode_meshes();
  LocalPrimitive decode_primitive(size_t mesh, size_t prim);
  void convert_materials();
  void validate_cameras();
  void validate_lights();
  void traverse(const std::vector<int>& roots);
  /// A node's mesh placed by `placements` (the node's world transform, or one per
  /// EXT_mesh_gpu_instancing instance). shared: stored once in object space and instanced;
  /// else one world-space copy per placement (skinned meshes always).
  void add_mesh(int mesh_index, int node, const std::vector<Transform>& placements, bool shared);
  /// Emits the usable primitives of a mesh (morphed, placed by `world` or skinned by the joint
  /// matrices). object_ids == nullptr: world-space meshes with identity instances; else the
  /// meshes are appended without instances and their indices recorded there.
  void emit_primitives(int mesh_index, int node, const Transform& world, const std::vector<double>& morph,
                       const std::vector<Transform>& joint_mats, std::vector<int>* object_ids);
  /// EXT_mesh_gpu_instancing: world x T_i R_i S_i per instance, or {world} without the extension.
  std::vector<Transform> placements_of(int node, const Transform& world);
  struct MeshUse {
    int mesh, node;
  };
  /// Charges the placements of a mesh use before they are made: per placement its Transform,
  /// and per primitive an Instance and what an accelerator allocates for it.
  void charge_placements(const MeshUse& use);
  std::vector<MeshUse> m_mesh_uses;  // in traversal order
  std::map<std::pair<int, std::vector<double>>, std::vector<int>> m_object_meshes;  // (mesh, morph) -> Scene::meshes
  void add_camera(int camera_index, int node, const Transform& world);
  void add_light(int light_index, int node, const Transform& world);
  Transform local_transform(int node);

  const tinygltf::Model& m_model;
  std::string m_file;
  const GltfLoadOptions& m_options;
  MemoryBudget& m_budget;
  LoadedScene& m_out;
  std::vector<std::vector<LocalPrimitive>> m_meshes;  // [mesh][primitive]
  std::map<int, DecodedImage> m_images;                // decoded on first use
  std::map<std::pair<int, bool>, int> m_textures;      // (glTF texture, sRGB) -> Scene::textures
};

std::span<const unsigned char> Converter::buffer_view_bytes(int view, const std::string& user) const {
  if (view < 0 || size_t(view) >= m_model.bufferViews.size())
    fail(user, "bufferView " + std::to_string(view) + " out of range (" +
                   std::to_string(m_model.bufferViews.size()) + " bufferViews)");
  const std::string bv_where = idx("bufferViews", size_t(view));
  const tinygltf::BufferView& bv = m_model.bufferViews[size_t(view)];
  if (bv.buffer < 0 || size_t(bv.buffer) >= m_model.buffers.size())
    fail(bv_where, "buffer " + std::to_string(bv.buffer) + " out of range (" +
                       std::to_string(m_model.buffers.size()) + " buffers)");
  const auto& buffer = m_model.buffers[size_t(bv.buffer)].data;
  uint64_t bv_end = 0;
  if (!add_ok(bv.byteOffset, bv.byteLength, bv_end) || bv_end > buffer.size())
    fail(bv_where, "byteOffset " + std::to_string(bv.byteOffset) + " + byteLength " +
                       std::to_string(bv.byteLength) + " exceeds buffer " + std::to_string(bv.buffer) +
                       " of " + std::to_string(buffer.size()) + " bytes");
  return {buffer.data() + bv.byteOffset, size_t(bv.byteLength)};
}

AccessorLayout Converter::layout(int accessor, const std::string& user) {
  const std::string where = idx("accessors", size_t(accessor));
  if (accessor < 0 || size_t(accessor) >= m_model.accessors.size())
    fail(user, "accessor index " + std::to_string(accessor) + " out of range (" +
                   std::to_string(m_model.accessors.size()) + " accessors)");
  const tinygltf::Accessor& a = m_model.accessors[size_t(accessor)];
  AccessorLayout l;
  const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  l.components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  if (comp_size <= 0) fail(where, "invalid componentType " + std::to_string(a.componentType));
  if (l.components <= 0) fail(where, "invalid type");
  l.component_type = a.componentType;
  l.normalized = a.normalized;
  l.count = a.count;
  if (l.count == 0) fail(where, "count must be >= 1");
  const uint64_t elem = uint64_t(comp_size) * uint64_t(l.components);

  uint64_t decoded = 0;
  if (!mul_ok(l.count, uint64_t(l.components) * 8, decoded))
    fail(where, "count " + std::to_string(l.count) + " overflows");
  charge_memory(decoded, where, "decoding its " + std::to_string(l.count) + " elements needs");

  if (a.bufferView >= 0) {
    const std::span<const unsigned char> view = buffer_view_bytes(a.bufferView, where);
    const std::string bv_where = idx("bufferViews", size_t(a.bufferView));
    const tinygltf::BufferView& bv = m_model.bufferViews[size_t(a.bufferView)];
    l.stride = bv.byteStride ? uint64_t(bv.byteStride) : elem;
    if (bv.byteStride != 0 && (bv.byteStride < elem || bv.byteStride > 252 || bv.byteStride % 4))
      fail(bv_where, "byteStride " + std::to_string(bv.byteStride) + " invalid for " +
                         std::to_string(elem) + "-byte elements of " + where);
    uint64_t last = 0, end = 0;
    if (!mul_ok(l.count - 1, l.stride, last) || !add_ok(last, a.byteOffset, end) ||
        !add_ok(end, elem, end) || end > bv.byteLength)
      fail(where, "byteOffset " + std::to_string(a.byteOffset) + " + " + std::to_string(l.count) +
                      " elements (stride " + std::to_string(l.stride) + ") read past the end of " +
                      bv_where + " (" + std::to_string(bv.byteLength) + " bytes)");
    if (a.byteOffset % uint64_t(comp_size) != 0)
      warn(where, "byteOffset " + std::to_string(a.byteOffset) +
                      " is not a multiple of the component size");
    l.data = view.data() + a.byteOffset;
  } else if (!a.sparse.isSparse) {
    warn(where, "no bufferView: values are all zero");
  }

  if (a.sparse.isSparse) {
    const std::string sw = where + ".sparse";
    if (a.sparse.count <= 0 || uint64_t(a.sparse.count) > l.count)
      fail(sw, "count " + std::to_string(a.sparse.count) + " not in [1, " + std::to_string(l.count) + "]");
    const uint64_t n = uint64_t(a.sparse.count);
    charge_memory(n * (sizeof(std::pair<uint64_t, std::vector<double>>) + uint64_t(l.components) * 8 + 16),
                  sw, "its " + std::to_string(n) + " sparse values need");
    auto view_span = [&](int view, uint64_t offset, uint64_t bytes, const std::string& what) {
      const std::span<const unsigned char> span = buffer_view_bytes(view, what);
      uint64_t end = 0;
      if (!add_ok(offset, bytes, end) || end > span.size()) fail(what, "reads past the end of its bufferView");
      return span.data() + offset;
    };
    const int ict = a.sparse.indices.componentType;
    const int isz = tinygltf::GetComponentSizeInBytes(uint32_t(ict));
    if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail(sw + ".indices", "componentType must be an unsigned integer type");
    const unsigned char* ip = view_span(a.sparse.indices.bufferView, uint64_t(a.sparse.indices.byteOffset),
                                        n * uint64_t(isz), sw + ".indices");
    const unsigned char* vp = view_span(a.sparse.values.bufferView, uint64_t(a.sparse.values.byteOffset),
                                        n * elem, sw + ".values");
    AccessorLayout values;
    values.data = vp;
    values.stride = elem;
    values.count = n;
    values.component_type = l.component_type;
    values.components = l.components;
    values.normalized = l.normalized;
    for (uint64_t i = 0; i < n; ++i) {
      uint64_t target = 0;
      if (isz == 1) target = ip[i];
      if (isz == 2) { uint16_t v; std::memcpy(&v, ip + i * 2, 2); target = v; }
      if (isz == 4) { uint32_t v; std::memcpy(&v, ip + i * 4, 4); target = v; }
      if (target >= l.count)
        fail(sw + ".indices", "index " + std::to_string(target) + " >= accessor count " + std::to_string(l.count));
      if (i > 0 && target <= l.sparse.back().first)  // the spec: sparse indices MUST strictly increase
        fail(sw + ".indices", "indices must strictly increase (index " + std::to_string(i) + " is " +
                                  std::to_string(target) + " after " + std::to_string(l.sparse.back().first) +
                                  ")");
      std::vector<double> vals(size_t(l.components));
      for (int c = 0; c < l.components; ++c) vals[size_t(c)] = component(values, i, c);
      l.sparse.emplace_back(target, std::move(vals));
    }
  }
  return l;
}

double Converter::component(const AccessorLayout& l, uint64_t element, int c) const {
  if (!l.data) return 0.0;
  const int size = tinygltf::GetComponentSizeInBytes(uint32_t(l.component_type));
  const unsigned char* p = l.data + element * l.stride + uint64_t(c) * uint64_t(size);
  switch (l.component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { const uint8_t v = *p; return l.normalized ? v / 255.0 : v; }
    case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t v; std::memcpy(&v, p, 1); return l.normalized ? std::max(v / 127.0, -1.0) : v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return l.normalized ? v / 65535.0 : v; }
    case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t v; std::memcpy(&v, p, 2); return l.normalized ? std::max(v / 32767.0, -1.0) : v; }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); return v; }
    default: return 0.0;
  }
}

std::vector<double> Converter::read(int accessor, const std::string& user,
                                    std::initializer_list<int> types,
                                    std::initializer_list<int> component_types, bool allow_normalized,
                                    bool allow_integer) {
  AccessorLayout l = layout(accessor, user);
  const auto& a = m_model.accessors[size_t(accessor)];
  const std::string where = user + " (" + idx("accessors", size_t(accessor)) + ")";
  if (std::find(types.begin(), types.end(), a.type) == types.end())
    fail(where, "unexpected accessor type");
  const bool ok_component = std::find(component_types.begin(), component_types.end(),
                                      a.componentType) != component_types.end();
  const bool is_float = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (!ok_component || (!is_float && !(allow_normalized && a.normalized) && !(allow_integer && !a.normalized)))
    fail(where, "unsupported componentType " + std::to_string(a.componentType) +
                    (a.normalized ? " (normalized)" : ""));
  std::vector<double> out(size_t(l.count) * size_t(l.components));
  for (uint64_t i = 0; i < l.count; ++i)
    for (int c = 0; c < l.components; ++c) out[size_t(i) * size_t(l.components) + size_t(c)] = component(l, i, c);
  for (const auto& [target, vals] : l.sparse)
    for (int c = 0; c < l.components; ++c) out[size_t(target) * size_t(l.components) + size_t(c)] = vals[size_t(c)];
  return out;
}

std::vector<uint32_t> Converter::read_indices(int accessor, const std::string& user) {
  AccessorLayout l = layout(accessor, user);
  const auto& a = m_model.accessors[size_t(accessor)];
  const std::string where = user + " (" + idx("accessors", size_t(accessor)) + ")";
  if (a.type != TINYGLTF_TYPE_SCALAR) fail(where, "indices must be SCALAR");
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    fail(where, "indices componentType must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
  if (a.normalized) fail(where, "indices must not be normalized");
  std::vector<uint32_t> out(size_t(l.count));
  for (uint64_t i = 0; i < l.count; ++i) out[size_t(i)] = uint32_t(component(l, i, 0));
  for (const auto& [target, vals] : l.sparse) out[size_t(target)] = uint32_t(vals[0]);
  return out;
}

void Converter::check_extensions() {
  const auto supported = supported_gltf_extensions();
  for (const auto& e : m_model.extensionsRequired)
    if (std::find(supported.begin(), supported.end(), e) == supported.end())
      fail("extensionsRequired", "extension " + e + " is required by the file but not supported");
  for (const auto& e : m_model.extensionsUsed)
    if (std::find(supported.begin(), supported.end(), e) == supported.end())
      warn("extensionsUsed", "extension " + e + " is not supported and will be ignored");
}

const DecodedImage& Converter::decoded_image(int image_index, const std::string& user) {
  if (auto it = m_images.find(image_index); it != m_images.end()) return it->second;
  DecodedImage& out = m_images[image_index];
  const auto& img = m_model.images[size_t(image_index)];
  const std::string where = idx("images", size_t(image_index)) + (img.name.empty() ? "" : " '" + img.name + "'");
  // The encoded bytes: a validated bufferView, or what tinygltf read from the URI.
  const unsigned char* data = nullptr;
  uint64_t size = 0;
  if (img.bufferView >= 0) {
    const std::span<const unsigned char> view = buffer_view_bytes(img.bufferView, where + ".bufferView");
    data = view.data();
    size = view.size();
  } else {
    data = img.image.data();
    size = img.image.size();
  }
  if (size == 0) {
    warn(where, "image data could not be read" + (img.uri.empty() ? std::string() : " from '" + img.uri + "'") +
                    "; textures using it (" + user + ") are ignored");
    return out;
  }
  // Format from the magic bytes (the mimeType and file extension are only hints).
  std::string ext;
  if (size >= 8 && std::memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0) ext = "png";
  else if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF) ext = "jpg";
  if (ext.empty()) {
    warn(where, "not a PNG or JPEG image; textures using it (" + user + ") are ignored");
    return out;
  }
  OIIO::Filesystem::IOMemReader reader(data, size_t(size));
  OIIO::ImageSpec config;  // glTF colour is not premultiplied: keep RGB where alpha is 0
  config.attribute("oiio:UnassociatedAlpha", 1);
  OIIO::Filesystem::IOProxy* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto in = OIIO::ImageInput::open("image." + ext, &config, &reader);
  if (!in) {
    warn(where, "cannot decode " + ext + " image: " + OIIO::geterror() + "; textures using it are ignored");
    return out;
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.width > kMaxTextureSize || spec.height > kMaxTextureSize ||
      spec.nchannels < 1 || spec.nchannels > 64) {
    warn(where, "image is " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " with " +
                    std::to_string(spec.nchannels) + " channels (limit " + std::to_string(kMaxTextureSize) +
                    " per side); textures using it are ignored");
    return out;
  }
  const uint64_t texels = uint64_t(spec.width) * uint64_t(spec.height);
  charge_memory(
      texels * uint64_t(spec.nchannels) * 4 + texels * 16, where,
      "decoding the " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " image needs");
  std::vector<float> pixels(size_t(texels) * size_t(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    warn(where, "cannot decode " + ext + " image: " + in->geterror() + "; textures using it are ignored");
    return out;
  }
  in->close();
  m_budget.release(texels * uint64_t(spec.nchannels) * 4);  // the channel buffer is freed below
  const int nc = spec.nchannels;
  out.rgba.resize(size_t(texels) * 4);
  for (size_t i = 0; i < size_t(texels); ++i) {
    const float* p = &pixels[i * size_t(nc)];
    float* q = &out.rgba[i * 4];
    if (nc <= 2) {
      q[0] = q[1] = q[2] = p[0];
      q[3] = nc == 2 ? p[1] : 1.0f;
    } else {
      q[0] = p[0];
      q[1] = p[1];
      q[2] = p[2];
      q[3] = nc >= 4 ? p[3] : 1.0f;
    }
  }
  out.width = spec.width;
  out.height = spec.height;
  out.ok = true;
  return out;
}

TextureRef Converter::texture_ref(int texture, int texcoord, const tinygltf::ExtensionMap& extensions,
                                  bool srgb, const std::string& where) {
  TextureRef ref;
  if (texture < 0 || size_t(texture) >= m_model.textures.size()) return ref;  // warned by validate_textures
  const auto& t = m_model.textures[size_t(texture)];
  if (t.source < 0 || size_t(t.source) >= m_model.images.size()) {
    if (t.source < 0) warn(idx("textures", size_t(texture)), "has no image source; ignored");
    return ref;
  }
  // KHR_texture_transform: uv' = T R S uv (spec: offset, rotation counter-clockwise, scale).
  if (auto it = extensions.find("KHR_texture_transform"); it != extensions.end()) {
    const auto& x = it->second;
    const std::string xw = where + ".extensions.KHR_texture_transform";
    double off[2] = {0, 0}, sc[2] = {1, 1}, rot = 0;
    auto read_pair = [&](const char* key, double* v) {
      const auto& a = x.Get(key);
      if (!a.IsArray()) return;
      if (a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber()) fail(xw + "." + key, "must be 2 numbers");
      v[0] = a.Get(0).GetNumberAsDouble();
      v[1] = a.Get(1).GetNumberAsDouble();
    };
    read_pair("offset", off);
    read_pair("scale", sc);
    if (x.Get("rotation").IsNumber()) rot = x.Get("rotation").GetNumberAsDouble();
    if (!std::isfinite(off[0] + off[1] + sc[0] + sc[1] + rot)) fail(xw, "values must be finite");
    if (x.Get("texCoord").IsNumber()) texcoord = x.Get("texCoord").GetNumberAsInt();
    const double c = std::cos(rot), sn = std::sin(rot);
    ref.m[0][0] = float(sc[0] * c);
    ref.m[0][1] = float(sc[1] * sn);
    ref.m[0][2] = float(off[0]);
    ref.m[1][0] = float(-sc[0] * sn);
    ref.m[1][1] = float(sc[1] * c);
    ref.m[1][2] = float(off[1]);
  }
  if (texcoord < 0 || texcoord > 1) {
    warn(where + ".texCoord", "TEXCOORD_" + std::to_string(texcoord) + " is not supported (only 0 and 1); texture ignored");
    return ref;
  }
  ref.texcoord = texcoord;
  if (auto it = m_textures.find({texture, srgb}); it != m_textures.end()) {
    ref.texture = it->second;
    return ref;
  }
  const DecodedImage& img = decoded_image(t.source, where);
  if (!img.ok) {
    m_textures[{texture, srgb}] = -1;
    return ref;
  }
  TextureSampler smp;
  if (t.sampler >= 0 && size_t(t.sampler) < m_model.samplers.size()) {
    const auto& s = m_model.samplers[size_t(t.sampler)];
    const std::string sw = idx("samplers", size_t(t.sampler));
    auto wrap = [&](int mode, const char* field) {
      switch (mode) {
        case TINYGLTF_TEXTURE_WRAP_REPEAT: return TextureWrap::Repeat;
        case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return TextureWrap::ClampToEdge;
        case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return TextureWrap::MirroredRepeat;
        default:
          warn(sw + "." + field, "unknown wrap mode " + std::to_string(mode) + "; REPEAT used");
          return TextureWrap::Repeat;
      }
    };
    smp.wrap_s = wrap(s.wrapS, "wrapS");
    smp.wrap_t = wrap(s.wrapT, "wrapT");
    if (s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST) smp.mag = TextureFilter::Nearest;
    switch (s.minFilter) {
      case TINYGLTF_TEXTURE_FILTER_NEAREST: smp.min = TextureFilter::Nearest; smp.mipmaps = false; break;
      case TINYGLTF_TEXTURE_FILTER_LINEAR: smp.mipmaps = false; break;
      case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST: smp.min = TextureFilter::Nearest; smp.mip = TextureFilter::Nearest; break;
      case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST: smp.mip = TextureFilter::Nearest; break;
      case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR: smp.min = TextureFilter::Nearest; break;
      default: break;  // LINEAR_MIPMAP_LINEAR or unspecified: trilinear
    }
  }
  const uint64_t copy_bytes = uint64_t(img.rgba.size()) * sizeof(float);
  charge_memory(copy_bytes, where, "a working copy of its texels needs");
  std::vector<float> rgba = img.rgba;
  if (srgb)
    for (size_t i = 0; i < rgba.size(); i += 4)
      for (size_t c = 0; c < 3; ++c) rgba[i + c] = srgb_to_linear(std::clamp(rgba[i + c], 0.0f, 1.0f));
  const auto& image = m_model.images[size_t(t.source)];
  charge_memory(texture_bytes_for(img.width, img.height), where, "its MIP-mapped texture needs");
  ref.texture = int(m_out.scene.textures.size());
  m_out.scene.textures.push_back(make_texture(
      idx("textures", size_t(texture)) + " (" + idx("images", size_t(t.source)) +
          (image.name.empty() ? (image.uri.empty() ? "" : " '" + image.uri + "'") : " '" + image.name + "'") + ")",
      img.width, img.height, rgba, smp));
  m_budget.release(copy_bytes);  // rgba is freed on return
  m_textures[{texture, srgb}] = ref.texture;
  return ref;
}

void Converter::convert_materials() {
  auto finite_or_fail = [&](double v, const std::string& where) {
    if (!std::isfinite(v)) fail(where, "value is not finite");
    return v;
  };
  for (size_t i = 0; i < m_model.materials.size(); ++i) {
    const auto& src = m_model.materials[i];
    const std::string where = idx("materials", i);
    Material m;
    m.name = src.name.empty() ? where : src.name;
    const auto& pbr = src.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() != 4) fail(where + ".pbrMetallicRoughness.baseColorFactor", "must have 4 values");
    for (int c = 0; c < 3; ++c)
      m.base_color[c] = float(std::clamp(finite_or_fail(pbr.baseColorFactor[size_t(c)], where + ".pbrMetallicRoughness.baseColorFactor"), 0.0, 1.0));
    m.alpha = float(std::clamp(finite_or_fail(pbr.baseColorFactor[3], where + ".pbrMetallicRoughness.baseColorFactor"), 0.0, 1.0));
    m.metallic = float(std::clamp(finite_or_fail(pbr.metallicFactor, where + ".pbrMetallicRoughness.metallicFactor"), 0.0, 1.0));
    m.roughness = float(std::clamp(finite_or_fail(pbr.roughnessFactor, where + ".pbrMetallicRoughness.roughnessFactor"), 0.0, 1.0));
    if (!src.emissiveFactor.empty()) {
      if (src.emissiveFactor.size() != 3) fail(where + ".emissiveFactor", "must have 3 values");
      for (int c = 0; c < 3; ++c)
        m.emissive[c] = float(std::clamp(finite_or_fail(src.emissiveFactor[size_t(c)], where + ".emissiveFactor"), 0.0, 1.0));
    }
    if (auto it = src.extensions.find("KHR_materials_emissive_strength"); it != src.extensions.end()) {
      const auto& s = it->second.Get("emissiveStrength");
      if (s.IsNumber()) {
        const double strength = finite_or_fail(s.GetNumberAsDouble(), where + ".extensions.KHR_materials_emissive_strength");
        if (strength < 0) fail(where + ".extensions.KHR_materials_emissive_strength", "emissiveStrength must be >= 0");
        m.emissive *= float(strength);
      }
    }
    m.unlit = src.extensions.count("KHR_materials_unlit") > 0;
    // A number in [lo, hi] at extensions.EXT.key (absent: keep the default).
    auto ext_number = [&](const char* ext, const char* key, float& out, double lo, double hi, const char* range) {
      auto it = src.extensions.find(ext);
      if (it == src.extensions.end()) return;
      const auto& v = it->second.Get(key);
      if (v.Type() == tinygltf::NULL_TYPE) return;
      const std::string w = where + ".extensions." + ext + "." + key;
      if (!v.IsNumber()) fail(w, "must be a number");
      const double x = finite_or_fail(v.GetNumberAsDouble(), w);
      if (x < lo || x > hi) fail(w, std::string("must be ") + range);
      out = float(x);
    };
    // ior: >= 1, or 0 (the extension's special case: f0 = 1).
    ext_number("KHR_materials_ior", "ior", m.ior, 0.0, 1e6, "0 or in [1, 1e6]");
    if (m.ior > 0 && m.ior < 1) fail(where + ".extensions.KHR_materials_ior.ior", "must be 0 or in [1, 1e6]");
    ext_number("KHR_materials_specular", "specularFactor", m.specular, 0.0, 1.0, "in [0, 1]");
    ext_number("KHR_materials_transmission", "transmissionFactor", m.transmission, 0.0, 1.0, "in [0, 1]");
    if (auto it = src.extensions.find("KHR_materials_transmission"); it != src.extensions.end() && m.transmission > 0) {
      const auto& info = it->second.Get("transmissionTexture");
      if (info.IsObject() && info.Get("index").IsInt()) {
        tinygltf::ExtensionMap texture_extensions;
        const auto& e = info.Get("extensions");
        if (e.IsObject())
          for (const auto& key : e.Keys()) texture_extensions[key] = e.Get(key);
        const int tc = info.Get("texCoord").IsInt() ? info.Get("texCoord").GetNumberAsInt() : 0;
        m.transmission_tex = texture_ref(info.Get("index").GetNumberAsInt(), tc, texture_extensions, false,
                                         where + ".extensions.KHR_materials_transmission.transmissionTexture");
      }
    }
    if (src.alphaMode == "OPAQUE" || src.alphaMode.empty()) m.alpha_mode = AlphaMode::Opaque;
    else if (src.alphaMode == "MASK") m.alpha_mode = AlphaMode::Mask;
    else if (src.alphaMode == "BLEND") m.alpha_mode = AlphaMode::Blend;
    else fail(where + ".alphaMode", "'" + src.alphaMode + "' is not OPAQUE, MASK or BLEND");
    m.alpha_cutoff = float(finite_or_fail(src.alphaCutoff, where + ".alphaCutoff"));
    if (m.alpha_cutoff < 0) fail(where + ".alphaCutoff", "must be >= 0");
    m.double_sided = src.doubleSided;
    m.base_color_tex = texture_ref(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                   pbr.baseColorTexture.extensions, true, where + ".pbrMetallicRoughness.baseColorTexture");
    m.metallic_roughness_tex = texture_ref(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                                           pbr.metallicRoughnessTexture.extensions, false,
                                           where + ".pbrMetallicRoughness.metallicRoughnessTexture");
    m.normal_tex = texture_ref(src.normalTexture.index, src.normalTexture.texCoord, src.normalTexture.extensions,
                               false, where + ".normalTexture");
    m.normal_scale = float(finite_or_fail(src.normalTexture.scale, where + ".normalTexture.scale"));
    m.occlusion_tex = texture_ref(src.occlusionTexture.index, src.occlusionTexture.texCoord,
                                  src.occlusionTexture.extensions, false, where + ".occlusionTexture");
    m.occlusion_strength = float(std::clamp(finite_or_fail(src.occlusionTexture.strength, where + ".occlusionTexture.strength"), 0.0, 1.0));
    if (max_component(m.emissive) > 0)
      m.emissive_tex = texture_ref(src.emissiveTexture.index, src.emissiveTexture.texCoord,
                                   src.emissiveTexture.extensions, true, where + ".emissiveTexture");
    m_out.scene.materials.push_back(m);
  }
}

void Converter::validate_cameras() {
  for (size_t i = 0; i < m_model.cameras.size(); ++i) {
    const auto& c = m_model.cameras[i];
    const std::string where = idx("cameras", i) + (c.name.empty() ? "" : " '" + c.name + "'");
    auto positive = [&](double v, const char* field) {
      if (!(std::isfinite(v) && v > 0))
        fail(where, std::string(field) + " must be a finite number > 0 (got " + std::to_string(v) + ")");
    };
    if (c.type == "perspective") {
      const auto& p = c.perspective;
      positive(p.yfov, "perspective.yfov");
      if (p.yfov >= kPi) fail(where, "perspective.yfov must be < pi (got " + std::to_string(p.yfov) + ")");
      positive(p.znear, "perspective.znear");
      if (p.aspectRatio != 0) positive(p.aspectRatio, "perspective.aspectRatio");
      if (p.zfar != 0) {
        positive(p.zfar, "perspective.zfar");
        if (p.zfar <= p.znear) fail(where, "perspective.zfar must be greater than znear");
      }
    } else if (c.type == "orthographic") {
      const auto& o = c.orthographic;
      positive(o.xmag, "orthographic.xmag");
      positive(o.ymag, "orthographic.ymag");
      if (!(std::isfinite(o.znear) && o.znear >= 0)) fail(where, "orthographic.znear must be >= 0");
      positive(o.zfar, "orthographic.zfar");
      if (o.zfar <= o.znear) fail(where, "orthographic.zfar must be greater than znear");
    } else {
      fail(where, "unknown camera type '" + c.type + "'");
    }
  }
}

void Converter::validate_lights() {
  for (size_t i = 0; i < m_model.lights.size(); ++i) {
    const auto& l = m_model.lights[i];
    const std::string where = "extensions.KHR_lights_punctual." + idx("lights", i);
    if (l.type != "point" && l.type != "spot" && l.type != "directional")
      fail(where, "unknown light type '" + l.type + "'");
    if (!l.color.empty()) {
      if (l.color.size() != 3) fail(where + ".color", "must have 3 values");
      for (double v : l.color)
        if (!(std::isfinite(v) && v >= 0)) fail(where + ".color", "values must be finite and >= 0");
    }
    if (!(std::isfinite(l.intensity) && l.intensity >= 0)) fail(where + ".intensity", "must be finite and >= 0");
    if (!(std::isfinite(l.range) && l.range >= 0)) fail(where + ".range", "must be finite and > 0");
    if (l.type == "spot") {
      const double in = l.spot.innerConeAngle, out = l.spot.outerConeAngle;
      if (!(std::isfinite(in) && std::isfinite(out) && in >= 0 && in < out && out <= kPi / 2 + 1e-6))
        fail(where + ".spot", "cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
    }
  }
}

Transform Converter::local_transform(int node) {
  const auto& n = m_model.nodes[size_t(node)];
  const std::string where = idx("nodes", size_t(node));
  if (!n.matrix.empty()) {
    if (n.matrix.size() != 16) fail(where + ".matrix", "must have 16 values");
    Transform t = from_column_major(n.matrix.data());
    if (!is_finite(t)) fail(where + ".matrix", "contains NaN or infinite values");
    return t;
  }
  std::array<double, 3> tr{0, 0, 0}, sc{1, 1, 1};
  Quat q;
  if (!n.translation.empty()) {
    if (n.translation.size() != 3) fail(where + ".translation", "must have 3 values");
    std::copy(n.translation.begin(), n.translation.end(), tr.begin());
  }
  if (!n.scale.empty()) {
    if (n.scale.size() != 3) fail(where + ".scale", "must have 3 values");
    std::copy(n.scale.begin(), n.scale.end(), sc.begin());
  }
  if (!n.rotation.empty()) {
    if (n.rotation.size() != 4) fail(where + ".rotation", "must have 4 values");
    q = {n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]};
    const double len = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
    if (!std::isfinite(len) || len < 1e-6) fail(where + ".rotation", "is not a unit quaternion (length " + std::to_string(len) + ")");
    if (std::fabs(len - 1) > 1e-3) warn(where + ".rotation", "quaternion not normalised (length " + std::to_string(len) + "); normalising");
  }
  if (size_t(node) < m_pose.size()) {  // animation channels override the static TRS
    const NodePose& pose = m_pose[size_t(node)];
    if (pose.has_t) tr = pose.t;
    if (pose.has_r) q = pose.r;
    if (pose.has_s) sc = pose.s;
  }
  for (double v : tr) if (!std::isfinite(v)) fail(where + ".translation", "contains NaN or infinite values");
  for (double v : sc) if (!std::isfinite(v)) fail(where + ".scale", "contains NaN or infinite values");
  return compose_trs(tr, q, sc);
}

const Transform& Converter::world_of(int node) {
  // Walk up to the first ancestor with a known world transform (or a root), then down.
  std::vector<int> chain;
  for (int cur = node; cur >= 0 && !m_has_world[size_t(cur)]; cur = m_parent[size_t(cur)]) chain.push_back(cur);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
    const int p = m_parent[size_t(*it)];
    const Transform world = (p >= 0 ? m_world[size_t(p)] : Transform{}) * local_transform(*it);
    if (!is_finite(world)) fail(idx("nodes", size_t(*it)), "world transform overflows to non-finite values");
    m_world[size_t(*it)] = world;
    m_has_world[size_t(*it)] = 1;
  }
  return m_world[size_t(node)];
}

void Converter::evaluate_animations(double time) {
  m_pose.assign(m_model.nodes.size(), NodePose{});
  for (size_t ai = 0; ai < m_model.animations.size(); ++ai) {
    const auto& anim = m_model.animations[ai];
    const std::string aw = idx("animations", ai);
    for (size_t ci = 0; ci < anim.channels.size(); ++ci) {
      const auto& ch = anim.channels[ci];
      const std::string cw = aw + "." + idx("channels", ci);
      if (ch.sampler < 0 || size_t(ch.sampler) >= anim.samplers.size())
        fail(cw + ".sampler", "sampler index " + std::to_string(ch.sampler) + " out of range (" +
                                  std::to_string(anim.samplers.size()) + " samplers)");
      if (ch.target_node < 0) continue;  // no target node: nothing to animate (spec allows it)
      if (size_t(ch.target_node) >= m_model.nodes.size())
        fail(cw + ".target.node", "node index " + std::to_string(ch.target_node) + " out of range (" +
                                      std::to_string(m_model.nodes.size()) + " nodes)");
      const auto& smp = anim.samplers[size_t(ch.sampler)];
      const std::string sw = aw + "." + idx("samplers", size_t(ch.sampler));
      Interpolation interp = Interpolation::Linear;
      if (smp.interpolation == "STEP") interp = Interpolation::Step;
      else if (smp.interpolation == "CUBICSPLINE") interp = Interpolation::CubicSpline;
      else if (smp.interpolation != "LINEAR" && !smp.interpolation.empty())
        fail(sw + ".interpolation", "'" + smp.interpolation + "' is not STEP, LINEAR or CUBICSPLINE");
      const std::string& path = ch.target_path;
      size_t width = 0;
      if (path == "translation" || path == "scale") width = 3;
      else if (path == "rotation") width = 4;
      else if (path == "weights") width = 0;  // from the counts below
      else {
        warn(cw + ".target.path", "path '" + path + "' is not supported; channel ignored");
        continue;
      }
      const auto in = read(smp.input, sw + ".input", {TINYGLTF_TYPE_SCALAR}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
      const auto outv = read(smp.output, sw + ".output",
                             {width == 3 ? TINYGLTF_TYPE_VEC3 : (width == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_SCALAR)},
                             {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                              TINYGLTF_COMPONENT_TYPE_SHORT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, true);
      std::vector<float> times(in.begin(), in.end()), values(outv.begin(), outv.end());
      for (size_t k = 0; k < times.size(); ++k)
        if (!std::isfinite(times[k]) || (k > 0 && times[k] < times[k - 1]))
          fail(sw + ".input", "key times must be finite and non-decreasing (key " + std::to_string(k) + ")");
      for (float v : values)
        if (!std::isfinite(v)) fail(sw + ".output", "values must be finite");
      const size_t per_key = interp == Interpolation::CubicSpline ? 3 : 1;
      if (width == 0) {  // weights: one value per morph target per key
        if (values.size() % (times.size() * per_key) != 0)
          fail(sw + ".output", "count " + std::to_string(values.size()) + " is not a multiple of " +
                                   std::to_string(times.size() * per_key) + " (keys x morph targets)");
        width = values.size() / (times.size() * per_key);
      } else if (values.size() != times.size() * per_key * width) {
        fail(sw + ".output", "has " + std::to_string(values.size() / width) + " elements; " +
                                 std::to_string(times.size() * per_key) + " expected for " +
                                 std::to_string(times.size()) + " keys");
      }
      std::vector<double> v(width);
      sample_track(times, values, width, interp, path == "rotation", time, v.data());
      NodePose& pose = m_pose[size_t(ch.target_node)];
      if (path == "translation") { pose.has_t = true; pose.t = {v[0], v[1], v[2]}; }
      else if (path == "scale") { pose.has_s = true; pose.s = {v[0], v[1], v[2]}; }
      else if (path == "rotation") { pose.has_r = true; pose.r = {v[0], v[1], v[2], v[3]}; }
      else { pose.has_w = true; pose.weights = v; }
    }
  }
}

void Converter::traverse(const std::vector<int>& roots) {
  const size_t n = m_model.nodes.size();
  // Phase 1: validate child references, parent uniqueness and acyclicity without recursion.
  std::vector<int> parent(n, -1);
  for (size_t i = 0; i < n; ++i) {
    for (int c : m_model.nodes[i].children) {
      if (c < 0 || size_t(c) >= n)
        fail(idx("nodes", i) + ".children", "node index " + std::to_string(c) + " out of range (" + std::to_string(n) + " nodes)");
      if (size_t(c) == i) fail(idx("nodes", i) + ".children", "node is its own child");
      if (parent[size_t(c)] >= 0)
        fail(idx("nodes", size_t(c)), "has more than one parent (nodes[" + std::to_string(parent[size_t(c)]) +
                                          "] and nodes[" + std::to_string(i) + "])");
      parent[size_t(c)] = int(i);
    }
  }
  // With at most one parent each, a cycle is a loop of parent links; find one iteratively.
  std::vector<uint8_t> state(n, 0);  // 0 unvisited, 1 on the current parent chain, 2 done
  std::vector<size_t> path;
  for (size_t i = 0; i < n; ++i) {
    path.clear();
    size_t cur = i;
    bool cycle = false;
    while (state[cur] != 2) {
      if (state[cur] == 1) {
        cycle = true;
        break;
      }
      state[cur] = 1;
      path.push_back(cur);
      if (parent[cur] < 0) break;
      cur = size_t(parent[cur]);
    }
    if (cycle) fail(idx("nodes", cur), "is part of a node cycle");
    for (size_t p : path) state[p] = 2;
  }
  m_parent = parent;
  m_world.assign(n, Transform{});
  m_has_world.assign(n, 0);
  // Phase 2: depth-first traversal with an explicit stack; each node's world transform is
  // parent * local (world_of), computed once.
  std::set<int> seen_roots;
  std::vector<int> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) {
    const int r = *it;
    if (r < 0 || size_t(r) >= n) fail("scenes.nodes", "node index " + std::to_string(r) + " out of range (" + std::to_string(n) + " nodes)");
    if (parent[size_t(r)] >= 0) fail(idx("nodes", size_t(r)), "is listed as a scene root but is a child of nodes[" + std::to_string(parent[size_t(r)]) + "]");
    if (!seen_roots.insert(r).second) fail(idx("nodes", size_t(r)), "listed twice as a scene root");
    stack.push_back(r);
  }
  while (!stack.empty()) {
    const int index = stack.back();
    stack.pop_back();
    const auto& node = m_model.nodes[size_t(index)];
    const Transform world = world_of(index);  // the parent's is known: pre-order
    if (node.mesh >= 0 || node.mesh < -1) m_mesh_uses.push_back({node.mesh, index});
    if (node.camera >= 0 || node.camera < -1) add_camera(node.camera, index, world);
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end()) {
      const auto& li = it->second.Get("light");
      if (!li.IsNumber()) fail(idx("nodes", size_t(index)) + ".extensions.KHR_lights_punctual.light", "must be an integer");
      add_light(int(li.GetNumberAsInt()), index, world);
    }
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back(*c);
  }
  // Meshes placed more than once are stored once and instanced (unless flattening is asked
  // for); a mesh placed once is put in world space, as Cycles applies the transform of a mesh
  // with one user, so single-level scenes keep single-level structures.
  std::vector<std::vector<Transform>> placements;
  std::map<int, uint64_t> uses;
  for (const MeshUse& u : m_mesh_uses) {
    charge_placements(u);
    placements.push_back(placements_of(u.node, m_world[size_t(u.node)]));
    if (u.mesh >= 0) uses[u.mesh] += placements.back().size();
  }
  for (size_t k = 0; k < m_mesh_uses.size(); ++k) {
    const MeshUse& u = m_mesh_uses[k];
    add_mesh(u.mesh, u.node, placements[k], !m_options.flatten && uses[u.mesh] > 1);
  }
}

Converter::LocalPrimitive Converter::decode_primitive(size_t mesh_index, size_t pi) {
  const auto& prim = m_model.meshes[mesh_index].primitives[pi];
  const std::string where = idx("meshes", mesh_index) + "." + idx("primitives", pi);
  LocalPrimitive out;
  if (prim.mode >= 0 && prim.mode <= 3) {
    warn(where, "points/lines primitive (mode " + std::to_string(prim.mode) + ") skipped");
    return out;
  }
  if (prim.mode != 4 && prim.mode != 5 && prim.mode != 6) fail(where, "invalid mode " + std::to_string(prim.mode));
  if (prim.material < -1 || prim.material >= int(m_model.materials.size()))
    fail(where + ".material", "material index " + std::to_string(prim.material) + " out of range (" +
                                  std::to_string(m_model.materials.size()) + " materials)");
  out.material = prim.material;
  const auto pos_it = prim.attributes.find("POSITION");
  if (pos_it == prim.attributes.end()) {
    warn(where, "no POSITION attribute; skipped");
    return out;
  }
  const auto pos = read(pos_it->second, where + ".attributes.POSITION", {TINYGLTF_TYPE_VEC3},
                        {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
  const size_t nv = pos.size() / 3;
  if (nv >= 0xffffffffu) fail(where, "too many vertices");

  // Indices (or the implicit 0..n-1), validated against the vertex count.
  std::vector<uint32_t> raw;
  if (prim.indices >= 0 || prim.indices < -1) {
    raw = read_indices(prim.indices, where + ".indices");
    for (uint32_t i : raw)
      if (i >= nv) fail(where, "index " + std::to_string(i) + " >= vertex count " + std::to_string(nv));
  } else {
    raw.resize(nv);
    for (size_t i = 0; i < nv; ++i) raw[i] = uint32_t(i);
  }
  // Triangle list from the topology (glTF spec 3.7.2.1, "Topology Types").
  auto& tris = out.indices;
  if (prim.mode == 4) {
    if (raw.size() % 3) warn(where, "index count " + std::to_string(raw.size()) + " not a multiple of 3; extra indices ignored");
    tris.assign(raw.begin(), raw.begin() + ptrdiff_t(raw.size() / 3 * 3));
  } else if (prim.mode == 5) {
    for (size_t i = 0; i + 2 < raw.size(); ++i) {
      const bool odd = i % 2;
      tris.insert(tris.end(), {raw[i], raw[i + (odd ? 2 : 1)], raw[i + (odd ? 1 : 2)]});
    }
  } else {
    for (size_t i = 1; i + 1 < raw.size(); ++i) tris.insert(tris.end(), {raw[i], raw[i + 1], raw[0]});
  }

  // Attributes must all have the POSITION count; read them before deciding to drop anything.
  std::vector<double> nrm, uv;
  if (auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
    nrm = read(it->second, where + ".attributes.NORMAL", {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    if (nrm.size() != pos.size()) fail(where + ".attributes.NORMAL", "count differs from POSITION count");
  }
  std::vector<double> uv1, tan, col;
  int col_components = 0;
  for (const char* name : {"TEXCOORD_0", "TEXCOORD_1"}) {
    auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) continue;
    auto& dst = name[9] == '0' ? uv : uv1;
    dst = read(it->second, where + ".attributes." + name, {TINYGLTF_TYPE_VEC2},
               {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, true);
    if (dst.size() / 2 != nv) fail(where + ".attributes." + name, "count differs from POSITION count");
  }
  if (auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end()) {
    tan = read(it->second, where + ".attributes.TANGENT", {TINYGLTF_TYPE_VEC4}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    if (tan.size() / 4 != nv) fail(where + ".attributes.TANGENT", "count differs from POSITION count");
  }
  if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end()) {
    col = read(it->second, where + ".attributes.COLOR_0", {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4},
               {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, true);
    col_components = m_model.accessors[size_t(it->second)].type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
    if (col.size() / size_t(col_components) != nv) fail(where + ".attributes.COLOR_0", "count differs from POSITION count");
  }
  if (tris.empty()) {
    warn(where, "no triangles; skipped");
    return out;
  }
  out.positions.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    out.positions[i] = {float(pos[i * 3]), float(pos[i * 3 + 1]), float(pos[i * 3 + 2])};
    if (!is_finite(out.positions[i]) || max_component(abs(out.positions[i])) > 1e18f) {
      warn(where, "POSITION has NaN, infinite or huge (> 1e18) values; primitive dropped");
      return out;
    }
  }
  if (!nrm.empty()) {
    out.normals.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      out.normals[i] = {float(nrm[i * 3]), float(nrm[i * 3 + 1]), float(nrm[i * 3 + 2])};
      if (!is_finite(out.normals[i]) || !(dot(out.normals[i], out.normals[i]) > 0)) {
        warn(where + ".attributes.NORMAL", "zero, NaN or infinite normals; computing smooth normals instead");
        out.normals.clear();
        break;
      }
    }
  }
  auto finite_or_zero = [](double v) { return std::isfinite(v) ? float(v) : 0.0f; };
  // Morph targets: POSITION and NORMAL displacements (glTF 3.7.2.2).
  for (size_t ti = 0; ti < prim.targets.size(); ++ti) {
    const std::string tw = where + "." + idx("targets", ti);
    std::vector<Vec3f> dp(nv), dn;
    for (const auto& [name, accessor] : prim.targets[ti]) {
      if (name != "POSITION" && name != "NORMAL") continue;
      const auto d = read(accessor, tw + "." + name, {TINYGLTF_TYPE_VEC3},
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT}, true);
      if (d.size() != nv * 3) fail(tw + "." + name, "count differs from POSITION count");
      auto& dst = name == "POSITION" ? dp : dn;
      dst.resize(nv);
      for (size_t i = 0; i < nv; ++i) dst[i] = {finite_or_zero(d[i * 3]), finite_or_zero(d[i * 3 + 1]), finite_or_zero(d[i * 3 + 2])};
    }
    out.target_positions.push_back(std::move(dp));
    out.target_normals.push_back(std::move(dn));
  }
  // Skinning attributes (glTF 3.7.3): JOINTS_0 with WEIGHTS_0.
  if (auto jt = prim.attributes.find("JOINTS_0"), wt = prim.attributes.find("WEIGHTS_0");
      jt != prim.attributes.end() && wt != prim.attributes.end()) {
    const auto j = read(jt->second, where + ".attributes.JOINTS_0", {TINYGLTF_TYPE_VEC4},
                        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, false, true);
    const auto w = read(wt->second, where + ".attributes.WEIGHTS_0", {TINYGLTF_TYPE_VEC4},
                        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT}, true);
    if (j.size() != nv * 4 || w.size() != nv * 4) fail(where + ".attributes.JOINTS_0", "JOINTS_0/WEIGHTS_0 counts differ from POSITION count");
    out.joints.resize(nv);
    out.weights.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      for (size_t c = 0; c < 4; ++c) out.joints[i][c] = uint16_t(j[i * 4 + c]);
      out.weights[i] = {finite_or_zero(w[i * 4]), finite_or_zero(w[i * 4 + 1]), finite_or_zero(w[i * 4 + 2]), finite_or_zero(w[i * 4 + 3])};
    }
  }
  if (!uv.empty()) {
    out.uvs.resize(nv);
    for (size_t i = 0; i < nv; ++i) out.uvs[i] = {finite_or_zero(uv[i * 2]), finite_or_zero(uv[i * 2 + 1])};
  }
  if (!uv1.empty()) {
    out.uvs1.resize(nv);
    for (size_t i = 0; i < nv; ++i) out.uvs1[i] = {finite_or_zero(uv1[i * 2]), finite_or_zero(uv1[i * 2 + 1])};
  }
  if (!tan.empty()) {
    out.tangents.resize(nv);
    for (size_t i = 0; i < nv; ++i) {
      const Vec3f t{float(tan[i * 4]), float(tan[i * 4 + 1]), float(tan[i * 4 + 2])};
      if (!is_finite(t) || !(dot(t, t) > 0) || !std::isfinite(tan[i * 4 + 3])) {
        warn(where + ".attributes.TANGENT", "zero, NaN or infinite tangents; generating tangents instead");
        out.tangents.clear();
        break;
      }
      out.tangents[i] = {t.x, t.y, t.z, tan[i * 4 + 3] < 0 ? -1.0f : 1.0f};
    }
  }
  if (!col.empty()) {
    out.colors.resize(nv);
    const size_t k = size_t(col_components);
    for (size_t i = 0; i < nv; ++i) {
      auto c = [&](size_t j) { return std::clamp(finite_or_zero(col[i * k + j]), 0.0f, 1.0f); };
      out.colors[i] = {c(0), c(1), c(2), k == 4 ? c(3) : 1.0f};
    }
  }
  out.usable = true;
  return out;
}

void Converter::decode_meshes() {
  m_meshes.resize(m_model.meshes.size());
  for (size_t m = 0; m < m_model.meshes.size(); ++m)
    for (size_t p = 0; p < m_model.meshes[m].primitives.size(); ++p) m_meshes[m].push_back(decode_primitive(m, p));
}

void Converter::add_mesh(int mesh_index, int node, const std::vector<Transform>& placements, bool shared) {
  const std::string node_where = idx("nodes", size_t(node));
  if (mesh_index < 0 || size_t(mesh_index) >= m_model.meshes.size())
    fail(node_where + ".mesh", "mesh index " + std::to_string(mesh_index) + " out of range (" +
                                   std::to_string(m_model.meshes.size()) + " meshes)");
  const auto& mesh = m_model.meshes[size_t(mesh_index)];
  const auto& gnode = m_model.nodes[size_t(node)];
  // Morph weights: animated, else the node's, else the mesh's defaults (glTF 3.7.2.2).
  std::vector<double> morph = mesh.weights;
  if (!gnode.weights.empty()) morph = gnode.weights;
  if (size_t(node) < m_pose.size() && m_pose[size_t(node)].has_w) morph = m_pose[size_t(node)].weights;
  // A non-finite weight contributes nothing (emit_primitives skips it); zeroing it keeps the
  // weights usable as a key of m_object_meshes (NaN has no order).
  for (double& w : morph)
    if (!std::isfinite(w)) w = 0;
  // Skin: joint matrices J_k = world(joint k) x inverseBindMatrix k; a skinned mesh ignores its
  // node's own transform (glTF 3.7.3.3).
  std::vector<Transform> joint_mats;
  if (gnode.skin >= 0 || gnode.skin < -1) {
    if (gnode.skin < 0 || size_t(gnode.skin) >= m_model.skins.size())
      fail(node_where + ".skin", "skin index " + std::to_string(gnode.skin) + " out of range (" +
                                     std::to_string(m_model.skins.size()) + " skins)");
    const auto& skin = m_model.skins[size_t(gnode.skin)];
    const std::string sw = idx("skins", size_t(gnode.skin));
    if (skin.joints.empty()) fail(sw + ".joints", "must not be empty");
    std::vector<double> ibm;
    if (skin.inverseBindMatrices >= 0) {
      ibm = read(skin.inverseBindMatrices, sw + ".inverseBindMatrices", {TINYGLTF_TYPE_MAT4}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
      if (ibm.size() < skin.joints.size() * 16)
        fail(sw + ".inverseBindMatrices", "has fewer matrices than the skin has joints");
    }
    for (size_t k = 0; k < skin.joints.size(); ++k) {
      const int j = skin.joints[k];
      if (j < 0 || size_t(j) >= m_model.nodes.size())
        fail(sw + ".joints", "node index " + std::to_string(j) + " out of range");
      Transform inv_bind;
      if (!ibm.empty()) inv_bind = from_column_major(&ibm[k * 16]);
      joint_mats.push_back(world_of(j) * inv_bind);
    }
    if (placements.size() != 1) warn(node_where, "EXT_mesh_gpu_instancing on a skinned mesh is ignored");
    emit_primitives(mesh_index, node, m_world[size_t(node)], morph, joint_mats, nullptr);
    return;
  }
  uint64_t singular = 0;
  if (!shared) {
    for (const Transform& world : placements) {
      Transform inv;
      if (!inverse(world, inv)) {
        ++singular;
        continue;
      }
      emit_primitives(mesh_index, node, world, morph, {}, nullptr);
    }
  } else {
    auto [it, inserted] = m_object_meshes.try_emplace({mesh_index, morph});
    if (inserted) emit_primitives(mesh_index, -1, Transform{}, morph, {}, &it->second);
    std::vector<Bounds3f> object_bounds;
    for (int id : it->second) {
      Bounds3f b;
      for (Vec3f p : m_out.scene.meshes[size_t(id)].positions) b = merge(b, p);
      object_bounds.push_back(b);
    }
    for (size_t k = 0; k < placements.size(); ++k) {
      Instance inst;
      try {
        inst = make_instance(0, to_affine(placements[k]), node);
      } catch (const std::invalid_argument&) {
        ++singular;
        continue;
      }
      inst.copy = gnode.extensions.count("EXT_mesh_gpu_instancing") ? int(k) : -1;
      bool usable = true;  // world-space corners finite and not huge, as for flattened meshes
      for (const Bounds3f& b : object_bounds) {
        const Bounds3f w = transform_bounds(inst.to_world, b);
        usable = usable && (b.empty() || (is_finite(w.lo) && is_finite(w.hi) &&
                                          std::max(max_component(abs(w.lo)), max_component(abs(w.hi))) <= 1e18f));
      }
      if (!usable) {
        ++singular;
        continue;
      }
      for (int id : it->second) {
        inst.mesh = id;
        m_out.scene.instances.push_back(inst);
      }
    }
  }
  if (singular == 1 && placements.size() == 1)
    warn(node_where, "singular, non-finite or huge transform; mesh " + std::to_string(mesh_index) + " skipped");
  else if (singular > 0)
    warn(node_where + ".extensions.EXT_mesh_gpu_instancing", std::to_string(singular) + " of " +
                                                                 std::to_string(placements.size()) +
                                                                 " instances have a singular, non-finite or huge transform; skipped");
}

void Converter::charge_placements(const MeshUse& use) {
  if (use.mesh < 0 || size_t(use.mesh) >= m_model.meshes.size()) return;  // add_mesh reports it
  const auto& gnode = m_model.nodes[size_t(use.node)];
  uint64_t count = 1;
  std::string where = idx("nodes", size_t(use.node));
  if (const auto ext = gnode.extensions.find("EXT_mesh_gpu_instancing"); ext != gnode.extensions.end()) {
    // The instance count from the accessors' declared counts, before any is decoded (placements_of
    // checks that they agree).
    const tinygltf::Value& attributes = ext->second.Get("attributes");
    where += ".extensions.EXT_mesh_gpu_instancing";
    for (const char* name : {"TRANSLATION", "ROTATION", "SCALE"}) {
      if (!attributes.IsObject() || !attributes.Has(name) || !attributes.Get(name).IsInt()) continue;
      const int a = attributes.Get(name).Get<int>();
      if (a >= 0 && size_t(a) < m_model.accessors.size())
        count = std::max<uint64_t>(count, m_model.accessors[size_t(a)].count);
    }
  }
  const uint64_t primitives = std::max<uint64_t>(1, m_model.meshes[size_t(use.mesh)].primitives.size());
  const uint64_t per_placement = sizeof(Transform) + primitives * (sizeof(Instance) + kAccelBytesPerInstance);
  uint64_t bytes = 0;
  if (!mul_ok(count, per_placement, bytes)) bytes = UINT64_MAX;
  charge_memory(bytes, where, std::to_string(count) + (count == 1 ? " instance needs" : " instances need"));
}

std::vector<Transform> Converter::placements_of(int node, const Transform& world) {
  const auto& gnode = m_model.nodes[size_t(node)];
  const auto ext = gnode.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == gnode.extensions.end()) return {world};
  const std::string where = idx("nodes", size_t(node)) + ".extensions.EXT_mesh_gpu_instancing";
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  // tinygltf stores an empty JSON object (and a missing member) as a null value.
  if (attributes.Type() == tinygltf::NULL_TYPE) {
    warn(where + ".attributes", "no TRANSLATION, ROTATION or SCALE; the mesh is placed once");
    return {world};
  }
  if (!attributes.IsObject()) fail(where + ".attributes", "must be an object");
  // TRANSLATION (VEC3 float), ROTATION (VEC4 float or normalized byte/short), SCALE (VEC3 float).
  std::vector<double> values[3];
  const char* names[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  uint64_t count = 0;
  std::string first;
  for (int k = 0; k < 3; ++k) {
    if (!attributes.Has(names[k])) continue;
    const std::string aw = where + ".attributes." + names[k];
    const tinygltf::Value& a = attributes.Get(names[k]);
    if (!a.IsInt()) fail(aw, "must be an accessor index");
    if (k == 1)
      values[k] = read(a.Get<int>(), aw, {TINYGLTF_TYPE_VEC4},
                       {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_COMPONENT_TYPE_SHORT}, true);
    else
      values[k] = read(a.Get<int>(), aw, {TINYGLTF_TYPE_VEC3}, {TINYGLTF_COMPONENT_TYPE_FLOAT}, false);
    const uint64_t n = values[k].size() / (k == 1 ? 4 : 3);
    if (!first.empty() && n != count)
      fail(aw, "has " + std::to_string(n) + " elements but " + first + " has " + std::to_string(count) +
                   " (all instance attributes must have the same count)");
    if (first.empty()) first = names[k];
    count = n;
  }
  for (const auto& key : attributes.Keys())
    if (key != "TRANSLATION" && key != "ROTATION" && key != "SCALE" && (key.empty() || key[0] != '_'))
      warn(where + ".attributes." + key, "unknown instance attribute; ignored");
  if (first.empty()) {
    warn(where + ".attributes", "no TRANSLATION, ROTATION or SCALE; the mesh is placed once");
    return {world};
  }
  std::vector<Transform> out;
  out.reserve(size_t(count));
  for (size_t i = 0; i < count; ++i) {
    std::array<double, 3> t{0, 0, 0}, sc{1, 1, 1};
    Quat q;
    if (!values[0].empty()) t = {values[0][3 * i], values[0][3 * i + 1], values[0][3 * i + 2]};
    if (!values[1].empty()) q = {values[1][4 * i], values[1][4 * i + 1], values[1][4 * i + 2], values[1][4 * i + 3]};
    if (!values[2].empty()) sc = {values[2][3 * i], values[2][3 * i + 1], values[2][3 * i + 2]};
    out.push_back(world * compose_trs(t, q, sc));  // NodeWorldXform x InstanceXform
  }
  return out;
}

void Converter::emit_primitives(int mesh_index, int node, const Transform& world, const std::vector<double>& morph,
                                const std::vector<Transform>& joint_mats, std::vector<int>* object_ids) {
  const std::string node_where = node >= 0 ? idx("nodes", size_t(node)) : "object space (instanced mesh)";
  const auto& mesh = m_model.meshes[size_t(mesh_index)];
  Transform inv;
  if (!inverse(world, inv)) return;  // callers skip singular placements
  const bool flip = !joint_mats.empty() ? determinant3x3(joint_mats[0]) < 0
                                        : determinant3x3(world) < 0;  // mirrored: keep counter-clockwise = front
  for (size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
    const LocalPrimitive& local = m_meshes[size_t(mesh_index)][pi];
    if (!local.usable) continue;
    const std::string where = idx("meshes", size_t(mesh_index)) + "." + idx("primitives", pi);
    charge_memory(uint64_t(local.indices.size()) * 4 + uint64_t(local.positions.size()) * 96, where,
                  "a placed copy needs");
    Mesh out;
    out.name = (mesh.name.empty() ? idx("meshes", size_t(mesh_index)) : mesh.name) + "[" + std::to_string(pi) + "]";
    out.node = node;
    out.material = local.material;
    // Morphed local positions and normals.
    std::vector<Vec3f> lp = local.positions, ln = local.normals;
    for (size_t t = 0; t < local.target_positions.size() && t < morph.size(); ++t) {
      const float w = float(morph[t]);
      if (w == 0 || !std::isfinite(w)) continue;
      for (size_t i = 0; i < lp.size(); ++i) lp[i] += local.target_positions[t][i] * w;
      if (!ln.empty() && !local.target_normals[t].empty())
        for (size_t i = 0; i < ln.size(); ++i) ln[i] += local.target_normals[t][i] * w;
    }
    // Per-vertex transforms: the node's world transform, or the blended joint matrices.
    const bool skinned = !joint_mats.empty() && !local.joints.empty();
    std::vector<Transform> vertex_xf;
    if (skinned) {
      vertex_xf.resize(lp.size());
      for (size_t i = 0; i < lp.size(); ++i) {
        Transform b;
        b.m = {};
        const float wsum = local.weights[i].x + local.weights[i].y + local.weights[i].z + local.weights[i].w;
        const float wk[4] = {local.weights[i].x, local.weights[i].y, local.weights[i].z, local.weights[i].w};
        for (size_t k = 0; k < 4; ++k) {
          if (wk[k] == 0) continue;
          const size_t j = local.joints[i][k];
          if (j >= joint_mats.size())
            fail(where + ".attributes.JOINTS_0", "joint " + std::to_string(j) + " >= skin joint count " + std::to_string(joint_mats.size()));
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) b.m[size_t(r)][size_t(c)] += double(wk[k] / (wsum > 0 ? wsum : 1)) * joint_mats[j].m[size_t(r)][size_t(c)];
        }
        vertex_xf[i] = wsum > 0 ? b : world;
      }
    }
    out.positions.resize(lp.size());
    for (size_t i = 0; i < lp.size(); ++i) {
      out.positions[i] = transform_point(skinned ? vertex_xf[i] : world, lp[i]);
      if (!is_finite(out.positions[i]) || max_component(abs(out.positions[i])) > 1e18f) {
        warn(where + " in " + node_where, "world-space positions are NaN, infinite or huge; dropped");
        out.positions.clear();
        break;
      }
    }
    if (out.positions.empty()) continue;
    out.indices = local.indices;
    if (flip)
      for (size_t i = 0; i < out.indices.size(); i += 3) std::swap(out.indices[i + 1], out.indices[i + 2]);
    if (!ln.empty()) {
      out.normals.resize(ln.size());
      for (size_t i = 0; i < ln.size(); ++i) {
        Transform vinv = inv;
        if (skinned && !inverse(vertex_xf[i], vinv)) vinv = inv;
        out.normals[i] = normalize(transform_normal(vinv, ln[i]));
      }
    } else {
      out.normals = compute_smooth_normals(out.positions, out.indices);
    }
    out.uvs = local.uvs;
    out.uvs1 = local.uvs1;
    out.colors = local.colors;
    // Tangents only where a normal map needs them: the file's (to world space; a mirroring
    // transform flips the bitangent sign), else generated from the map's UV set.
    if (local.material >= 0) {
      const TextureRef& nt = m_out.scene.materials[size_t(local.material)].normal_tex;
      const auto& nuv = nt.texcoord == 1 ? out.uvs1 : out.uvs;
      if (nt.texture >= 0 && !local.tangents.empty()) {
        out.tangents.resize(local.tangents.size());
        for (size_t i = 0; i < local.tangents.size(); ++i) {
          const Vec4f t = local.tangents[i];
          const Vec3f tw = normalize(transform_vector(world, {t.x, t.y, t.z}));
          out.tangents[i] = {tw.x, tw.y, tw.z, flip ? -t.w : t.w};
        }
      } else if (nt.texture >= 0 && !nuv.empty()) {
        out.tangents = compute_tangents(out.positions, out.normals, nuv, out.indices);
      } else if (nt.texture >= 0) {
        warn(where, "normal texture without TEXCOORD_" + std::to_string(nt.texcoord) + "; normal map ignored");
      }
    }
    if (object_ids) {
      object_ids->push_back(int(m_out.scene.meshes.size()));
      m_out.scene.meshes.push_back(std::move(out));
    } else {
      add_world_mesh(m_out.scene, std::move(out));
    }
  }
}

void Converter::validate_accessors() {
  for (size_t i = 0; i < m_model.accessors.size(); ++i) {
    const std::string where = idx("accessors", i);
    const uint64_t charged = m_budget.used();
    AccessorLayout l = layout(int(i), where);
    m_budget.release(m_budget.used() - charged);  // validation decodes nothing; only decoding is charged
    if (l.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT || !l.data) continue;
    for (uint64_t e = 0; e < l.count; ++e)
      for (int c = 0; c < l.components; ++c)
        if (!std::isfinite(component(l, e, c))) {
          warn(where, "element " + std::to_string(e) + " is NaN or infinite");
          e = l.count;
          break;
        }
  }
}

void Converter::validate_textures() {
  const int n = int(m_model.textures.size());
  for (size_t i = 0; i < m_model.textures.size(); ++i) {
    const auto& t = m_model.textures[i];
    if (t.source < -1 || t.source >= int(m_model.images.size()))
      warn(idx("textures", i) + ".source", "image index " + std::to_string(t.source) + " out of range; texture ignored");
    if (t.sampler < -1 || t.sampler >= int(m_model.samplers.size()))
      warn(idx("textures", i) + ".sampler", "sampler index " + std::to_string(t.sampler) + " out of range; default sampler used");
  }
  for (size_t i = 0; i < m_model.materials.size(); ++i) {
    const auto& m = m_model.materials[i];
    const std::pair<const char*, int> refs[] = {
        {"pbrMetallicRoughness.baseColorTexture", m.pbrMetallicRoughness.baseColorTexture.index},
        {"pbrMetallicRoughness.metallicRoughnessTexture", m.pbrMetallicRoughness.metallicRoughnessTexture.index},
        {"normalTexture", m.normalTexture.index}, {"occlusionTexture", m.occlusionTexture.index},
        {"emissiveTexture", m.emissiveTexture.index}};
    for (const auto& [field, index] : refs)
      if (index < -1 || index >= n)
        warn(idx("materials", i) + "." + field, "texture index " + std::to_string(index) + " out of range (" +
                                                   std::to_string(n) + " textures); ignored");
  }
}

void Converter::add_camera(int camera_index, int node, const Transform& world) {
  const std::string node_where = idx("nodes", size_t(node));
  if (camera_index < 0 || size_t(camera_index) >= m_model.cameras.size())
    fail(node_where + ".camera", "camera index " + std::to_string(camera_index) + " out of range (" +
                                     std::to_string(m_model.cameras.size()) + " cameras)");
  const auto& src = m_model.cameras[size_t(camera_index)];
  Camera cam;
  cam.name = src.name.empty() ? idx("cameras", size_t(camera_index)) : src.name;
  cam.eye = transform_point(world, {0, 0, 0});
  // Orthonormalise the node's axes (scale is not part of a camera placement).
  const Vec3f w = normalize(transform_vector(world, {0, 0, 1}));
  Vec3f u = transform_vector(world, {1, 0, 0});
  u = normalize(u - w * dot(u, w));
  if (!(dot(w, w) > 0) || !(dot(u, u) > 0) || !is_finite(cam.eye))
    fail(node_where, "camera transform is singular");
  cam.w = w;
  cam.u = u;
  cam.v = cross(w, u);
  if (src.type == "perspective") {
    cam.projection = Projection::Perspective;
    cam.yfov = float(src.perspective.yfov);
    cam.aspect = float(src.perspective.aspectRatio);
    cam.znear = float(src.perspective.znear);
    cam.zfar = src.perspective.zfar > 0 ? float(src.perspective.zfar) : kInfinity;
  } else {
    cam.projection = Projection::Orthographic;
    cam.xmag = float(src.orthographic.xmag);
    cam.ymag = float(src.orthographic.ymag);
    cam.aspect = cam.xmag / cam.ymag;
    cam.znear = float(src.orthographic.znear);
    cam.zfar = float(src.orthographic.zfar);
  }
  m_out.scene.cameras.push_back(cam);
  m_out.info.camera_instances.push_back(cam.name + " (" + src.type + ", " + node_where +
                                        (m_model.nodes[size_t(node)].name.empty() ? "" : " '" + m_model.nodes[size_t(node)].name + "'") + ")");
}

void Converter::add_light(int light_index, int node, const Transform& world) {
  const std::string node_where = idx("nodes", size_t(node));
  if (light_index < 0 || size_t(light_index) >= m_model.lights.size())
    fail(node_where + ".extensions.KHR_lights_punctual.light", "light index " + std::to_string(light_index) +
                                                                   " out of range (" + std::to_string(m_model.lights.size()) + " lights)");
  const auto& src = m_model.lights[size_t(light_index)];
  Light l;
  l.name = src.name.empty() ? "lights[" + std::to_string(light_index) + "]" : src.name;
  l.type = src.type == "point" ? LightType::Point : (src.type == "spot" ? LightType::Spot : LightType::Directional);
  if (src.color.size() == 3) l.color = {float(src.color[0]), float(src.color[1]), float(src.color[2])};
  l.intensity = float(src.intensity);
  l.range = src.range > 0 ? float(src.range) : kInfinity;
  l.inner_cone = float(src.spot.innerConeAngle);
  l.outer_cone = float(src.spot.outerConeAngle);
  l.position = transform_point(world, {0, 0, 0});
  l.direction = normalize(transform_vector(world, {0, 0, -1}));
  if (l.type != LightType::Point && !(dot(l.direction, l.direction) > 0))
    fail(node_where, "light transform is singular");
  m_out.scene.lights.push_back(l);
}

void Converter::run() {
  auto& info = m_out.info;
  info.generator = m_model.asset.generator;
  info.version = m_model.asset.version;
  info.scene_count = int(m_model.scenes.size());
  for (size_t i = 0; i < m_model.scenes.size(); ++i)
    info.scene_names.push_back(m_model.scenes[i].name.empty() ? idx("scenes", i) : m_model.scenes[i].name);
  info.node_count = int(m_model.nodes.size());
  for (size_t i = 0; i < m_model.nodes.size(); ++i)
    info.node_names.push_back(m_model.nodes[i].name.empty() ? idx("nodes", i) : m_model.nodes[i].name);
  info.mesh_count = int(m_model.meshes.size());
  for (const auto& m : m_model.meshes) info.primitive_count += int(m.primitives.size());
  info.gltf_camera_count = int(m_model.cameras.size());
  info.gltf_light_count = int(m_model.lights.size());
  info.image_count = int(m_model.images.size());
  info.animation_count = int(m_model.animations.size());
  info.extensions_used = m_model.extensionsUsed;
  info.extensions_required = m_model.extensionsRequired;

  if (!m_model.asset.version.empty() && m_model.asset.version.rfind("2.", 0) != 0)
    fail("asset.version", "version '" + m_model.asset.version + "' is not glTF 2.x");
  check_extensions();
  validate_accessors();
  validate_textures();
  convert_materials();
  validate_cameras();
  validate_lights();
  decode_meshes();
  if (m_options.time) evaluate_animations(*m_options.time);

  // Which scene: --scene N, else the file's default, else scenes[0], else every root node.
  int scene = m_options.scene >= 0 ? m_options.scene : m_model.defaultScene;
  if (m_options.scene >= 0 && size_t(m_options.scene) >= m_model.scenes.size())
    throw InputError(m_file, "--scene", "scene " + std::to_string(m_options.scene) + " does not exist (" +
                                            std::to_string(m_model.scenes.size()) + " scenes)");
  if (scene >= int(m_model.scenes.size()) || scene < -1)
    fail("scene", "default scene " + std::to_string(scene) + " out of range (" + std::to_string(m_model.scenes.size()) + " scenes)");
  if (scene < 0 && !m_model.scenes.empty()) scene = 0;
  info.scene_index = scene;
  std::vector<int> roots;
  if (scene >= 0) {
    roots = m_model.scenes[size_t(scene)].nodes;
  } else {
    std::vector<bool> is_child(m_model.nodes.size(), false);
    for (const auto& n : m_model.nodes)
      for (int c : n.children)
        if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = true;
    for (size_t i = 0; i < is_child.size(); ++i)
      if (!is_child[i]) roots.push_back(int(i));
    if (!m_model.nodes.empty()) warn("scenes", "file has no scene; rendering all root nodes");
  }
  traverse(roots);
  if (m_out.scene.meshes.empty())
    warn(scene >= 0 ? idx("scenes", size_t(scene)) : "scenes", "no renderable triangles; the image shows only the background");
}

// Bytes the converter allocates per node beyond tinygltf's Node: its name in GltfInfo, the world
// transform and the traversal stack entry, two parent links, two flags, the scene-root set entry
// (a red-black tree node), the scene's root list and the animated pose (NodePose).
constexpr uint64_t kLoaderBytesPerNode =
    sizeof(std::string) + 2 * sizeof(Transform) + 8 + 2 * sizeof(int) + 2 + 48 + sizeof(int) + 112;

void Converter::charge_elements(const nlohmann::json& doc, MemoryBudget& budget) {
  struct Cost {
    const char* array;
    uint64_t bytes;
  };
  const Cost costs[] = {
      {"nodes", sizeof(tinygltf::Node) + kLoaderBytesPerNode},
      {"meshes", sizeof(tinygltf::Mesh) + sizeof(std::vector<LocalPrimitive>)},
      {"accessors", sizeof(tinygltf::Accessor)},
      {"bufferViews", sizeof(tinygltf::BufferView)},
      {"buffers", sizeof(tinygltf::Buffer)},
      {"materials", sizeof(tinygltf::Material) + sizeof(Material)},
      {"textures", sizeof(tinygltf::Texture)},
      {"images", sizeof(tinygltf::Image)},
      {"samplers", sizeof(tinygltf::Sampler)},
      {"cameras", sizeof(tinygltf::Camera) + sizeof(Camera)},
      {"skins", sizeof(tinygltf::Skin)},
      {"animations", sizeof(tinygltf::Animation)},
      {"scenes", sizeof(tinygltf::Scene) + sizeof(std::string)},
  };
  for (const Cost& c : costs) {
    const auto it = doc.find(c.array);
    if (it == doc.end() || !it->is_array() || it->empty()) continue;
    budget.charge(it->size() * c.bytes, c.array, std::to_string(it->size()) + " " + c.array + " need");
  }
  // Nested elements: primitives (tinygltf's and the decoded form), animation channels and samplers.
  uint64_t primitives = 0, channels = 0, samplers = 0;
  if (const auto m = doc.find("meshes"); m != doc.end())
    for (const auto& mesh : *m)
      if (const auto p = mesh.find("primitives"); p != mesh.end()) primitives += p->size();
  if (const auto a = doc.find("animations"); a != doc.end())
    for (const auto& anim : *a) {
      if (const auto c = anim.find("channels"); c != anim.end()) channels += c->size();
      if (const auto sm = anim.find("samplers"); sm != anim.end()) samplers += sm->size();
    }
  budget.charge(primitives * (sizeof(tinygltf::Primitive) + sizeof(LocalPrimitive)), "meshes",
                std::to_string(primitives) + " primitives need");
  budget.charge(channels * sizeof(tinygltf::AnimationChannel) + samplers * sizeof(tinygltf::AnimationSampler),
                "animations",
                std::to_string(channels) + " channels and " + std::to_string(samplers) + " samplers need");
}

// Reads the scene file. Before the whole file is read, the JSON text's parsed size is charged
// (from the file size, or a GLB's JSON chunk length), and a GLB's binary rest.
std::vector<unsigned char> read_scene_file(const fs::path& file, uint64_t max_file_bytes,
                                           MemoryBudget& budget) {
  const std::string name = file.string();
  const uint64_t size = check_input_file(file, "", max_file_bytes);
  const std::vector<unsigned char> head = read_input_file(file, "", max_file_bytes, 20);
  uint64_t json = size;
  if (head.size() >= 4 && std::memcmp(head.data(), "glTF", 4) == 0) {
    uint32_t chunk = 0;
    if (head.size() >= 16) std::memcpy(&chunk, head.data() + 12, 4);
    json = std::min<uint64_t>(chunk, size);
  }
  const uint64_t parsed = json * kParsedBytesPerJsonByte;
  if (parsed > budget.limit() - budget.used())
    throw InputError(name, "",
                     "the JSON text (" + format_bytes(json) + ") needs about " + format_bytes(parsed) +
                         " parsed, over the " + format_bytes(budget.limit()) + " budget");
  budget.charge(parsed, "", "the parsed JSON needs");
  if (size > json) budget.charge(size - json, "GLB", "the binary chunk needs");
  std::vector<unsigned char> bytes = read_input_file(file, "", max_file_bytes);
  if (bytes.size() != size) throw InputError(name, "", "the file changed size while it was read");
  return bytes;
}

// Resolves and checks every external buffer and image URI before tinygltf reads anything: a
// buffer that may not be read is an error, an image a warning (its textures are ignored). The
// readable files are served to tinygltf under the names it will ask for, and charged.
void resolve_external_files(const nlohmann::json& doc, const std::string& file, const fs::path& root,
                            const GltfLoadOptions& options, FsSandbox& box, MemoryBudget& budget,
                            std::vector<std::string>& warnings) {
  for (const char* array : {"buffers", "images"}) {
    const auto list = doc.find(array);
    if (list == doc.end()) continue;
    const bool is_buffer = array[0] == 'b';
    for (size_t i = 0; i < list->size(); ++i) {
      const std::string where = idx(array, i);
      const auto& element = (*list)[i];
      const auto uri_it = element.find("uri");
      if (uri_it == element.end()) continue;
      if (!uri_it->is_string()) throw InputError(file, where + ".uri", "must be a string");
      const std::string uri = uri_it->get<std::string>();
      if (is_data_uri(uri)) continue;
      const ResolvedUri r = resolve_uri(uri, root, options.allow_external_uris, options.max_file_bytes);
      std::string problem;
      if (!r.refusal.empty()) problem = r.by_policy ? r.refusal : "cannot be read: " + r.refusal;
      const uint64_t declared =
          is_buffer && element.contains("byteLength") ? element["byteLength"].get<uint64_t>() : 0;
      if (problem.empty() && is_buffer && r.size != declared)
        problem = "names '" + r.path.string() + "', a file of " + std::to_string(r.size) +
                  " bytes, but the buffer's byteLength is " + std::to_string(declared);
      if (!problem.empty()) {
        if (is_buffer) throw InputError(file, where, "URI '" + uri + "' " + problem);
        warnings.push_back(where + ": URI '" + uri + "' " + problem + "; the image is not read");
        continue;
      }
      // Buffers are charged by byteLength (below); an image's encoded bytes are held twice
      // while tinygltf hands them over.
      if (!is_buffer) budget.charge(2 * r.size, where, "its encoded bytes need");
      box.served[tinygltf_join(root.string(), decode_uri(uri))] = r.path;
    }
  }
  if (const auto buffers = doc.find("buffers"); buffers != doc.end())
    for (size_t i = 0; i < buffers->size(); ++i)
      if ((*buffers)[i].contains("byteLength"))
        budget.charge((*buffers)[i]["byteLength"].get<uint64_t>(), idx("buffers", i), "its data needs");
}

// The JSON checks that need the DOM, run on a DOM of the loader's own that is freed before
// tinygltf builds its own: schema checks, element and buffer charges, URI resolution.
void check_document(std::string_view json, const std::string& file, const fs::path& root,
                    const GltfLoadOptions& options, FsSandbox& box, MemoryBudget& budget,
                    std::vector<std::string>& warnings) {
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json.begin(), json.end());
  } catch (const nlohmann::json::exception& e) {
    throw InputError(file, "JSON", std::string("parse error: ") + e.what());
  } catch (const std::bad_alloc&) {
    throw InputError(file, "JSON", "out of memory while parsing");
  }
  check_gltf_json(doc, file);
  Converter::charge_elements(doc, budget);
  resolve_external_files(doc, file, root, options, box, budget, warnings);
}

}  // namespace

LoadedScene load_gltf(const fs::path& file, const GltfLoadOptions& options) {
  const std::string name = file.string();
  MemoryBudget budget(name, options.max_memory_bytes);
  LoadedScene out;
  std::vector<unsigned char> bytes = read_scene_file(file, options.max_file_bytes, budget);
  if (bytes.size() >= 0xffffffffu) throw InputError(name, "", "file too large for glTF (>= 4 GiB)");

  // A GLB is handed to tinygltf without the chunks of unknown type (they follow JSON and BIN).
  const bool is_glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  std::string_view json(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  size_t parse_bytes = bytes.size();
  if (is_glb) {
    GlbLayout glb = parse_glb(name, bytes);
    json = glb.json;
    parse_bytes = size_t(glb.kept_length);
    const uint32_t kept = uint32_t(glb.kept_length);
    std::memcpy(bytes.data() + 8, &kept, 4);
    for (auto& w : glb.warnings) out.warnings.push_back(std::move(w));
  }
  if (json_nesting_depth(json, options.max_json_depth) > options.max_json_depth)
    throw InputError(name, "JSON", "nesting deeper than " + std::to_string(options.max_json_depth) +
                                       " levels (refused before parsing)");

  std::error_code ec;
  const fs::path root = fs::weakly_canonical(fs::absolute(file).parent_path(), ec);
  out.info.source_files.push_back(file);
  FsSandbox box;
  box.max_bytes = options.max_file_bytes;
  box.read = &out.info.source_files;
  check_document(json, name, root, options, box, budget, out.warnings);

  tinygltf::TinyGLTF parser;
  parser.SetFsCallbacks({sandbox_file_exists, sandbox_expand, sandbox_read, sandbox_write, &box});
  parser.SetImageLoader(capture_image, nullptr);
  tinygltf::Model model;
  std::string terr, twarn;
  bool ok = false;
  try {
    ok = is_glb
             ? parser.LoadBinaryFromMemory(&model, &terr, &twarn, bytes.data(), unsigned(parse_bytes),
                                           root.string())
             : parser.LoadASCIIFromString(&model, &terr, &twarn, reinterpret_cast<const char*>(bytes.data()),
                                          unsigned(bytes.size()), root.string());
  } catch (const std::bad_alloc&) {
    throw InputError(name, "", "out of memory while parsing (file too large or malformed)");
  } catch (const std::exception& e) {
    throw InputError(name, "", std::string("parse error: ") + e.what());
  }
  budget.release(uint64_t(json.size()) * kJsonDomBytesPerByte);  // tinygltf's DOM is gone
  auto trim = [](std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    for (auto& c : s) if (c == '\n') c = ';';
    return s;
  };
  if (!ok) throw InputError(name, "", terr.empty() ? "tinygltf could not parse the file" : trim(terr));
  if (!twarn.empty()) out.warnings.push_back("tinygltf: " + trim(twarn));
  try {
    Converter(model, name, options, budget, out).run();
  } catch (const std::bad_alloc&) {
    throw InputError(name, "", "out of memory while converting the scene");
  }
  return out;
}

}  // namespace penumbra
