// libFuzzer entry point for io/checkpoint's reader. The first input byte selects the mode, the
// rest is the resume state file:
//   even: the bytes are written unchanged (exercises magic, size and checksum checks);
//   odd:  the last 32 bytes are replaced by the SHA-256 of the others before writing, so a
//         mutated header, settings text or pixel record passes the checksum and reaches the
//         size, settings and consistency checks.
// read_checkpoint runs with fixed expected settings; an InputError is the expected outcome for
// garbage, anything else (crash, sanitizer report, other exception, leak) is a finding.
// With PENUMBRA_FUZZ_WRITE_SEEDS=DIR set, the target writes seed inputs (valid states in both
// modes) to DIR with write_checkpoint and exits.
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "io/farm/checkpoint.h"
#include "io/files/error.h"
#include "io/files/hash.h"
#include "renderer/integrators/light_groups.h"

namespace fs = std::filesystem;

namespace {

const penumbra::RenderSettings& expected_settings() {
  static const penumbra::RenderSettings s{
      {{"camera", "Main"}, {"scene.sha256", std::string(64, 'a')}, {"seed", "1"}, {"width", "8"}}};
  return s;
}

const fs::path& work_dir() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("penumbra-fuzz-checkpoint-" + std::to_string(::getpid()));
    fs::create_directories(p);
    return p;
  }();
  return d;
}

// A consistent w x h state after `reached` samples, every other pixel stopped at 2; `groups`
// adds light-group and odd-sample sums.
penumbra::PathAccumulators seed_state(int w, int h, uint32_t reached, bool groups) {
  penumbra::PathAccumulators st;
  st.window = {1, 2, 1 + w, 2 + h};
  st.pixels.resize(size_t(w) * size_t(h));
  for (size_t i = 0; i < st.pixels.size(); ++i) {
    auto& p = st.pixels[i];
    p.active = i % 2;
    p.n = p.active ? reached : 2;
    p.rgba[0] = p.rgba[1] = p.rgba[2] = 0.5 * p.n;
    p.rgba[3] = p.n;
    p.sum_y = 0.5 * p.n;
    p.sum_y2 = 0.25 * p.n;
  }
  if (groups) st.groups.assign(st.pixels.size() * penumbra::kLightGroupChannels, 0.125);
  if (groups)  // with the odd samples' sums too: a quarter of the colour and coverage
    for (const auto& p : st.pixels)
      for (int c = 0; c < 4; ++c) st.odd.push_back(p.rgba[c] / 4);
  st.reached = reached;
  st.passes = 3;
  return st;
}

void write_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  int k = 0;
  for (const bool groups : {false, true})
    for (const uint32_t reached : {4u, 16u}) {
      const fs::path state = work_dir() / "seed.resume";
      penumbra::write_checkpoint(state, seed_state(3, 2, reached, groups), expected_settings());
      std::ifstream in(state, std::ios::binary);
      const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      for (const char mode : {'\0', '\1'})
        std::ofstream(dir / ("seed-" + std::to_string(k++)), std::ios::binary) << mode << bytes;
    }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("PENUMBRA_FUZZ_WRITE_SEEDS")) {
    write_seeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if ((data[0] & 1) && bytes.size() >= 32) {
    penumbra::Sha256 sha;
    sha.update(bytes.data(), bytes.size() - 32);
    const std::array<uint8_t, 32> digest = sha.finish();
    std::memcpy(&bytes[bytes.size() - 32], digest.data(), digest.size());
  }
  const fs::path file = work_dir() / "input.resume";
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
  try {
    (void)penumbra::read_checkpoint(file, expected_settings());
  } catch (const penumbra::InputError&) {
  }
  return 0;
}
