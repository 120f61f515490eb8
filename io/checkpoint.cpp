// Checkpoint files: "PNMBRCK1", fingerprint, window, counters, pixels, light groups.
#include "io/checkpoint.h"

#include <cstring>
#include <fstream>

#include "io/atomic_file.h"
#include "io/error.h"

namespace penumbra {

namespace {
constexpr char kMagic[8] = {'P', 'N', 'M', 'B', 'R', 'C', 'K', '1'};

struct Header {
  int32_t window[4];
  uint32_t reached;
  int32_t passes;
  uint32_t complete;
  uint64_t pixels;
  uint64_t groups;
  uint64_t fingerprint_bytes;
};
}  // namespace

void write_checkpoint(const std::filesystem::path& path, const PathAccumulators& state,
                      const std::string& fingerprint) {
  Header h{};
  h.window[0] = state.window.x0;
  h.window[1] = state.window.y0;
  h.window[2] = state.window.x1;
  h.window[3] = state.window.y1;
  h.reached = state.reached;
  h.passes = state.passes;
  h.complete = state.complete ? 1 : 0;
  h.pixels = state.pixels.size();
  h.groups = state.groups.size();
  h.fingerprint_bytes = fingerprint.size();
  write_atomically(path, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out.write(kMagic, sizeof kMagic);
    out.write(reinterpret_cast<const char*>(&h), sizeof h);
    out.write(fingerprint.data(), std::streamsize(fingerprint.size()));
    out.write(reinterpret_cast<const char*>(state.pixels.data()), std::streamsize(state.pixels.size() * sizeof(PathAccumulators::Pixel)));
    out.write(reinterpret_cast<const char*>(state.groups.data()), std::streamsize(state.groups.size() * sizeof(double)));
    out.flush();
    if (!out) throw std::runtime_error(path.string() + ": cannot write the checkpoint");
  });
}

PathAccumulators read_checkpoint(const std::filesystem::path& path, const std::string& fingerprint) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, "", "cannot open the checkpoint");
  in.seekg(0, std::ios::end);
  const uint64_t size = uint64_t(in.tellg());
  in.seekg(0);
  char magic[8] = {};
  Header h{};
  in.read(magic, sizeof magic);
  in.read(reinterpret_cast<char*>(&h), sizeof h);
  if (!in || std::memcmp(magic, kMagic, sizeof kMagic) != 0) throw InputError(file, "", "not a Penumbra checkpoint");
  const uint64_t px_bytes = sizeof(PathAccumulators::Pixel);
  const uint64_t header = sizeof kMagic + sizeof h;
  if (h.fingerprint_bytes > (1u << 20) || h.pixels > (uint64_t(1) << 32) || (h.groups != 0 && h.groups != h.pixels * 15) ||
      size != header + h.fingerprint_bytes + h.pixels * px_bytes + h.groups * sizeof(double))
    throw InputError(file, "", "truncated or corrupt checkpoint");
  std::string stored(h.fingerprint_bytes, '\0');
  in.read(stored.data(), std::streamsize(stored.size()));
  if (stored != fingerprint)
    throw InputError(file, "", "was written for other settings; delete it or render with the same settings\n  checkpoint: " +
                                   stored + "\n  this render: " + fingerprint);
  PathAccumulators state;
  state.window = {h.window[0], h.window[1], h.window[2], h.window[3]};
  state.reached = h.reached;
  state.passes = h.passes;
  state.complete = h.complete != 0;
  state.pixels.resize(h.pixels);
  state.groups.resize(h.groups);
  in.read(reinterpret_cast<char*>(state.pixels.data()), std::streamsize(h.pixels * px_bytes));
  in.read(reinterpret_cast<char*>(state.groups.data()), std::streamsize(h.groups * sizeof(double)));
  if (!in) throw InputError(file, "", "truncated checkpoint");
  return state;
}

}  // namespace penumbra
