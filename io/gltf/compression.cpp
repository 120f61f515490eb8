// Geometry compression: meshoptimizer bufferViews (EXT_/KHR_meshopt_compression, decoded with
// meshoptimizer's own decoders and filters) and Draco primitives (KHR_draco_mesh_compression,
// decoded with Draco), each rewritten into plain buffers, bufferViews and accessors.
#include "io/gltf/compression.h"

#include <meshoptimizer.h>
#include <tiny_gltf.h>

#include <cstring>

#include "io/gltf/draco_decode.h"

namespace penumbra::gltf {

namespace {

constexpr const char* kMeshoptExt = "EXT_meshopt_compression";
constexpr const char* kMeshoptKhr = "KHR_meshopt_compression";
constexpr const char* kDraco = "KHR_draco_mesh_compression";

// A non-negative integer member `key` of object `v` (absent: `fallback`, or an error when
// fallback < 0).
uint64_t count_member(const std::string& file, const tinygltf::Value& v, const char* key,
                      const std::string& where, int64_t fallback) {
  const auto& m = v.Get(key);
  if (m.Type() == tinygltf::NULL_TYPE) {
    if (fallback < 0) throw InputError(file, where, std::string("'") + key + "' is required");
    return uint64_t(fallback);
  }
  if (!m.IsNumber()) throw InputError(file, where + "." + key, "must be an integer");
  const double d = m.GetNumberAsDouble();
  if (!(d >= 0) || d != double(int64_t(d)) || d > 9.007199254740992e15)
    throw InputError(file, where + "." + key, "must be a non-negative integer");
  return uint64_t(d);
}

std::string string_member(const tinygltf::Value& v, const char* key, const char* fallback) {
  const auto& m = v.Get(key);
  return m.IsString() ? m.Get<std::string>() : std::string(fallback);
}

// A new buffer of `bytes` zero bytes, charged to the budget for `where`; returns its index.
int new_buffer(tinygltf::Model& model, uint64_t bytes, MemoryBudget& budget, const std::string& where) {
  budget.charge(bytes, where, "its decoded data needs");
  tinygltf::Buffer b;
  b.data.assign(size_t(bytes), 0);
  model.buffers.push_back(std::move(b));
  return int(model.buffers.size() - 1);
}

// The `length` source bytes at `offset` of buffers[buffer].
const unsigned char* source_bytes(const tinygltf::Model& model, const std::string& file, uint64_t buffer,
                                  uint64_t offset, uint64_t length, const std::string& where) {
  if (buffer >= model.buffers.size())
    throw InputError(file, where + ".buffer",
                     "buffer " + std::to_string(buffer) + " out of range (" +
                         std::to_string(model.buffers.size()) + " buffers)");
  const auto& data = model.buffers[size_t(buffer)].data;
  uint64_t end = 0;
  if (!add_ok(offset, length, end) || end > data.size())
    throw InputError(file, where,
                     "byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) +
                         " exceeds buffer " + std::to_string(buffer) + " of " + std::to_string(data.size()) +
                         " bytes");
  return data.data() + offset;
}

// The meshopt filter of a decoded ATTRIBUTES stream, after its stride is checked.
void apply_filter(const std::string& file, const std::string& filter, unsigned char* data, uint64_t count,
                  uint64_t stride, const std::string& where) {
  if (filter == "NONE") return;
  const bool ok = (filter == "OCTAHEDRAL" && (stride == 4 || stride == 8)) ||
                  (filter == "QUATERNION" && stride == 8) || (filter == "EXPONENTIAL" && stride % 4 == 0);
  if (filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
    throw InputError(file, where + ".filter",
                     "'" + filter + "' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
  if (!ok)
    throw InputError(file, where,
                     "byteStride " + std::to_string(stride) + " is invalid for filter " + filter);
  if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(data, size_t(count), size_t(stride));
  if (filter == "QUATERNION") meshopt_decodeFilterQuat(data, size_t(count), size_t(stride));
  if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(data, size_t(count), size_t(stride));
}

// Decodes bufferViews[view]'s meshopt stream (extension object `x`) into a new buffer.
void decode_meshopt_view(tinygltf::Model& model, const std::string& file, size_t view,
                         const tinygltf::Value& x, const std::string& where, MemoryBudget& budget) {
  const uint64_t buffer = count_member(file, x, "buffer", where, -1);
  const uint64_t offset = count_member(file, x, "byteOffset", where, 0);
  const uint64_t length = count_member(file, x, "byteLength", where, -1);
  const uint64_t stride = count_member(file, x, "byteStride", where, -1);
  const uint64_t count = count_member(file, x, "count", where, -1);
  const std::string mode = string_member(x, "mode", "");
  const std::string filter = string_member(x, "filter", "NONE");
  if (mode == "ATTRIBUTES") {
    if (stride == 0 || stride % 4 != 0 || stride > 256)
      throw InputError(file, where + ".byteStride", "must be a multiple of 4 in [4, 256] for ATTRIBUTES");
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    if (stride != 2 && stride != 4)
      throw InputError(file, where + ".byteStride", "must be 2 or 4 for " + mode);
    if (mode == "TRIANGLES" && count % 3 != 0)
      throw InputError(file, where + ".count", "must be a multiple of 3 for TRIANGLES");
    if (filter != "NONE") throw InputError(file, where + ".filter", "must be NONE for " + mode);
  } else {
    throw InputError(file, where + ".mode", "'" + mode + "' is not ATTRIBUTES, TRIANGLES or INDICES");
  }
  uint64_t decoded = 0;
  if (!mul_ok(count, stride, decoded)) throw InputError(file, where, "count x byteStride overflows");
  tinygltf::BufferView& bv = model.bufferViews[view];
  if (decoded > uint64_t(bv.byteLength))
    throw InputError(file, where,
                     "decodes to " + std::to_string(decoded) +
                         " bytes, more than the bufferView's byteLength " + std::to_string(bv.byteLength));
  source_bytes(model, file, buffer, offset, length, where);  // the range is checked before allocating
  const int target = new_buffer(model, uint64_t(bv.byteLength), budget, where);
  const unsigned char* src = model.buffers[size_t(buffer)].data.data() + offset;
  unsigned char* dst = model.buffers[size_t(target)].data.data();
  int rc = 0;
  if (mode == "ATTRIBUTES")
    rc = meshopt_decodeVertexBuffer(dst, size_t(count), size_t(stride), src, size_t(length));
  else if (mode == "TRIANGLES")
    rc = meshopt_decodeIndexBuffer(dst, size_t(count), size_t(stride), src, size_t(length));
  else
    rc = meshopt_decodeIndexSequence(dst, size_t(count), size_t(stride), src, size_t(length));
  if (rc != 0)
    throw InputError(file, where,
                     "malformed " + mode + " stream (meshoptimizer error " + std::to_string(rc) + ")");
  if (mode == "ATTRIBUTES") apply_filter(file, filter, dst, count, stride, where);
  bv.buffer = target;
  bv.byteOffset = 0;
  bv.extensions.erase(kMeshoptExt);
  bv.extensions.erase(kMeshoptKhr);
}

// Size in bytes of one component of a glTF componentType, 0 if it is not one.
uint64_t component_bytes(int type) {
  const int s = tinygltf::GetComponentSizeInBytes(uint32_t(type));
  return s > 0 ? uint64_t(s) : 0;
}

// A new tightly packed bufferView over a new buffer holding `data`; returns the view's index.
int new_view(tinygltf::Model& model, std::vector<unsigned char>&& data) {
  tinygltf::Buffer b;
  b.data = std::move(data);
  model.buffers.push_back(std::move(b));
  tinygltf::BufferView bv;
  bv.buffer = int(model.buffers.size() - 1);
  bv.byteOffset = 0;
  bv.byteLength = model.buffers.back().data.size();
  model.bufferViews.push_back(bv);
  return int(model.bufferViews.size() - 1);
}

// Points accessors[a] at bufferViews[view] from offset 0, as `component_type`, without a sparse
// part (a Draco primitive's accessors describe its decoded data and have none of their own).
void repoint_accessor(tinygltf::Model& model, int a, int view, int component_type) {
  tinygltf::Accessor& acc = model.accessors[size_t(a)];
  acc.bufferView = view;
  acc.byteOffset = 0;
  acc.componentType = component_type;
  acc.sparse = {};
}

// The accessor index `a` used by `where`, checked against the accessor count.
const tinygltf::Accessor& accessor_at(const tinygltf::Model& model, const std::string& file, int a,
                                      const std::string& where) {
  if (a < 0 || size_t(a) >= model.accessors.size())
    throw InputError(file, where,
                     "accessor " + std::to_string(a) + " out of range (" +
                         std::to_string(model.accessors.size()) + " accessors)");
  return model.accessors[size_t(a)];
}

// The attributes a Draco primitive decodes (extension object `x`), with the accessors they fill;
// their decoded size is charged to the budget.
std::vector<DracoAttribute> draco_requests(const tinygltf::Model& model, const std::string& file,
                                           const tinygltf::Primitive& prim, const tinygltf::Value& x,
                                           const std::string& where, std::vector<int>& accessors,
                                           uint64_t& points, MemoryBudget& budget) {
  const std::string xw = where + ".extensions." + kDraco;
  const auto& attributes = x.Get("attributes");
  if (!attributes.IsObject()) throw InputError(file, xw + ".attributes", "must be an object");
  std::vector<DracoAttribute> out;
  for (const std::string& name : attributes.Keys()) {
    const auto& id = attributes.Get(name);
    if (!id.IsInt() || id.GetNumberAsInt() < 0)
      throw InputError(file, xw + ".attributes." + name, "must be a non-negative integer");
    const auto it = prim.attributes.find(name);
    if (it == prim.attributes.end())
      throw InputError(file, xw + ".attributes." + name, "names an attribute the primitive does not have");
    const std::string aw = where + ".attributes." + name;
    const tinygltf::Accessor& a = accessor_at(model, file, it->second, aw);
    DracoAttribute r;
    r.id = uint32_t(id.GetNumberAsInt());
    r.component_type = a.componentType;
    r.components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (r.components <= 0 || r.components > 4 || component_bytes(a.componentType) == 0)
      throw InputError(file, aw, "type/componentType is not a vertex attribute type");
    if (!out.empty() && uint64_t(a.count) != points)
      throw InputError(file, aw, "count differs from the primitive's other Draco attributes");
    points = uint64_t(a.count);
    uint64_t bytes = 0;
    if (!mul_ok(points, component_bytes(a.componentType) * uint64_t(r.components) * 2, bytes))
      throw InputError(file, aw, "count " + std::to_string(points) + " is too large");
    budget.charge(bytes, aw, "its decoded data needs");
    out.push_back(std::move(r));
    accessors.push_back(it->second);
  }
  return out;
}

// Decodes one KHR_draco_mesh_compression primitive (extension object `x`).
void decode_draco_primitive(tinygltf::Model& model, const std::string& file, tinygltf::Primitive& prim,
                            const tinygltf::Value& x, const std::string& where, MemoryBudget& budget) {
  const std::string xw = where + ".extensions." + kDraco;
  const uint64_t view = count_member(file, x, "bufferView", xw, -1);
  if (view >= model.bufferViews.size())
    throw InputError(file, xw + ".bufferView",
                     "bufferView " + std::to_string(view) + " out of range (" +
                         std::to_string(model.bufferViews.size()) + " bufferViews)");
  const tinygltf::BufferView& bv = model.bufferViews[size_t(view)];
  const unsigned char* src =
      source_bytes(model, file, bv.buffer < 0 ? model.buffers.size() : size_t(bv.buffer), bv.byteOffset,
                   bv.byteLength, idx("bufferViews", size_t(view)));
  std::vector<int> accessors;
  uint64_t points = 0;
  std::vector<DracoAttribute> attributes =
      draco_requests(model, file, prim, x, where, accessors, points, budget);
  // Draco decodes a triangle list; the primitive declares its size by its indices accessor.
  if (prim.indices < 0) throw InputError(file, xw, "a Draco primitive needs an indices accessor");
  if (prim.mode != TINYGLTF_MODE_TRIANGLES)
    throw InputError(file, where + ".mode", "a Draco primitive must be a triangle list (mode 4)");
  const tinygltf::Accessor& ia = accessor_at(model, file, prim.indices, where + ".indices");
  if (ia.count % 3 != 0) throw InputError(file, where + ".indices", "count is not a multiple of 3");
  const uint64_t faces = uint64_t(ia.count) / 3;
  uint64_t index_bytes = 0;
  if (!mul_ok(uint64_t(ia.count), 8, index_bytes))
    throw InputError(file, where + ".indices", "count " + std::to_string(ia.count) + " is too large");
  budget.charge(index_bytes, where + ".indices", "its decoded data needs");
  DracoMesh mesh = decode_draco(src, bv.byteLength, points, faces, attributes);
  if (!mesh.error.empty()) throw InputError(file, xw, mesh.error);
  if (mesh.points != points && !attributes.empty())
    throw InputError(file, where + ".attributes." + x.Get("attributes").Keys().front(),
                     "accessor count " + std::to_string(points) + " differs from the " +
                         std::to_string(mesh.points) + " points of the Draco stream");
  if (mesh.faces != faces && prim.indices >= 0)
    throw InputError(file, where + ".indices",
                     "accessor count " + std::to_string(faces * 3) + " differs from the " +
                         std::to_string(mesh.faces * 3) + " indices of the Draco stream");
  if (prim.indices >= 0) {
    std::vector<unsigned char> bytes(mesh.indices.size() * 4);
    std::memcpy(bytes.data(), mesh.indices.data(), bytes.size());
    repoint_accessor(model, prim.indices, new_view(model, std::move(bytes)),
                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
  }
  for (size_t k = 0; k < attributes.size(); ++k)
    repoint_accessor(model, accessors[k], new_view(model, std::move(attributes[k].data)),
                     attributes[k].component_type);
  prim.extensions.erase(kDraco);
}

}  // namespace

std::vector<std::string> compression_extensions() {
  return {kMeshoptExt, kMeshoptKhr, kDraco, "KHR_mesh_quantization"};
}

void decompress_model(tinygltf::Model& model, const std::string& file, MemoryBudget& budget) {
  for (size_t i = 0; i < model.bufferViews.size(); ++i) {
    for (const char* name : {kMeshoptExt, kMeshoptKhr}) {
      const auto it = model.bufferViews[i].extensions.find(name);
      if (it == model.bufferViews[i].extensions.end()) continue;
      const tinygltf::Value x = it->second;
      decode_meshopt_view(model, file, i, x, idx("bufferViews", i) + ".extensions." + name, budget);
      break;
    }
  }
  for (size_t m = 0; m < model.meshes.size(); ++m) {
    for (size_t p = 0; p < model.meshes[m].primitives.size(); ++p) {
      tinygltf::Primitive& prim = model.meshes[m].primitives[p];
      const auto it = prim.extensions.find(kDraco);
      if (it == prim.extensions.end()) continue;
      const tinygltf::Value x = it->second;
      decode_draco_primitive(model, file, prim, x, idx("meshes", m) + "." + idx("primitives", p), budget);
    }
  }
}

}  // namespace penumbra::gltf
