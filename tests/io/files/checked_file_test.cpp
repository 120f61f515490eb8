// Tests for io/checked_file: a file size limit (RLIMIT_FSIZE, so EFBIG on the write that crosses
// it) stands in for a full disk; EXR, PNG and TIFF writes through the proxy must report it with
// the system's reason and leave the previous file as it was.
#include "io/files/checked_file.h"

#include <sys/resource.h>

#include <catch2/catch.hpp>
#include <csignal>
#include <fstream>
#include <random>
#include <sstream>

#include "io/image/image_output.h"
#include "support/test_util.h"

using namespace penumbra;
using Catch::Matchers::Contains;

namespace {

/// Lowers the process's file size limit for its lifetime (SIGXFSZ ignored: the write fails).
struct FileSizeLimit {
  rlimit old{};
  explicit FileSizeLimit(rlim_t bytes) {
    std::signal(SIGXFSZ, SIG_IGN);
    getrlimit(RLIMIT_FSIZE, &old);
    rlimit r = old;
    r.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &r);
  }
  ~FileSizeLimit() { setrlimit(RLIMIT_FSIZE, &old); }
};

Film noise(int w, int h) {
  Film f = make_film(w, h);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  for (float& v : f.rgba) v = u(rng);  // incompressible, so the file is large
  return f;
}

std::string bytes_of(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_CASE("checked file: a write that cannot complete is an error and the old file stays",
          "[io][checked][quick]") {
  const auto dir = test::temp_dir("checked_file");
  for (const char* name : {"big.exr", "big.png", "big.tif"}) {
    const auto path = dir / name;
    write_display_image(noise(8, 8), dir / "small.png", {});  // any bytes as the previous file
    std::filesystem::copy_file(dir / "small.png", path, std::filesystem::copy_options::overwrite_existing);
    const std::string before = bytes_of(path);
    const Film film = noise(256, 256);
    bool threw = false;
    std::string what;
    {
      FileSizeLimit limit(16 * 1024);
      try {
        if (std::string(name).ends_with(".exr")) {
          ExrOptions o;
          o.half = false;
          o.compression = "none";
          write_exr(film, path, o);
        } else {
          write_display_image(film, path, {});
        }
      } catch (const std::runtime_error& e) {
        threw = true;
        what = e.what();
      }
    }
    INFO(name << ": " << what);
    CHECK(threw);
    CHECK_THAT(what, Contains(path.string()) && Contains("File too large"));
    CHECK(bytes_of(path) == before);
  }
  // Without the limit the same writes succeed and read back.
  CHECK_NOTHROW(write_exr(noise(256, 256), dir / "ok.exr", {}));
  CHECK_NOTHROW(write_display_image(noise(256, 256), dir / "ok.png", {}));
  CHECK(std::filesystem::file_size(dir / "ok.exr") > 16 * 1024);
}
