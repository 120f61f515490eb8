// libFuzzer entry point for io/job_file's reader: the input is a job file, read beside a
// readable scene file (scene.gltf), then split into work units; the first, the last and a unit
// in the middle are computed and their outputs formed. An InputError is the expected outcome
// for garbage, anything else (crash, sanitizer report, other exception, leak, a unit count
// beyond kMaxJobUnits) is a finding. With PENUMBRA_FUZZ_WRITE_SEEDS=DIR set, the target writes
// seed job files (stills, ranges, tiles, tile_frames, settings) to DIR and exits.
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/farm/job_file.h"
#include "io/files/error.h"

namespace fs = std::filesystem;

namespace {

const fs::path& work_dir() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("penumbra-fuzz-job-" + std::to_string(::getpid()));
    fs::create_directories(p);
    std::ofstream(p / "scene.gltf") << "{}";
    return p;
  }();
  return d;
}

void write_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  const char* seeds[] = {
      R"({"shots": [{"name": "a", "scene": "scene.gltf", "output": "a.exr"}]})",
      R"({"version": 1, "defaults": {"spp": 4, "aov": ["Z", "id"], "float": true},
          "shots": [{"name": "b", "scene": "scene.gltf", "output": "out/b.####.exr", "frames": "1-20:3",
                     "tiles": 3, "tile_frames": "4-16:2", "png": "b.####.png", "camera": 0}]})",
      R"({"output_root": "out", "shots": [{"name": "c", "scene": "scene.gltf", "output": "out/c.#.exr",
          "frames": "-5--1", "settings": {"look-at": ["0,1,5", "0,0,0"], "tiles": 2}}]})",
  };
  int i = 0;
  for (const char* s : seeds) std::ofstream(dir / ("seed" + std::to_string(i++) + ".json")) << s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool seeded = [] {
    if (const char* dir = std::getenv("PENUMBRA_FUZZ_WRITE_SEEDS")) {
      write_seeds(dir);
      std::exit(0);
    }
    return true;
  }();
  (void)seeded;
  const fs::path file = work_dir() / "job.json";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    const penumbra::Job job = penumbra::read_job_file(file);
    const penumbra::JobUnits units(job, 1 + int(size % 3));
    if (units.size() > penumbra::kMaxJobUnits) std::abort();
    for (const size_t n : {size_t(0), units.size() / 2, units.size() - 1})
      if (n < units.size()) (void)penumbra::unit_output(job, units[n]);
  } catch (const penumbra::InputError&) {
  }
  return 0;
}
