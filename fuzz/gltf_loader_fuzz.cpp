// libFuzzer entry point for the glTF loader (io/gltf/): each input is written as a .glb (if it starts with
// the GLB magic) or .gltf file in a private folder and loaded. An InputError is the expected
// outcome for garbage; anything else (crash, sanitizer report, other exception, leak) is a
// finding.
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/files/error.h"
#include "io/gltf/loader.h"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("penumbra-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const fs::path file = dir / (glb ? "input.glb" : "input.gltf");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  penumbra::GltfLoadOptions options;
  options.max_memory_bytes = 256ull << 20;  // keep the fuzzer within its RSS limit
  options.time = 0.5;                       // exercise the animation path too
  try {
    (void)penumbra::load_gltf(file, options);
  } catch (const penumbra::InputError&) {
  }
  return 0;
}
