// Typed reads from the raw glTF JSON with errors naming the JSON path.
#include "io/gltf/json_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace penumbra::gltf {

using nlohmann::json;

std::string shown(const json& v) {
  if (v.is_number_float() && !std::isfinite(v.get<double>())) return v.get<double>() > 0 ? "inf" : "-inf";
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

void JsonReader::require_object(const json& obj, const std::string& where, const std::string& what) const {
  if (!obj.is_object()) fail(where, "must be " + what + " object (got " + shown(obj) + ")");
}

void JsonReader::check_keys(const json& obj, const std::string& where, const std::string& what,
                            std::span<const char* const> common, std::span<const char* const> typed,
                            std::span<const char* const> known) const {
  auto listed = [](std::span<const char* const> keys, const std::string& key) {
    return std::any_of(keys.begin(), keys.end(), [&](const char* k) { return k && key == k; });
  };
  for (const auto& [key, value] : obj.items()) {
    if (listed(common, key) || listed(typed, key)) continue;
    std::string keys;
    for (auto list : {common, typed})
      for (const char* k : list)
        if (k) keys += (keys.empty() ? "" : ", ") + std::string(k);
    if (listed(known, key))
      fail(where.empty() ? key : where + "." + key,
           "does not apply to " + what + " (its keys: " + keys + ")");
    fail(where.empty() ? key : where + "." + key, "unknown key (" + what + " has: " + keys + ")");
  }
}

float JsonReader::number(const json& v, const std::string& where, Bound bound) const {
  if (!v.is_number()) fail(where, "must be a number (got " + shown(v) + ")");
  const double d = v.get<double>();
  const float f = float(d);
  if (!std::isfinite(d)) fail(where, "must be a finite number (got " + shown(v) + ")");
  if (!std::isfinite(f)) fail(where, "is beyond the 32-bit float range (got " + shown(v) + ")");
  const char* rounded = d != 0 && f == 0 ? ", 0 as a 32-bit float" : "";
  if (bound == Bound::Positive && !(f > 0)) fail(where, "must be > 0 (got " + shown(v) + rounded + ")");
  if (bound == Bound::NonNegative && !(f >= 0)) fail(where, "must be >= 0 (got " + shown(v) + ")");
  if (bound == Bound::NonZero && f == 0) fail(where, "must be non-zero (got " + shown(v) + rounded + ")");
  return f;
}

float JsonReader::number_or(const json& obj, const char* key, const std::string& where, float fallback,
                            Bound bound) const {
  const json* v = find(obj, key);
  return v ? number(*v, where + "." + key, bound) : fallback;
}

float JsonReader::number_in(const json& obj, const char* key, const std::string& where, float fallback,
                            float lo, float hi) const {
  const json* v = find(obj, key);
  if (!v) return fallback;
  const std::string kw = where + "." + key;
  const float f = number(*v, kw, Bound::Any);
  if (!(f >= lo && f <= hi))
    fail(kw, "must be in [" + format_number(lo) + ", " + format_number(hi) + "] (got " + shown(*v) + ")");
  return f;
}

Vec3f JsonReader::vec3_or(const json& obj, const char* key, const std::string& where, Vec3f fallback,
                          Bound bound) const {
  const json* v = find(obj, key);
  if (!v) return fallback;
  const auto a = numbers<3>(*v, where + "." + key, bound);
  return {a[0], a[1], a[2]};
}

int JsonReader::integer_or(const json& obj, const char* key, const std::string& where, int fallback, int lo,
                           int hi) const {
  const json* v = find(obj, key);
  if (!v) return fallback;
  const std::string kw = where + "." + key;
  const std::string range = "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v->is_number_integer()) fail(kw, "must be an integer " + range + " (got " + shown(*v) + ")");
  const bool in_range = v->is_number_unsigned() ? v->get<uint64_t>() >= uint64_t(std::max(lo, 0)) &&
                                                      v->get<uint64_t>() <= uint64_t(hi)
                                                : v->get<int64_t>() >= lo && v->get<int64_t>() <= hi;
  if (!in_range) fail(kw, "must be " + range + " (got " + shown(*v) + ")");
  return int(v->get<int64_t>());
}

bool JsonReader::matrix_or(const json& obj, const char* key, const std::string& where, Transform& t) const {
  const json* matrix = find(obj, key);
  if (!matrix) return false;
  const std::string mw = where + "." + key;
  for (const char* trs : {"translation", "rotation", "scale"})
    if (find(obj, trs)) fail(mw, std::string("cannot be given together with ") + trs);
  const auto m = numbers<16>(*matrix, mw, Bound::Any);
  if (m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1)
    fail(mw, "must be affine (its last row 0, 0, 0, 1)");
  std::array<double, 16> d;
  std::copy(m.begin(), m.end(), d.begin());
  t = from_column_major(d.data());
  return true;
}

uint32_t JsonReader::uint32_or(const json& obj, const char* key, const std::string& where,
                               uint32_t fallback) const {
  const json* v = find(obj, key);
  if (!v) return fallback;
  const std::string kw = where + "." + key;
  if (!v->is_number_integer() || (!v->is_number_unsigned() && v->get<int64_t>() < 0) ||
      v->get<uint64_t>() > 0xffffffffu)
    fail(kw, "must be an integer in [0, 4294967295] (got " + shown(*v) + ")");
  return uint32_t(v->get<uint64_t>());
}

bool JsonReader::boolean_or(const json& obj, const char* key, const std::string& where, bool fallback) const {
  const json* v = find(obj, key);
  if (!v) return fallback;
  if (!v->is_boolean()) fail(where + "." + key, "must be true or false (got " + shown(*v) + ")");
  return v->get<bool>();
}

int JsonReader::choice_or(const json& obj, const char* key, const std::string& where,
                          std::span<const char* const> names, int fallback) const {
  const json* v = find(obj, key);
  if (!v) return fallback;
  std::string all;
  for (const char* n : names) all += (all.empty() ? "\"" : ", \"") + std::string(n) + "\"";
  const std::string kw = where + "." + key;
  if (!v->is_string()) fail(kw, "must be one of " + all + " (got " + shown(*v) + ")");
  const std::string s = v->get<std::string>();
  for (size_t i = 0; i < names.size(); ++i)
    if (s == names[i]) return int(i);
  fail(kw, "'" + s.substr(0, 40) + "' is not one of " + all);
}

}  // namespace penumbra::gltf
