// What every conversion phase of the glTF loader shares: the parsed tinygltf model, the load
// options, the memory budget, the scene being filled and the fail()/warn() helpers whose
// messages name the glTF element. Internal to io/gltf/; it holds no phase's own state.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>

#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/gltf/loader.h"

namespace tinygltf {
class Model;
}

namespace penumbra::gltf {

/// Overflow-safe arithmetic for sizes read from the file: false if the result wraps.
inline bool add_ok(uint64_t a, uint64_t b, uint64_t& r) {
  return !__builtin_add_overflow(a, b, &r);
}
inline bool mul_ok(uint64_t a, uint64_t b, uint64_t& r) {
  return !__builtin_mul_overflow(a, b, &r);
}

/// "array[i]", the JSON path of an array element.
inline std::string idx(const char* array, size_t i) {
  return std::string(array) + "[" + std::to_string(i) + "]";
}

/// The memory budget (GltfLoadOptions::max_memory_bytes): everything that grows with the file is
/// charged here before it is allocated.
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
  /// Gives back `bytes` (at most what is charged).
  void release(uint64_t bytes) { m_used -= std::min(bytes, m_used); }
  uint64_t used() const { return m_used; }
  uint64_t limit() const { return m_limit; }

 private:
  std::string m_file;
  uint64_t m_limit;
  uint64_t m_used = 0;
};

/// One conversion of a parsed model into `out`. The references outlive every phase.
struct GltfContext {
  const tinygltf::Model& model;
  const std::string& file;  ///< the scene file, as named in every InputError
  const GltfLoadOptions& options;
  MemoryBudget& budget;
  LoadedScene& out;  ///< the scene, info and warnings being filled

  /// Throws InputError(file, element, message).
  [[noreturn]] void fail(const std::string& element, const std::string& message) const {
    throw InputError(file, element, message);
  }
  /// Appends "element: message" to out.warnings.
  void warn(const std::string& element, const std::string& message) const {
    out.warnings.push_back(element + ": " + message);
  }
  /// Charges `bytes` to the budget for `element` (see MemoryBudget::charge).
  void charge(uint64_t bytes, const std::string& element,
              const std::string& subject = "its decoded data needs") const {
    budget.charge(bytes, element, subject);
  }
};

}  // namespace penumbra::gltf
