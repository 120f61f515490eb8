// Cryptomatte hashing and the ranking pixel filter.
#include "renderer/film/cryptomatte.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace penumbra {

namespace {

uint32_t rotl32(uint32_t x, int r) {
  return (x << r) | (x >> (32 - r));
}

uint32_t float_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

}  // namespace

uint32_t murmur3_32(std::string_view bytes, uint32_t seed) {
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t len = bytes.size(), blocks = len / 4;
  constexpr uint32_t c1 = 0xcc9e2d51u, c2 = 0x1b873593u;
  uint32_t h = seed;
  for (size_t i = 0; i < blocks; ++i) {
    uint32_t k = uint32_t(data[i * 4]) | uint32_t(data[i * 4 + 1]) << 8 | uint32_t(data[i * 4 + 2]) << 16 |
                 uint32_t(data[i * 4 + 3]) << 24;
    k *= c1;
    k = rotl32(k, 15);
    k *= c2;
    h ^= k;
    h = rotl32(h, 13);
    h = h * 5 + 0xe6546b64u;
  }
  const unsigned char* tail = data + blocks * 4;
  uint32_t k = 0;
  switch (len & 3) {
    case 3:
      k ^= uint32_t(tail[2]) << 16;
      [[fallthrough]];
    case 2:
      k ^= uint32_t(tail[1]) << 8;
      [[fallthrough]];
    case 1:
      k ^= uint32_t(tail[0]);
      k *= c1;
      k = rotl32(k, 15);
      k *= c2;
      h ^= k;
  }
  h ^= uint32_t(len);
  h ^= h >> 16;
  h *= 0x85ebca6bu;
  h ^= h >> 13;
  h *= 0xc2b2ae35u;
  h ^= h >> 16;
  return h;
}

float crypto_hash_to_float(uint32_t hash) {
  const uint32_t exponent = std::clamp((hash >> 23) & 0xffu, 1u, 254u);
  const uint32_t bits = (hash & 0x807fffffu) | exponent << 23;
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

float crypto_id(std::string_view name) {
  return crypto_hash_to_float(murmur3_32(name));
}

std::string crypto_hex(float id) {
  char buf[9];
  std::snprintf(buf, sizeof buf, "%08x", float_bits(id));
  return buf;
}

std::string crypto_key(std::string_view layer) {
  char buf[9];
  std::snprintf(buf, sizeof buf, "%08x", murmur3_32(layer));
  return std::string(buf, 7);
}

void rank_crypto_ids(std::vector<float>& ids, int depth, int channels, float* out) {
  std::fill(out, out + channels, 0.0f);
  if (ids.empty()) return;
  // Group equal ids (by bits, so the order is total and exact), then rank the groups.
  std::sort(ids.begin(), ids.end(), [](float a, float b) { return float_bits(a) < float_bits(b); });
  std::vector<std::pair<size_t, float>> groups;  // (count, id)
  for (size_t k = 0; k < ids.size();) {
    size_t e = k;
    while (e < ids.size() && float_bits(ids[e]) == float_bits(ids[k])) ++e;
    if (ids[k] != 0.0f) groups.emplace_back(e - k, ids[k]);
    k = e;
  }
  int filled = 0;
  std::stable_sort(groups.begin(), groups.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& [count, id] : groups) {
    if (filled >= depth || filled * 2 + 1 >= channels) break;
    out[filled * 2] = id;
    out[filled * 2 + 1] = float(count) / float(ids.size());  // exactly 1 when every sample agrees
    ++filled;
  }
}

}  // namespace penumbra
