// Accessor decoding for the glTF loader: bufferView bounds, strides, sparse substitution and
// component conversion (glTF 2.0 spec 3.6, "Buffers, BufferViews and Accessors"). Every read of
// a bufferView, for accessors, sparse indices and values, and images, goes through
// buffer_view_bytes(). Internal to io/gltf/.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "io/gltf/context.h"

namespace penumbra::gltf {

/// The bytes of bufferViews[view] after checking that the view and its buffer exist and that
/// byteOffset + byteLength lies within the buffer. Throws InputError naming `user` (a view index
/// out of range) or the bufferView.
std::span<const unsigned char> buffer_view_bytes(const GltfContext& ctx, int view, const std::string& user);

/// A validated accessor: where element i, component c is, and the sparse substitutions.
struct AccessorLayout {
  const unsigned char* data = nullptr;  ///< nullptr: all zeros (no bufferView)
  uint64_t stride = 0;
  uint64_t count = 0;
  int component_type = 0;
  int components = 0;
  bool normalized = false;
  std::vector<std::pair<uint64_t, std::vector<double>>> sparse;  ///< (index, values), indices increasing
};

/// Validates accessors[accessor] (used by `user`) and charges its decoded size to the budget.
/// Throws InputError naming the accessor, its bufferView or `user`.
AccessorLayout accessor_layout(const GltfContext& ctx, int accessor, const std::string& user);

/// Component c of element `element` as a double (normalized integers mapped to [0,1] or [-1,1]);
/// 0 without data. The layout's bounds are already checked.
double accessor_component(const AccessorLayout& l, uint64_t element, int c);

/// Every component of accessors[accessor], sparse values applied, element-major. The accessor's
/// type must be one of `types` and its componentType one of `component_types`; integer types
/// need `allow_normalized` (and normalized: true) or `allow_integer` (and normalized: false).
std::vector<double> read_accessor(const GltfContext& ctx, int accessor, const std::string& user,
                                  std::initializer_list<int> types,
                                  std::initializer_list<int> component_types, bool allow_normalized,
                                  bool allow_integer = false);

/// A SCALAR unsigned byte/short/int, non-normalized index accessor.
std::vector<uint32_t> read_indices(const GltfContext& ctx, int accessor, const std::string& user);

/// Validates every accessor without decoding (nothing stays charged) and warns once per float
/// accessor holding NaN or infinite values.
void validate_accessors(const GltfContext& ctx);

}  // namespace penumbra::gltf
