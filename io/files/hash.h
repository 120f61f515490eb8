// SHA-256 (FIPS 180-4) for content identity: the scene a render came from (the glTF file and
// every buffer and image it loads), checksums of resume state, and the hash of a written image
// recorded beside it, so that outputs written together can be recognised as such.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

/// Incremental SHA-256. update() any number of times, then finish() once.
class Sha256 {
 public:
  Sha256();
  void update(const void* data, size_t bytes);
  void update(std::string_view text) { update(text.data(), text.size()); }
  /// The digest; the object must not be updated afterwards.
  std::array<uint8_t, 32> finish();
  /// finish() as 64 lowercase hex digits (as `sha256sum` prints it).
  std::string finish_hex();

 private:
  void block(const uint8_t* p);
  uint32_t m_h[8];
  uint8_t m_buffer[64];
  uint64_t m_length = 0;  ///< bytes hashed so far
  size_t m_fill = 0;      ///< bytes in m_buffer
};

/// SHA-256 of `data` as hex.
std::string sha256_hex(std::string_view data);

/// SHA-256 identifying a set of files by content (a scene: the glTF file and every buffer and
/// image it loads): over each file's name relative to the first file's folder and its SHA-256
/// (`digests[i]`, hex, of `files[i]`), in the given order. Moving the whole set elsewhere keeps
/// the digest; editing, renaming or replacing any file changes it. Throws std::invalid_argument
/// if the two lists differ in length.
std::string sha256_of_set(const std::vector<std::filesystem::path>& files,
                          const std::vector<std::string>& digests);

/// sha256_of_set over the files' current bytes (read now). Throws InputError as sha256_file does.
std::string sha256_of_files(const std::vector<std::filesystem::path>& files);

/// SHA-256 of a regular file's bytes as hex. Throws InputError naming the file if it is not
/// a regular file or cannot be read.
std::string sha256_file(const std::filesystem::path& path);

}  // namespace penumbra
