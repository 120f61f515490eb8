// libFuzzer entry point for io/exr_merge's part reader and io/image/deep_exr's deep reader. The
// first input byte holds the options:
//   bit 0: MergeOptions::force (skip the metadata comparison, reach the geometric checks);
//   bit 1: two parts; the next 4 bytes (little-endian, taken modulo the remaining size) give
//          the first part's length, the rest is the second part. Otherwise the rest is one part.
//   bit 2: besides the merge, read the first part as a deep image (read_deep_exr) and composite
//          it (flatten_deep, and with two parts merge_deep and holdout_deep when both read).
// The parts are written as .exr files and merged to a temporary output under a 64 MiB frame
// bound. InputError and std::runtime_error (a failed write) are expected outcomes for garbage;
// anything else (crash, sanitizer report, other exception, leak) is a finding.
// With PENUMBRA_FUZZ_WRITE_SEEDS=DIR set, the target writes seed inputs (pairs of stripes of one
// frame, single- and multi-part, deep stripes, and a whole frame) to DIR with write_exr and
// write_deep_exr and exits.
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "io/farm/render_settings.h"
#include "io/files/error.h"
#include "io/image/deep_exr.h"
#include "io/image/exr_merge.h"
#include "io/image/image_output.h"

namespace fs = std::filesystem;

namespace {

const fs::path& work_dir() {
  static const fs::path d = [] {
    const fs::path p = fs::temp_directory_path() / ("penumbra-fuzz-merge-" + std::to_string(::getpid()));
    fs::create_directories(p);
    return p;
  }();
  return d;
}

void write_file(const fs::path& path, std::string_view bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), std::streamsize(bytes.size()));
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Rows [y0, y1) of a 5x4 frame with a depth AOV, as a Penumbra tile.
std::string stripe(int y0, int y1, bool multipart, const std::string& compression) {
  penumbra::Film film = penumbra::make_film(5, y1 - y0);
  film.origin_y = y0;
  film.full_height = 4;
  for (size_t i = 0; i < film.rgba.size(); ++i) film.rgba[i] = float(i % 7) * 0.25f;
  std::vector<float> depth(size_t(film.width) * size_t(film.height), 2.5f);
  penumbra::ExrOptions opt;
  opt.multipart = multipart;
  opt.compression = compression;
  opt.extra = {{"Z", &depth}};
  const penumbra::RenderSettings settings{{{"camera", "Main"}, {"width", "5"}}};
  opt.metadata = {{penumbra::kSceneHashAttribute, std::string(64, 'b')},
                  {penumbra::kSettingsAttribute, penumbra::canonical_text(settings)}};
  const fs::path path = work_dir() / "seed.exr";
  penumbra::write_exr(film, path, opt);
  return read_file(path);
}

// Rows [y0, y1) of a 5x4 deep frame: pixel (x, y) holds x % 3 samples, the last of two the
// background at +inf.
std::string deep_stripe(int y0, int y1) {
  penumbra::DeepImage img;
  img.width = img.full_width = 5;
  img.height = y1 - y0;
  img.origin_y = y0;
  img.full_height = 4;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < 5; ++x) {
      img.counts.push_back(uint32_t(x % 3));
      for (int k = 0; k < x % 3; ++k) {
        penumbra::DeepSample s;
        s.r = 0.25f * float(x);
        s.a = k == 0 ? 0.5f : 0.0f;
        s.z = s.zback = k == 0 ? 1.0f + float(y) : std::numeric_limits<float>::infinity();
        s.id = float(x);
        img.samples.push_back(s);
      }
    }
  penumbra::ExrOptions opt;
  const penumbra::RenderSettings settings{{{"camera", "Main"}, {"width", "5"}}};
  opt.metadata = {{penumbra::kSceneHashAttribute, std::string(64, 'b')},
                  {penumbra::kSettingsAttribute, penumbra::canonical_text(settings)}};
  const fs::path path = work_dir() / "seed.exr";
  penumbra::write_deep_exr(img, path, opt);
  return read_file(path);
}

std::string two_parts(char flags, const std::string& a, const std::string& b) {
  const uint32_t n = uint32_t(a.size());
  std::string out(1, char(flags | 2));
  for (int i = 0; i < 4; ++i) out += char((n >> (8 * i)) & 0xff);
  return out + a + b;
}

void write_seeds(const fs::path& dir) {
  fs::create_directories(dir);
  write_file(dir / "seed-stripes-zip", two_parts(0, stripe(0, 2, false, "zip"), stripe(2, 4, false, "zip")));
  write_file(dir / "seed-stripes-piz-forced",
             two_parts(1, stripe(0, 1, false, "piz"), stripe(1, 4, false, "piz")));
  write_file(dir / "seed-stripes-multipart",
             two_parts(0, stripe(0, 3, true, "rle"), stripe(3, 4, true, "rle")));
  write_file(dir / "seed-whole-none", std::string(1, '\0') + stripe(0, 4, false, "none"));
  write_file(dir / "seed-whole-dwaa", std::string(1, '\1') + stripe(0, 4, true, "dwaa"));
  write_file(dir / "seed-deep-stripes", two_parts(4, deep_stripe(0, 1), deep_stripe(1, 4)));
  write_file(dir / "seed-deep-whole", std::string(1, '\4') + deep_stripe(0, 4));
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  OIIO::attribute("threads", 1);
  OIIO::attribute("exr_threads", 1);
  if (const char* dir = std::getenv("PENUMBRA_FUZZ_WRITE_SEEDS")) {
    write_seeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t flags = data[0];
  std::string_view rest(reinterpret_cast<const char*>(data + 1), size - 1);
  std::vector<fs::path> parts = {work_dir() / "a.exr"};
  if ((flags & 2) && rest.size() >= 4) {
    uint32_t n = 0;
    for (int i = 0; i < 4; ++i) n |= uint32_t(uint8_t(rest[size_t(i)])) << (8 * i);
    rest.remove_prefix(4);
    const size_t first = rest.empty() ? 0 : n % (rest.size() + 1);
    write_file(parts[0], rest.substr(0, first));
    parts.push_back(work_dir() / "b.exr");
    write_file(parts[1], rest.substr(first));
  } else {
    write_file(parts[0], rest);
  }
  penumbra::MergeOptions options;
  options.force = flags & 1;
  options.max_memory_bytes = uint64_t(64) << 20;
  try {
    penumbra::merge_exr_parts(parts, work_dir() / "merged.exr", options);
  } catch (const std::runtime_error&) {  // InputError included
  }
  if (flags & 4) {
    try {
      const penumbra::DeepImage a = penumbra::read_deep_exr(parts[0], options.max_memory_bytes);
      (void)penumbra::flatten_deep(a);
      if (parts.size() > 1) {
        const penumbra::DeepImage b = penumbra::read_deep_exr(parts[1], options.max_memory_bytes);
        if (penumbra::same_window(a, b)) {
          (void)penumbra::merge_deep({&a, &b});
          (void)penumbra::holdout_deep(a, b);
        }
      }
    } catch (const std::runtime_error&) {
    }
  }
  return 0;
}
