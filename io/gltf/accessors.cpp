// Accessor decoding: the one bufferView bounds check, accessor layouts with overflow-safe
// extents, sparse substitutions and typed reads.
#include "io/gltf/accessors.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace penumbra::gltf {

std::span<const unsigned char> buffer_view_bytes(const GltfContext& ctx, int view, const std::string& user) {
  const tinygltf::Model& model = ctx.model;
  if (view < 0 || size_t(view) >= model.bufferViews.size())
    ctx.fail(user, "bufferView " + std::to_string(view) + " out of range (" +
                       std::to_string(model.bufferViews.size()) + " bufferViews)");
  const std::string bv_where = idx("bufferViews", size_t(view));
  const tinygltf::BufferView& bv = model.bufferViews[size_t(view)];
  if (bv.buffer < 0 || size_t(bv.buffer) >= model.buffers.size())
    ctx.fail(bv_where, "buffer " + std::to_string(bv.buffer) + " out of range (" +
                           std::to_string(model.buffers.size()) + " buffers)");
  const auto& buffer = model.buffers[size_t(bv.buffer)].data;
  uint64_t bv_end = 0;
  if (!add_ok(bv.byteOffset, bv.byteLength, bv_end) || bv_end > buffer.size())
    ctx.fail(bv_where, "byteOffset " + std::to_string(bv.byteOffset) + " + byteLength " +
                           std::to_string(bv.byteLength) + " exceeds buffer " + std::to_string(bv.buffer) +
                           " of " + std::to_string(buffer.size()) + " bytes");
  return {buffer.data() + bv.byteOffset, size_t(bv.byteLength)};
}

namespace {

// `bytes` bytes at `offset` within bufferViews[view], for sparse indices or values (`what`).
const unsigned char* sparse_span(const GltfContext& ctx, int view, uint64_t offset, uint64_t bytes,
                                 const std::string& what) {
  const std::span<const unsigned char> span = buffer_view_bytes(ctx, view, what);
  uint64_t end = 0;
  if (!add_ok(offset, bytes, end) || end > span.size())
    ctx.fail(what, "reads past the end of its bufferView");
  return span.data() + offset;
}

// The sparse substitutions of accessor `a` (glTF 2.0 spec 3.6.2.3, "Sparse Accessors") into l.sparse.
void read_sparse(const GltfContext& ctx, const tinygltf::Accessor& a, const std::string& where, uint64_t elem,
                 AccessorLayout& l) {
  const std::string sw = where + ".sparse";
  if (a.sparse.count <= 0 || uint64_t(a.sparse.count) > l.count)
    ctx.fail(sw, "count " + std::to_string(a.sparse.count) + " not in [1, " + std::to_string(l.count) + "]");
  const uint64_t n = uint64_t(a.sparse.count);
  ctx.charge(n * (sizeof(std::pair<uint64_t, std::vector<double>>) + uint64_t(l.components) * 8 + 16), sw,
             "its " + std::to_string(n) + " sparse values need");
  const int ict = a.sparse.indices.componentType;
  const int isz = tinygltf::GetComponentSizeInBytes(uint32_t(ict));
  if (ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      ict != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    ctx.fail(sw + ".indices", "componentType must be an unsigned integer type");
  const unsigned char* ip =
      sparse_span(ctx, a.sparse.indices.bufferView, uint64_t(a.sparse.indices.byteOffset), n * uint64_t(isz),
                  sw + ".indices");
  const unsigned char* vp = sparse_span(ctx, a.sparse.values.bufferView, uint64_t(a.sparse.values.byteOffset),
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
    if (isz == 2) {
      uint16_t v;
      std::memcpy(&v, ip + i * 2, 2);
      target = v;
    }
    if (isz == 4) {
      uint32_t v;
      std::memcpy(&v, ip + i * 4, 4);
      target = v;
    }
    if (target >= l.count)
      ctx.fail(sw + ".indices",
               "index " + std::to_string(target) + " >= accessor count " + std::to_string(l.count));
    if (i > 0 && target <= l.sparse.back().first)  // the spec: sparse indices MUST strictly increase
      ctx.fail(sw + ".indices", "indices must strictly increase (index " + std::to_string(i) + " is " +
                                    std::to_string(target) + " after " +
                                    std::to_string(l.sparse.back().first) + ")");
    std::vector<double> vals(size_t(l.components));
    for (int c = 0; c < l.components; ++c) vals[size_t(c)] = accessor_component(values, i, c);
    l.sparse.emplace_back(target, std::move(vals));
  }
}

}  // namespace

AccessorLayout accessor_layout(const GltfContext& ctx, int accessor, const std::string& user) {
  const tinygltf::Model& model = ctx.model;
  const std::string where = idx("accessors", size_t(accessor));
  if (accessor < 0 || size_t(accessor) >= model.accessors.size())
    ctx.fail(user, "accessor index " + std::to_string(accessor) + " out of range (" +
                       std::to_string(model.accessors.size()) + " accessors)");
  const tinygltf::Accessor& a = model.accessors[size_t(accessor)];
  AccessorLayout l;
  const int comp_size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  l.components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  if (comp_size <= 0) ctx.fail(where, "invalid componentType " + std::to_string(a.componentType));
  if (l.components <= 0) ctx.fail(where, "invalid type");
  l.component_type = a.componentType;
  l.normalized = a.normalized;
  l.count = a.count;
  if (l.count == 0) ctx.fail(where, "count must be >= 1");
  const uint64_t elem = uint64_t(comp_size) * uint64_t(l.components);

  uint64_t decoded = 0;
  if (!mul_ok(l.count, uint64_t(l.components) * 8, decoded))
    ctx.fail(where, "count " + std::to_string(l.count) + " overflows");
  ctx.charge(decoded, where, "decoding its " + std::to_string(l.count) + " elements needs");

  if (a.bufferView >= 0) {
    const std::span<const unsigned char> view = buffer_view_bytes(ctx, a.bufferView, where);
    const std::string bv_where = idx("bufferViews", size_t(a.bufferView));
    const tinygltf::BufferView& bv = model.bufferViews[size_t(a.bufferView)];
    l.stride = bv.byteStride ? uint64_t(bv.byteStride) : elem;
    if (bv.byteStride != 0 && (bv.byteStride < elem || bv.byteStride > 252 || bv.byteStride % 4))
      ctx.fail(bv_where, "byteStride " + std::to_string(bv.byteStride) + " invalid for " +
                             std::to_string(elem) + "-byte elements of " + where);
    uint64_t last = 0, end = 0;
    if (!mul_ok(l.count - 1, l.stride, last) || !add_ok(last, a.byteOffset, end) || !add_ok(end, elem, end) ||
        end > bv.byteLength)
      ctx.fail(where, "byteOffset " + std::to_string(a.byteOffset) + " + " + std::to_string(l.count) +
                          " elements (stride " + std::to_string(l.stride) + ") read past the end of " +
                          bv_where + " (" + std::to_string(bv.byteLength) + " bytes)");
    if (a.byteOffset % uint64_t(comp_size) != 0)
      ctx.warn(where,
               "byteOffset " + std::to_string(a.byteOffset) + " is not a multiple of the component size");
    l.data = view.data() + a.byteOffset;
  } else if (!a.sparse.isSparse) {
    ctx.warn(where, "no bufferView: values are all zero");
  }
  if (a.sparse.isSparse) read_sparse(ctx, a, where, elem, l);
  return l;
}

double accessor_component(const AccessorLayout& l, uint64_t element, int c) {
  if (!l.data) return 0.0;
  const int size = tinygltf::GetComponentSizeInBytes(uint32_t(l.component_type));
  const unsigned char* p = l.data + element * l.stride + uint64_t(c) * uint64_t(size);
  switch (l.component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const uint8_t v = *p;
      return l.normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v;
      std::memcpy(&v, p, 1);
      return l.normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return l.normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return l.normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default:
      return 0.0;
  }
}

std::vector<double> read_accessor(const GltfContext& ctx, int accessor, const std::string& user,
                                  std::initializer_list<int> types,
                                  std::initializer_list<int> component_types, bool allow_normalized,
                                  bool allow_integer) {
  AccessorLayout l = accessor_layout(ctx, accessor, user);
  const auto& a = ctx.model.accessors[size_t(accessor)];
  const std::string where = user + " (" + idx("accessors", size_t(accessor)) + ")";
  if (std::find(types.begin(), types.end(), a.type) == types.end())
    ctx.fail(where, "unexpected accessor type");
  const bool ok_component =
      std::find(component_types.begin(), component_types.end(), a.componentType) != component_types.end();
  const bool is_float = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (!ok_component ||
      (!is_float && !(allow_normalized && a.normalized) && !(allow_integer && !a.normalized)))
    ctx.fail(where, "unsupported componentType " + std::to_string(a.componentType) +
                        (a.normalized ? " (normalized)" : ""));
  std::vector<double> out(size_t(l.count) * size_t(l.components));
  for (uint64_t i = 0; i < l.count; ++i)
    for (int c = 0; c < l.components; ++c)
      out[size_t(i) * size_t(l.components) + size_t(c)] = accessor_component(l, i, c);
  for (const auto& [target, vals] : l.sparse)
    for (int c = 0; c < l.components; ++c)
      out[size_t(target) * size_t(l.components) + size_t(c)] = vals[size_t(c)];
  return out;
}

std::vector<uint32_t> read_indices(const GltfContext& ctx, int accessor, const std::string& user) {
  AccessorLayout l = accessor_layout(ctx, accessor, user);
  const auto& a = ctx.model.accessors[size_t(accessor)];
  const std::string where = user + " (" + idx("accessors", size_t(accessor)) + ")";
  if (a.type != TINYGLTF_TYPE_SCALAR) ctx.fail(where, "indices must be SCALAR");
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    ctx.fail(where, "indices componentType must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
  if (a.normalized) ctx.fail(where, "indices must not be normalized");
  std::vector<uint32_t> out(size_t(l.count));
  for (uint64_t i = 0; i < l.count; ++i) out[size_t(i)] = uint32_t(accessor_component(l, i, 0));
  for (const auto& [target, vals] : l.sparse) out[size_t(target)] = uint32_t(vals[0]);
  return out;
}

void validate_accessors(const GltfContext& ctx) {
  for (size_t i = 0; i < ctx.model.accessors.size(); ++i) {
    const std::string where = idx("accessors", i);
    const uint64_t charged = ctx.budget.used();
    AccessorLayout l = accessor_layout(ctx, int(i), where);
    ctx.budget.release(ctx.budget.used() - charged);  // validation decodes nothing; only decoding is charged
    if (l.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT || !l.data) continue;
    for (uint64_t e = 0; e < l.count; ++e)
      for (int c = 0; c < l.components; ++c)
        if (!std::isfinite(accessor_component(l, e, c))) {
          ctx.warn(where, "element " + std::to_string(e) + " is NaN or infinite");
          e = l.count;
          break;
        }
  }
}

}  // namespace penumbra::gltf
