// SHA-256 after FIPS 180-4, section 6.2.
#include "io/files/hash.h"

#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "io/files/error.h"
#include "io/files/file_checks.h"

namespace penumbra {

namespace {

constexpr uint32_t kRound[64] = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

inline uint32_t rotr(uint32_t x, int n) {
  return (x >> n) | (x << (32 - n));
}

}  // namespace

Sha256::Sha256()
    : m_h{0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19} {}

void Sha256::block(const uint8_t* p) {
  uint32_t w[64];
  for (int i = 0; i < 16; ++i)
    w[i] =
        uint32_t(p[4 * i]) << 24 | uint32_t(p[4 * i + 1]) << 16 | uint32_t(p[4 * i + 2]) << 8 | p[4 * i + 3];
  for (int i = 16; i < 64; ++i) {
    const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
    const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
    w[i] = w[i - 16] + s0 + w[i - 7] + s1;
  }
  uint32_t a = m_h[0], b = m_h[1], c = m_h[2], d = m_h[3], e = m_h[4], f = m_h[5], g = m_h[6], h = m_h[7];
  for (int i = 0; i < 64; ++i) {
    const uint32_t t1 =
        h + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + kRound[i] + w[i];
    const uint32_t t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & c) ^ (b & c));
    h = g, g = f, f = e, e = d + t1, d = c, c = b, b = a, a = t1 + t2;
  }
  m_h[0] += a, m_h[1] += b, m_h[2] += c, m_h[3] += d, m_h[4] += e, m_h[5] += f, m_h[6] += g, m_h[7] += h;
}

void Sha256::update(const void* data, size_t bytes) {
  if (bytes == 0) return;  // `data` may be null then (an empty vector's data())
  const auto* p = static_cast<const uint8_t*>(data);
  m_length += bytes;
  if (m_fill > 0) {
    const size_t take = std::min(bytes, sizeof m_buffer - m_fill);
    std::memcpy(m_buffer + m_fill, p, take);
    m_fill += take, p += take, bytes -= take;
    if (m_fill < sizeof m_buffer) return;
    block(m_buffer);
    m_fill = 0;
  }
  for (; bytes >= 64; p += 64, bytes -= 64) block(p);
  std::memcpy(m_buffer, p, bytes);
  m_fill = bytes;
}

std::array<uint8_t, 32> Sha256::finish() {
  const uint64_t bits = m_length * 8;
  const uint8_t pad = 0x80;
  update(&pad, 1);
  const uint8_t zero[64] = {};
  update(zero, (m_fill <= 56 ? 56 - m_fill : 120 - m_fill));
  uint8_t len[8];
  for (int i = 0; i < 8; ++i) len[i] = uint8_t(bits >> (56 - 8 * i));
  update(len, 8);
  std::array<uint8_t, 32> digest{};
  for (int i = 0; i < 8; ++i)
    for (int k = 0; k < 4; ++k) digest[size_t(4 * i + k)] = uint8_t(m_h[i] >> (24 - 8 * k));
  return digest;
}

std::string Sha256::finish_hex() {
  static const char* digits = "0123456789abcdef";
  std::string hex;
  for (uint8_t b : finish()) hex += digits[b >> 4], hex += digits[b & 15];
  return hex;
}

std::string sha256_hex(std::string_view data) {
  Sha256 h;
  h.update(data);
  return h.finish_hex();
}

std::string sha256_file(const std::filesystem::path& path) {
  check_input_file(path, "", ~uint64_t(0));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string(), "", "cannot open for reading");
  Sha256 h;
  std::vector<char> buf(1 << 20);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    if (in.gcount() > 0) h.update(buf.data(), size_t(in.gcount()));
  }
  if (in.bad()) throw InputError(path.string(), "", "read failed");
  return h.finish_hex();
}

std::string sha256_of_set(const std::vector<std::filesystem::path>& files,
                          const std::vector<std::string>& digests) {
  namespace fs = std::filesystem;
  if (files.size() != digests.size()) throw std::invalid_argument("sha256_of_set: one digest per file");
  Sha256 h;
  const fs::path base = files.empty() ? fs::path() : fs::absolute(files[0]).lexically_normal().parent_path();
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string name =
        fs::absolute(files[i]).lexically_normal().lexically_relative(base).generic_string();
    h.update(name + '\0' + digests[i] + '\n');
  }
  return h.finish_hex();
}

std::string sha256_of_files(const std::vector<std::filesystem::path>& files) {
  std::vector<std::string> digests;
  for (const auto& f : files) digests.push_back(sha256_file(f));
  return sha256_of_set(files, digests);
}

}  // namespace penumbra
