// Resume state files ("PNMBRCK3"): header, settings text, pixel records, light-group sums,
// odd-sample sums and a trailing SHA-256. Reading validates sizes against the file size, then the checksum,
// then the settings, then every value.
#include "io/farm/checkpoint.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "io/files/atomic_file.h"
#include "io/files/error.h"
#include "io/files/file_checks.h"
#include "io/files/hash.h"
#include "renderer/integrators/light_groups.h"

namespace penumbra {

namespace {

static_assert(std::endian::native == std::endian::little, "resume state files are little-endian");

constexpr char kMagic[8] = {'P', 'N', 'M', 'B', 'R', 'C', 'K', '3'};
constexpr char kOldMagic[8] = {'P', 'N', 'M', 'B', 'R', 'C', 'K', '1'};
constexpr char kOldMagic2[8] = {'P', 'N', 'M', 'B', 'R', 'C', 'K', '2'};
constexpr size_t kDigestBytes = 32;
constexpr uint64_t kGroupsPerPixel = kLightGroupChannels;

using Pixel = PathAccumulators::Pixel;
static_assert(sizeof(Pixel) == kPathPixelBytes,
              "Pixel: rgba, sum_y, sum_y2 (6 doubles), n, active (2 uint32)");

// 64 bytes after the magic, no padding.
struct Header {
  int32_t window[4];        ///< x0, y0, x1, y1
  uint32_t reached;         ///< PathAccumulators::reached
  int32_t passes;           ///< PathAccumulators::passes
  uint32_t complete;        ///< 0 or 1
  uint32_t pixel_bytes;     ///< sizeof(Pixel) of the writer
  uint64_t pixels;          ///< pixel records
  uint64_t groups;          ///< light-group doubles
  uint64_t odd;             ///< odd-sample doubles (RGBA per pixel)
  uint64_t settings_bytes;  ///< canonical settings text
};
static_assert(sizeof(Header) == 64);

constexpr uint64_t kPrefixBytes = sizeof kMagic + sizeof(Header);

// Throws unless the header's counts describe exactly `file_size` bytes. Each count is bounded
// by the file size before anything is added or multiplied, so no sum can overflow.
void check_sizes(const std::string& file, const Header& h, uint64_t file_size) {
  if (h.pixel_bytes != sizeof(Pixel))
    throw InputError(file, "",
                     "truncated or corrupt checkpoint: pixel records of " + std::to_string(h.pixel_bytes) +
                         " bytes, expected " + std::to_string(sizeof(Pixel)));
  const uint64_t budget =
      file_size < kPrefixBytes + kDigestBytes ? 0 : file_size - kPrefixBytes - kDigestBytes;
  const bool fits =
      h.settings_bytes <= kMaxCheckpointSettingsBytes && h.settings_bytes <= budget &&
      h.pixels <= budget / sizeof(Pixel) && h.groups <= budget / sizeof(double) &&
      h.odd <= budget / sizeof(double) &&
      h.settings_bytes + h.pixels * sizeof(Pixel) + (h.groups + h.odd) * sizeof(double) == budget;
  if (!fits)
    throw InputError(file, "",
                     "truncated or corrupt checkpoint: its header does not describe its " +
                         std::to_string(file_size) + " bytes");
}

std::string where(const PathAccumulators& s, size_t i) {
  const int64_t w = int64_t(s.window.x1) - s.window.x0;
  return "pixel " + std::to_string(s.window.x0 + int64_t(i) % w) + "," +
         std::to_string(s.window.y0 + int64_t(i) / w);
}

bool finite_non_negative(double v) {
  return std::isfinite(v) && v >= 0;
}

// Throws unless one pixel's sums could have come from `s.reached` samples of the path tracer.
void check_pixel(const std::string& file, const PathAccumulators& s, size_t i) {
  const Pixel& p = s.pixels[i];
  const auto bad = [&](const std::string& what) {
    return InputError(file, where(s, i), "inconsistent checkpoint: " + what);
  };
  for (int c = 0; c < 4; ++c)
    if (!finite_non_negative(p.rgba[c]))
      throw bad("colour sum " + std::to_string(p.rgba[c]) + " is not finite and >= 0");
  if (!finite_non_negative(p.sum_y) || !finite_non_negative(p.sum_y2))
    throw bad("luminance sums are not finite and >= 0");
  if (p.rgba[3] > double(p.n))
    throw bad("coverage sum " + std::to_string(p.rgba[3]) + " exceeds its " + std::to_string(p.n) +
              " samples");
  if (p.active > 1) throw bad("active flag " + std::to_string(p.active) + " is not 0 or 1");
  if (p.n > s.reached)
    throw bad(std::to_string(p.n) + " samples, more than the " + std::to_string(s.reached) + " reached");
  if (p.active && p.n != s.reached)
    throw bad("still sampling with " + std::to_string(p.n) + " samples, not the " +
              std::to_string(s.reached) + " reached");
  if (p.n == 0 &&
      (p.rgba[0] != 0 || p.rgba[1] != 0 || p.rgba[2] != 0 || p.rgba[3] != 0 || p.sum_y != 0 || p.sum_y2 != 0))
    throw bad("sums without samples");
  for (uint64_t k = 0; k < (s.groups.empty() ? 0 : kGroupsPerPixel); ++k) {
    const double g = s.groups[i * kGroupsPerPixel + k];
    if (!finite_non_negative(g) || (p.n == 0 && g != 0))
      throw bad("light-group sum " + std::to_string(g) + " is not finite and >= 0 (or has no samples)");
  }
  if (s.odd.empty()) return;
  const double* odd = &s.odd[i * 4];
  for (int c = 0; c < 4; ++c)
    if (!finite_non_negative(odd[c]) || odd[c] > p.rgba[c] * (1 + 1e-9) + 1e-9)
      throw bad("odd-sample sum " + std::to_string(odd[c]) +
                " is not finite, >= 0 and within the pixel's sum");
  if (odd[3] > double(p.n / 2)) throw bad("odd-sample coverage exceeds the odd samples");
}

// Throws unless the counters, the window and every pixel agree with each other.
void check_consistency(const std::string& file, const PathAccumulators& s) {
  const auto bad = [&](const std::string& what) {
    return InputError(file, "", "inconsistent checkpoint: " + what);
  };
  const PixelWindow& w = s.window;
  const int64_t width = int64_t(w.x1) - w.x0, height = int64_t(w.y1) - w.y0;
  if (w.x0 < 0 || w.y0 < 0 || width < 1 || height < 1)
    throw bad("empty or negative window " + std::to_string(w.x0) + "," + std::to_string(w.y0) + "-" +
              std::to_string(w.x1) + "," + std::to_string(w.y1));
  if (uint64_t(width) * uint64_t(height) != s.pixels.size())
    throw bad("the window holds " + std::to_string(width * height) + " pixels, the file " +
              std::to_string(s.pixels.size()));
  if (!s.groups.empty() && s.groups.size() != s.pixels.size() * kGroupsPerPixel)
    throw bad(std::to_string(s.groups.size()) + " light-group sums for " + std::to_string(s.pixels.size()) +
              " pixels");
  if (!s.odd.empty() && s.odd.size() != s.pixels.size() * 4)
    throw bad(std::to_string(s.odd.size()) + " odd-sample sums for " + std::to_string(s.pixels.size()) +
              " pixels");
  if (s.passes < 0 || uint64_t(s.passes) > s.reached)
    throw bad(std::to_string(s.passes) + " passes for " + std::to_string(s.reached) + " samples");
  if (s.passes == 0 && s.reached != 0) throw bad("samples without a completed pass");
  for (size_t i = 0; i < s.pixels.size(); ++i) check_pixel(file, s, i);
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const PathAccumulators& state,
                      const RenderSettings& settings) {
  const std::string text = canonical_text(settings);
  Header h{};
  h.window[0] = state.window.x0;
  h.window[1] = state.window.y0;
  h.window[2] = state.window.x1;
  h.window[3] = state.window.y1;
  h.reached = state.reached;
  h.passes = state.passes;
  h.complete = state.complete ? 1 : 0;
  h.pixel_bytes = sizeof(Pixel);
  h.pixels = state.pixels.size();
  h.groups = state.groups.size();
  h.odd = state.odd.size();
  h.settings_bytes = text.size();
  const size_t pixel_bytes = state.pixels.size() * sizeof(Pixel);
  const size_t group_bytes = state.groups.size() * sizeof(double);
  const size_t odd_bytes = state.odd.size() * sizeof(double);
  Sha256 sha;
  sha.update(kMagic, sizeof kMagic);
  sha.update(&h, sizeof h);
  sha.update(text);
  sha.update(state.pixels.data(), pixel_bytes);
  sha.update(state.groups.data(), group_bytes);
  sha.update(state.odd.data(), odd_bytes);
  const std::array<uint8_t, 32> digest = sha.finish();
  write_atomically(path, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out.write(kMagic, sizeof kMagic);
    out.write(reinterpret_cast<const char*>(&h), sizeof h);
    out.write(text.data(), std::streamsize(text.size()));
    out.write(reinterpret_cast<const char*>(state.pixels.data()), std::streamsize(pixel_bytes));
    out.write(reinterpret_cast<const char*>(state.groups.data()), std::streamsize(group_bytes));
    out.write(reinterpret_cast<const char*>(state.odd.data()), std::streamsize(odd_bytes));
    out.write(reinterpret_cast<const char*>(digest.data()), std::streamsize(digest.size()));
    out.flush();
    if (!out) throw std::runtime_error(path.string() + ": cannot write the checkpoint");
  });
}

PathAccumulators read_checkpoint(const std::filesystem::path& path, const RenderSettings& expected) {
  const std::string file = path.string();
  const uint64_t size = check_input_file(path, "", kMaxCheckpointBytes);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, "", "cannot open the checkpoint");

  // Magic and sizes: the only fields used before the checksum is verified.
  char magic[8] = {};
  Header h{};
  in.read(magic, sizeof magic);
  if (in && std::memcmp(magic, kOldMagic, sizeof kOldMagic) == 0)
    throw InputError(file, "",
                     "is a resume state in the old format (PNMBRCK1, without a checksum) that this version "
                     "cannot verify; delete it to render from the beginning");
  if (in && std::memcmp(magic, kOldMagic2, sizeof kOldMagic2) == 0)
    throw InputError(
        file, "",
        "is a resume state in an older format (PNMBRCK2) that this version cannot read; delete it "
        "to render from the beginning");
  if (!in || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw InputError(file, "", "not a Penumbra checkpoint");
  in.read(reinterpret_cast<char*>(&h), sizeof h);
  if (!in) throw InputError(file, "", "truncated or corrupt checkpoint: the header is incomplete");
  check_sizes(file, h, size);

  // The seal, verified by streaming the file through SHA-256 in small chunks: nothing sized by
  // the file is allocated before the checksum and the settings have been accepted.
  const uint64_t sealed = size - kDigestBytes;
  Sha256 sha;
  {
    std::ifstream all(path, std::ios::binary);
    std::vector<char> chunk(1 << 20);
    for (uint64_t left = sealed; left > 0;) {
      const size_t n = size_t(std::min<uint64_t>(left, chunk.size()));
      if (!all.read(chunk.data(), std::streamsize(n)))
        throw InputError(file, "", "truncated or corrupt checkpoint: read failed");
      sha.update(chunk.data(), n);
      left -= n;
    }
    std::array<uint8_t, kDigestBytes> stored{};
    if (!all.read(reinterpret_cast<char*>(stored.data()), std::streamsize(stored.size())))
      throw InputError(file, "", "truncated or corrupt checkpoint: read failed");
    if (sha.finish() != stored)
      throw InputError(
          file, "",
          "checksum mismatch: the checkpoint is damaged (its SHA-256 does not match its contents); "
          "delete it to render from the beginning");
  }

  // The settings it was written for; the payload is read only for a state of this render.
  std::string text(h.settings_bytes, '\0');
  in.read(text.data(), std::streamsize(text.size()));
  if (!in) throw InputError(file, "", "truncated or corrupt checkpoint: read failed");
  RenderSettings settings;
  try {
    settings = parse_canonical_text(text);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, "settings", std::string("malformed: ") + e.what());
  }
  if (settings.entries != expected.entries)
    throw InputError(file, "",
                     "was written for other settings; delete it or render with the same settings:\n" +
                         describe_differences(settings, expected));
  PathAccumulators state;
  state.pixels.resize(h.pixels);
  state.groups.resize(h.groups);
  state.odd.resize(h.odd);
  in.read(reinterpret_cast<char*>(state.pixels.data()), std::streamsize(h.pixels * sizeof(Pixel)));
  in.read(reinterpret_cast<char*>(state.groups.data()), std::streamsize(h.groups * sizeof(double)));
  in.read(reinterpret_cast<char*>(state.odd.data()), std::streamsize(h.odd * sizeof(double)));
  if (!in) throw InputError(file, "", "truncated or corrupt checkpoint: read failed");

  // The values, checked against each other.
  state.window = {h.window[0], h.window[1], h.window[2], h.window[3]};
  state.reached = h.reached;
  state.passes = h.passes;
  if (h.complete > 1)
    throw InputError(file, "", "inconsistent checkpoint: complete flag " + std::to_string(h.complete));
  state.complete = h.complete != 0;
  check_consistency(file, state);
  if (state.complete && state.passes < 1)
    throw InputError(file, "", "inconsistent checkpoint: complete without a pass");
  return state;
}

}  // namespace penumbra
