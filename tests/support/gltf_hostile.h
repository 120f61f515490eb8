// Test helpers for glTF files that break the spec on purpose: a one-triangle scene to edit,
// raw text and byte files, extra GLB chunks, a PNG CRC, and matchers for the "file: element:"
// prefix every loader InputError starts with.
#pragma once

#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "io/gltf/loader.h"
#include "support/gltf_writer.h"
#include "support/test_util.h"

namespace penumbra::test {

// The file name and the element, as every InputError from the loader starts.
inline Catch::Matchers::StdString::ContainsMatcher names(const std::filesystem::path& file,
                                                         const std::string& element) {
  return Catch::Matchers::Contains(file.string() + ": " + element + ":");
}

inline std::filesystem::path write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A one-triangle scene (data URI buffer) whose JSON `edit` then modifies.
template <class Edit>
std::filesystem::path triangle_scene(const std::string& test, Edit edit, GltfWriter* writer = nullptr) {
  GltfWriter local;
  GltfWriter& w = writer ? *writer : local;
  w.node({{"mesh", w.mesh(w.positions({0, 0, 0, 1, 0, 0, 0, 1, 0}))}});
  edit(w);
  const auto path = temp_dir(test) / "scene.gltf";
  w.write_embedded(path);
  return path;
}

inline bool has_warning(const LoadedScene& l, const std::string& needle) {
  for (const auto& w : l.warnings)
    if (w.find(needle) != std::string::npos) return true;
  return false;
}

inline std::vector<uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Appends a chunk to a GLB file and fixes the header's total length.
inline void append_glb_chunk(const std::filesystem::path& path, uint32_t type,
                             const std::vector<uint8_t>& data) {
  std::vector<uint8_t> b = read_bytes(path);
  const uint32_t length = uint32_t(data.size());
  b.insert(b.end(), reinterpret_cast<const uint8_t*>(&length), reinterpret_cast<const uint8_t*>(&length) + 4);
  b.insert(b.end(), reinterpret_cast<const uint8_t*>(&type), reinterpret_cast<const uint8_t*>(&type) + 4);
  b.insert(b.end(), data.begin(), data.end());
  const uint32_t total = uint32_t(b.size());
  std::memcpy(b.data() + 8, &total, 4);
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}

// CRC-32 (ISO 3309) as PNG chunks carry it.
inline uint32_t crc32(const uint8_t* p, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

}  // namespace penumbra::test
