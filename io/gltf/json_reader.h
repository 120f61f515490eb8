// Typed reads from the raw glTF JSON for the vendor extensions (PENUMBRA_shapes,
// PENUMBRA_procedural): numbers as finite 32-bit floats with a sign bound, fixed-size number
// arrays, bounded integers, booleans, enumerations by name, and the check that an object holds
// only its schema's keys. Each failure is an InputError(file, JSON path, reason). Internal to
// io/gltf/.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <span>
#include <string>

#include "io/files/error.h"
#include "renderer/core/math.h"

namespace penumbra::gltf {

/// A value for messages, cut to 40 characters; infinite numbers (which JSON cannot spell but an
/// overflowing literal such as 1e999 reads as) shown as inf.
std::string shown(const nlohmann::json& v);

/// %.6g of v.
std::string format_number(double v);

/// What a number must be beyond finite as a 32-bit float.
enum class Bound { Any, Positive, NonNegative, NonZero };

class JsonReader {
 public:
  /// Errors name `file`; `suffix` (such as " (material 'marble')") is appended to every message.
  explicit JsonReader(const std::string& file, std::string suffix = {})
      : m_file(file), m_suffix(std::move(suffix)) {}

  [[noreturn]] void fail(const std::string& where, const std::string& message) const {
    throw InputError(m_file, where, message + m_suffix);
  }
  static const nlohmann::json* find(const nlohmann::json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  /// Fails unless `obj` is a JSON object (`what` names it in the message).
  void require_object(const nlohmann::json& obj, const std::string& where, const std::string& what) const;
  /// Fails on a key of `obj` in neither `common` nor `typed`; keys listed in `known` (the schema's
  /// other keys) are reported as not applying to `what`. Null entries in the lists are skipped.
  void check_keys(const nlohmann::json& obj, const std::string& where, const std::string& what,
                  std::span<const char* const> common, std::span<const char* const> typed,
                  std::span<const char* const> known) const;
  float number(const nlohmann::json& v, const std::string& where, Bound bound) const;
  float number_or(const nlohmann::json& obj, const char* key, const std::string& where, float fallback,
                  Bound bound) const;
  /// number_or() within [lo, hi].
  float number_in(const nlohmann::json& obj, const char* key, const std::string& where, float fallback,
                  float lo, float hi) const;
  template <size_t N>
  std::array<float, N> numbers(const nlohmann::json& v, const std::string& where, Bound bound) const {
    if (!v.is_array() || v.size() != N)
      fail(where, "must be an array of " + std::to_string(N) + " numbers (got " + shown(v) + ")");
    std::array<float, N> out;
    for (size_t i = 0; i < N; ++i) out[i] = number(v[i], where + "[" + std::to_string(i) + "]", bound);
    return out;
  }
  Vec3f vec3_or(const nlohmann::json& obj, const char* key, const std::string& where, Vec3f fallback,
                Bound bound) const;
  int integer_or(const nlohmann::json& obj, const char* key, const std::string& where, int fallback, int lo,
                 int hi) const;
  /// obj[key] as an affine glTF matrix (16 numbers, column-major, last row 0 0 0 1), which
  /// excludes the keys translation, rotation and scale; false (t untouched) if absent.
  bool matrix_or(const nlohmann::json& obj, const char* key, const std::string& where, Transform& t) const;
  /// An unsigned 32-bit integer.
  uint32_t uint32_or(const nlohmann::json& obj, const char* key, const std::string& where,
                     uint32_t fallback) const;
  bool boolean_or(const nlohmann::json& obj, const char* key, const std::string& where, bool fallback) const;
  /// The index in `names` of the string at obj[key], `fallback` if absent.
  int choice_or(const nlohmann::json& obj, const char* key, const std::string& where,
                std::span<const char* const> names, int fallback) const;

 private:
  const std::string& m_file;
  std::string m_suffix;
};

}  // namespace penumbra::gltf
