// The `penumbra` command: `render` a glTF scene to EXR (+ display PNG) and print its `info`.
// Exit codes: 0 success, 2 bad input or usage, 1 internal failure. Only main() exits.
#include <CLI/CLI.hpp>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <charconv>
#include <climits>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/file_checks.h"
#include "io/hash.h"
#include "io/render_settings.h"
#include "io/error.h"
#include "io/gltf_loader.h"
#include "io/image_output.h"
#include "io/accel_params.h"
#include "io/environment_io.h"
#include "io/checkpoint.h"
#include "io/exr_merge.h"
#include "renderer/accel/factory.h"
#include "renderer/accel/embree.h"
#include "renderer/scene/camera.h"
#include "renderer/film/aov.h"
#include "renderer/film/cost_map.h"
#include "renderer/integrators/render.h"

namespace fs = std::filesystem;
using namespace penumbra;

namespace {

constexpr int kExitOk = 0, kExitInternal = 1, kExitInput = 2;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

/// Bad command-line values: reported like bad files, exit 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// What the program is doing, for the out-of-memory message (main() reports it).
const char* g_phase = "parsing the command line";

/// A decimal integer in [lo, hi]: digits only (a leading '-' only if lo < 0), no spaces, no
/// wrap-around. Throws UsageError naming `option` and the valid range otherwise.
long long parse_integer(std::string_view text, long long lo, long long hi, const std::string& option) {
  long long v = 0;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, v);
  if (text.empty() || r.ptr != end || (r.ec != std::errc() && r.ec != std::errc::result_out_of_range) ||
      text[0] == '+' || (text[0] == '-' && lo >= 0))
    throw UsageError(option + ": '" + std::string(text) + "' is not an integer");
  if (r.ec == std::errc::result_out_of_range || v < lo || v > hi)
    throw UsageError(option + ": " + std::string(text) + " is outside [" + std::to_string(lo) + ", " +
                     std::to_string(hi) + "]");
  return v;
}

/// Splits "a<sep>b" into exactly two parts; throws UsageError with `expected` otherwise.
std::pair<std::string, std::string> split_pair(const std::string& text, char sep, const std::string& option,
                                               const std::string& expected) {
  const size_t at = text.find(sep);
  if (at == std::string::npos || text.find(sep, at + 1) != std::string::npos)
    throw UsageError(option + ": expected " + expected + ", got '" + text + "'");
  return {text.substr(0, at), text.substr(at + 1)};
}

// While a path render runs, the first SIGINT/SIGTERM asks it to stop after the current pass
// (the finished passes are then written); otherwise, or on a second signal, temporaries are
// removed and the process dies of the signal.
std::atomic<bool> g_graceful{false}, g_stop{false};
std::atomic<int> g_signal{0};

extern "C" void on_signal(int sig) {
  if (g_graceful.load() && !g_stop.load()) {
    g_signal = sig;
    g_stop = true;
    return;
  }
  remove_pending_temporaries();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

double peak_memory_mib() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0;  // ru_maxrss is KiB on Linux
}

uint64_t default_memory_budget() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 8ull << 30;
  return uint64_t(pages) * uint64_t(page) / 2;  // half the machine's RAM
}

/// "512M", "4G", "1073741824" -> bytes.
uint64_t parse_bytes(const std::string& s) {
  size_t pos = 0;
  double v = 0;
  try {
    v = std::stod(s, &pos);
  } catch (...) {
    throw UsageError("--max-memory: cannot parse '" + s + "'");
  }
  const std::string unit = s.substr(pos);
  double mul = 1;
  if (unit == "K" || unit == "k") mul = 1024.0;
  else if (unit == "M" || unit == "m") mul = 1024.0 * 1024;
  else if (unit == "G" || unit == "g") mul = 1024.0 * 1024 * 1024;
  else if (!unit.empty()) throw UsageError("--max-memory: unknown unit '" + unit + "' (use K, M or G)");
  if (!(v > 0) || !std::isfinite(v * mul) || v * mul > 1e15) throw UsageError("--max-memory: out of range: " + s);
  return uint64_t(v * mul);
}

/// "r,g,b" or a single grey value -> Vec3f, each finite and >= 0.
Vec3f parse_colour(const std::string& s, const char* option) {
  std::vector<float> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t pos = 0;
      v.push_back(std::stof(item, &pos));
      if (pos != item.size()) throw std::invalid_argument(item);
    } catch (...) {
      throw UsageError(std::string(option) + ": cannot parse '" + s + "' (expected r,g,b or one value)");
    }
  }
  if (v.size() == 1) v = {v[0], v[0], v[0]};
  if (v.size() != 3) throw UsageError(std::string(option) + ": expected r,g,b or one value, got '" + s + "'");
  for (float x : v)
    if (!std::isfinite(x) || x < 0) throw UsageError(std::string(option) + ": values must be finite and >= 0");
  return {v[0], v[1], v[2]};
}

std::string human_count(uint64_t n) {
  char buf[32];
  if (n >= 1000000) std::snprintf(buf, sizeof buf, "%.2fM", double(n) / 1e6);
  else if (n >= 1000) std::snprintf(buf, sizeof buf, "%.1fk", double(n) / 1e3);
  else std::snprintf(buf, sizeof buf, "%llu", static_cast<unsigned long long>(n));
  return buf;
}

/// Progress on stderr: a self-overwriting line on a terminal, or a line per 10% in logs.
class ProgressReporter {
 public:
  explicit ProgressReporter(bool enabled) : m_enabled(enabled), m_tty(isatty(STDERR_FILENO)) {}
  void operator()(int done, int total) {
    if (!m_enabled) return;
    std::lock_guard lock(m_mutex);
    const double elapsed = seconds_since(m_start);
    const double frac = double(done) / double(total);
    const int decile = int(frac * 10);
    if (m_tty) {
      if (done != total && elapsed - m_last < 0.1) return;
      m_last = elapsed;
    } else {
      if (decile <= m_last_decile) return;
      m_last_decile = decile;
    }
    m_open = m_tty && done != total;
    const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
    std::fprintf(stderr, "%srender %5.1f%%  elapsed %6.1fs  eta %6.1fs%s", m_tty ? "\r" : "",
                 100 * frac, elapsed, eta, m_tty ? (done == total ? "\n" : "") : "\n");
    std::fflush(stderr);
  }

  /// Ends a terminal progress line left open by a render that stopped early (--time-limit,
  /// --adaptive), so the summary starts on its own line.
  void finish() {
    std::lock_guard lock(m_mutex);
    if (m_open) std::fputc('\n', stderr);
    m_open = false;
  }

 private:
  bool m_enabled, m_tty, m_open = false;
  std::mutex m_mutex;
  Clock::time_point m_start = Clock::now();
  double m_last = -1;
  int m_last_decile = 0;
};

struct RenderArgs {
  std::string scene_file, output, png;
  bool multipart = false;
  bool no_png = false, use_float = false, quiet = false, allow_external = false, flatten = false;
  int width = 0, height = 0, spp = 4, max_depth = 5, threads = 0, scene = -1;
  std::string camera;  ///< index or name; empty = the first camera, or framing
  std::string seed = "0";      ///< parsed as an unsigned 64-bit integer
  float exposure = 0;
  std::string compression = "zip", ocio_config, display, view, background = "0", ambient = "0.05";
  std::string accel = "embree", max_memory, debug_pixel, cost_png;
  std::vector<std::string> accel_params, aovs;
  std::string command_line, look;
  std::vector<std::string> crop;  ///< x0 x1 y0 y1, pixels or fractions
  std::string tile;               ///< "i/N"
  double checkpoint = 0;          ///< seconds between checkpoints; 0 = none
  std::string stats_json;
  bool resume = false;
  std::string integrator = "whitted", light_sampling = "mis", sampler = "sobol", filter, env;
  int rr_depth = 3, adaptive_min_spp = 16;
  float clamp_indirect = 0, env_intensity = 1, env_rotation = 0, filter_width = 0, adaptive = 0;
  double time_limit = 0;
  bool spp_given = false, depth_given = false, background_given = false, ambient_given = false;
  std::optional<double> time;   ///< --time, seconds
  std::optional<std::string> frame;  ///< --frame, an integer, converted with --fps
  double fps = 24;
};

/// The accelerator name and "key=value" parameters, checked before any loading: exit 2 with
/// the list of valid names or keys.
AccelConfig parse_accel(const std::string& name, const std::vector<std::string>& params) {
  bool known = false;
  std::string names;
  for (const auto& n : accelerator_names()) {
    known |= n == name;
    names += (names.empty() ? "" : ", ") + n;
  }
  if (!known) throw UsageError("--accel: unknown accelerator '" + name + "' (known: " + names + ")");
  AccelConfig config;
  for (const auto& p : params) {
    // A parameter of another structure would be silently unused: refuse it.
    apply_accel_param(config, p);
    const std::string prefix = p.substr(0, p.find('.'));
    if (prefix != name)
      throw UsageError("--accel-param " + p + ": a parameter of '" + prefix + "', but --accel is '" + name + "'");
  }
  validate(config.embree);
  validate(config.bvh);
  validate(config.kdtree);
  validate(config.grid);
  return config;
}

std::string accel_param_help() {
  std::string h = "accelerator build parameter key=value (repeatable):";
  for (const auto& k : accel_param_keys()) h += "\n  " + k.key + " (default " + k.default_value + "): " + k.description;
  return h;
}

/// The camera instance `spec` names: an index as `penumbra info` lists them, or a camera name.
/// Throws InputError listing the cameras if there is no such camera or the name is ambiguous.
int find_camera(const Scene& scene, const std::string& spec, const std::string& file) {
  std::string known;
  for (size_t i = 0; i < scene.cameras.size(); ++i)
    known += (known.empty() ? "" : ", ") + std::to_string(i) + " '" + scene.cameras[i].name + "'";
  const std::string listing = scene.cameras.empty() ? "the scene has no camera" : "cameras: " + known;
  if (!spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos) {
    const unsigned long long i = spec.size() <= 9 ? std::stoull(spec) : ~0ull;
    if (i >= scene.cameras.size())
      throw InputError(file, "--camera", "camera " + spec + " does not exist (" + listing + ")");
    return int(i);
  }
  int found = -1;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    if (scene.cameras[i].name != spec) continue;
    if (found >= 0)
      throw InputError(file, "--camera", "camera name '" + spec + "' is ambiguous (" + listing + "); use an index");
    found = int(i);
  }
  if (found < 0) throw InputError(file, "--camera", "no camera named '" + spec + "' (" + listing + ")");
  return found;
}

/// The AOV names --aov accepts (besides "all").
constexpr const char* kAovNames[] = {"albedo", "N", "P", "Z", "UV", "id", "samples", "variance", "light", "cost"};

std::string json_string(const std::string& v) {
  std::string r = "\"";
  for (unsigned char c : v) {
    if (c == '"' || c == '\\') r += '\\', r += char(c);
    else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      r += buf;
    } else r += char(c);
  }
  return r + "\"";
}

/// {"object": {"<id>": "<node name>", ...}, "material": {...}}: the names behind id.object
/// (glTF node index + 1) and id.material (material index + 1); 0 is the background.
std::string id_manifest(const Scene& scene, const GltfInfo& info) {
  std::set<int> nodes;
  for (const auto& inst : scene.instances)
    if (inst.node >= 0) nodes.insert(inst.node);
  std::string j = "{\"object\": {";
  bool first = true;
  for (int n : nodes) {
    const std::string name = size_t(n) < info.node_names.size() ? info.node_names[size_t(n)] : "nodes[" + std::to_string(n) + "]";
    j += (first ? "" : ", ") + json_string(std::to_string(n + 1)) + ": " + json_string(name);
    first = false;
  }
  j += "}, \"material\": {";
  for (size_t m = 0; m < scene.materials.size(); ++m)
    j += (m ? ", " : "") + json_string(std::to_string(m + 1)) + ": " + json_string(scene.materials[m].name);
  return j + "}}";
}

/// OpenEXR's standard camera attributes (row vectors, p' = p M; camera space looks down -Z):
/// worldToCamera, and worldToNDC mapping the image to x, y in [-1, 1] (y up) after the
/// homogeneous divide, as Nuke reads them; plus the field of view and clip distances.
void add_camera_metadata(ExrOptions& exr, const Camera& cam, int width, int height) {
  const Vec3f u = cam.u, v = cam.v, w = cam.w, e = cam.eye;
  const std::array<float, 16> w2c = {u.x, v.x, w.x, 0, u.y, v.y, w.y, 0, u.z, v.z, w.z, 0,
                                     -dot(e, u), -dot(e, v), -dot(e, w), 1};
  const float aspect = float(width) / float(height);
  std::array<float, 16> proj{};  // camera space -> clip space (row vectors)
  if (cam.projection == Projection::Perspective) {
    const float ty = std::tan(0.5f * cam.yfov), tx = ty * aspect;
    proj = {1 / tx, 0, 0, 0, 0, 1 / ty, 0, 0, 0, 0, -1, -1, 0, 0, 0, 0};
  } else {
    proj = {1 / (cam.ymag * aspect), 0, 0, 0, 0, 1 / cam.ymag, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1};
  }
  std::array<float, 16> w2ndc{};
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 4; ++k) w2ndc[size_t(r * 4 + c)] += w2c[size_t(r * 4 + k)] * proj[size_t(k * 4 + c)];
  exr.matrix_metadata.push_back({"worldToCamera", w2c});
  exr.matrix_metadata.push_back({"worldToNDC", w2ndc});
  if (cam.projection == Projection::Perspective) {
    exr.float_metadata.push_back({"penumbra:yfov_degrees", cam.yfov * 180 / kPi});
    exr.float_metadata.push_back({"penumbra:xfov_degrees", 2 * std::atan(std::tan(0.5f * cam.yfov) * aspect) * 180 / kPi});
  }
  exr.float_metadata.push_back({"penumbra:near", cam.znear});
  exr.float_metadata.push_back({"penumbra:far", std::isfinite(cam.zfar) ? cam.zfar : std::numeric_limits<float>::max()});
}

LoadedScene load_scene(const std::string& file, int scene, bool allow_external, bool flatten,
                       const std::string& max_memory, bool quiet, std::optional<double> time = {}) {
  GltfLoadOptions opt;
  opt.time = time;
  opt.flatten = flatten;
  opt.scene = scene;
  opt.allow_external_uris = allow_external;
  opt.max_memory_bytes = max_memory.empty() ? default_memory_budget() : parse_bytes(max_memory);
  LoadedScene loaded = load_gltf(file, opt);
  if (!quiet) {
    const size_t shown = std::min<size_t>(loaded.warnings.size(), 20);
    for (size_t i = 0; i < shown; ++i) std::fprintf(stderr, "warning: %s: %s\n", file.c_str(), loaded.warnings[i].c_str());
    if (loaded.warnings.size() > shown)
      std::fprintf(stderr, "warning: %s: ... and %zu more warnings\n", file.c_str(), loaded.warnings.size() - shown);
  }
  return loaded;
}

/// --crop x0 x1 y0 y1 (integers: pixels; with a '.': fractions of the width or height; x1, y1
/// exclusive) or --tile i/N (stripe i of N equal bands of rows, top first).
PixelWindow parse_window(const RenderArgs& a, int width, int height) {
  if (!a.crop.empty() && !a.tile.empty()) throw UsageError("--crop and --tile exclude each other");
  if (!a.crop.empty()) {
    int v[4];
    for (int k = 0; k < 4; ++k) {
      const std::string& t = a.crop[size_t(k)];
      const int extent = k < 2 ? width : height;
      try {
        if (t.find('.') != std::string::npos) {
          size_t pos = 0;
          const double x = std::stod(t, &pos);
          if (pos != t.size() || !std::isfinite(x) || t.find_first_not_of("0123456789.") != std::string::npos)
            throw std::invalid_argument(t);
          if (x < 0 || x > 1) throw UsageError("--crop: fraction " + t + " is outside [0, 1]");
          v[k] = int(std::lround(x * extent));
        } else {
          v[k] = int(parse_integer(t, 0, extent, "--crop"));
        }
      } catch (const UsageError&) {
        throw;
      } catch (...) {
        throw UsageError("--crop: cannot parse '" + t + "' (expected x0 x1 y0 y1 in pixels or fractions)");
      }
    }
    const PixelWindow w{v[0], v[2], v[1], v[3]};
    if (w.empty()) throw UsageError("--crop: empty region (need x0 < x1 and y0 < y1)");
    return w;
  }
  if (!a.tile.empty()) {
    const auto [index, count] = split_pair(a.tile, '/', "--tile", "i/N with 0 <= i < N");
    const long long n = parse_integer(count, 1, 1ll << 40, "--tile N");
    if (n > height) throw UsageError("--tile: " + std::to_string(n) + " stripes exceed the " + std::to_string(height) + " rows");
    long long i = -1;
    try {
      i = parse_integer(index, 0, n - 1, "--tile i");
    } catch (const UsageError&) {
      throw UsageError("--tile: expected i/N with 0 <= i < N, got '" + a.tile + "'");
    }
    return {0, int(int64_t(i) * height / n), width, int(int64_t(i + 1) * height / n)};
  }
  return {};
}

/// Bytes an acceleration structure needs per stored triangle, for the budget before it is built
/// (Embree's and the own BVH's nodes, references and triangle copies stay below this).
constexpr uint64_t kAccelBytesPerTriangle = 96;

/// Bytes per rendered pixel of every buffer a render keeps until its outputs are written: the
/// film (RGBA float), the path tracer's accumulators and statistics, light groups (double sums
/// and float means), data AOVs (14 floats), cost AOVs (3 floats), the EXR's packed channels
/// (4 bytes each) and the display image (float RGB and its encoding).
uint64_t image_bytes_per_pixel(bool path, bool data_aovs, bool light_groups, bool cost, bool display, size_t aov_count) {
  uint64_t b = 16;
  if (path) b += sizeof(PathAccumulators::Pixel) + 4 + 4;
  if (light_groups) b += 15 * 8 + 15 * 4;
  if (data_aovs) b += 14 * 4;
  if (cost) b += 3 * 4 + 3;
  b += (4 + (data_aovs ? 14 : 0) + (light_groups ? 15 : 0) + (cost ? 3 : 0) + (aov_count ? 2 : 0)) * 4;
  if (display) b += 12 + 3;
  return b;
}

/// A float as text that reads back to the same value.
std::string exact(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// Everything that decides the pixels of a render except its window and sample target, in
/// canonical form: what the scene is (its content hash, scene index, camera, pose), the image
/// size and every sampling and integrator setting. Resume state adds the window; tiles add the
/// sample target and the layers.
RenderSettings pixel_settings(const RenderArgs& a, const RenderConfig& cfg, const Camera& camera,
                              const std::string& scene_sha256, const std::string& env_sha256) {
  std::map<std::string, std::string> e;
  e["scene.sha256"] = scene_sha256;
  e["scene.index"] = std::to_string(a.scene);
  e["scene.flatten"] = a.flatten ? "1" : "0";
  e["scene.time"] = a.time ? exact(*a.time) : (a.frame ? "frame " + *a.frame + " at " + exact(a.fps) + " fps" : "static");
  e["camera"] = a.camera.empty() ? "default '" + camera.name + "'" : a.camera;
  e["image"] = std::to_string(cfg.width) + "x" + std::to_string(cfg.height);
  e["integrator"] = a.integrator;
  e["seed"] = std::to_string(cfg.seed);
  e["filter"] = std::string(filter_name(cfg.filter.type)) + " " + exact(cfg.filter.width);
  e["accel"] = a.accel;
  for (const auto& p : a.accel_params) e["accel." + p.substr(0, p.find('='))] = p.substr(p.find('=') + 1);
  if (a.integrator == "path") {
    const auto& p = cfg.path;
    e["path.sampler"] = a.sampler;
    e["path.max_depth"] = std::to_string(p.max_depth);
    e["path.rr_depth"] = std::to_string(p.rr_depth);
    e["path.clamp_indirect"] = exact(p.clamp_indirect);
    e["path.light_sampling"] = a.light_sampling;
    e["path.adaptive"] = exact(cfg.adaptive_threshold) + " min " + std::to_string(cfg.adaptive_min_spp);
    e["path.light_groups"] = cfg.light_groups ? "1" : "0";
    e["env"] = a.env.empty() ? "none" : a.env;
    if (!env_sha256.empty()) e["env.sha256"] = env_sha256;
    e["env.intensity"] = exact(a.env_intensity);
    e["env.rotation"] = exact(a.env_rotation);
  } else {
    const auto& w = cfg.whitted;
    e["whitted.max_depth"] = std::to_string(w.max_depth);
    e["whitted.background"] = exact(w.background.x) + "," + exact(w.background.y) + "," + exact(w.background.z);
    e["whitted.ambient"] = exact(w.ambient.x) + "," + exact(w.ambient.y) + "," + exact(w.ambient.z);
  }
  return {e};
}

int run_render(const RenderArgs& a) {
  // Validate everything the user typed before spending time on loading.
  fs::path out(a.output);
  std::string ext = out.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".exr") throw UsageError("-o " + a.output + ": the output must be an .exr file");
  // Each output's folder must exist and its target must be replaceable or streamable.
  auto check_dir = [](const fs::path& p, const char* opt) { resolve_output(p, opt); };
  check_dir(out, "-o");
  if (!a.stats_json.empty()) check_dir(fs::path(a.stats_json), "--stats-json");
  std::optional<fs::path> png;
  if (!a.no_png) png = a.png.empty() ? fs::path(out).replace_extension(".png") : fs::path(a.png);
  DisplayOptions display;
  display.ocio_config = a.ocio_config;
  display.display = a.display;
  display.view = a.view;
  display.look = a.look;
  display.exposure = a.exposure;
  if (png) {
    check_dir(*png, "--png");
    check_display_output(*png, display);  // a typo must not cost a whole render
  }
  if (!std::isfinite(a.exposure) || std::fabs(a.exposure) > 64) throw UsageError("--exposure must be finite and within [-64, 64]");
  const Vec3f background = parse_colour(a.background, "--background");
  const Vec3f ambient = parse_colour(a.ambient, "--ambient");
  const bool path = a.integrator == "path";
  if (path && (a.background_given || a.ambient_given))
    throw UsageError(std::string(a.background_given ? "--background" : "--ambient") +
                     " applies to --integrator whitted; the path tracer is lit by the scene's lights and --env");
  if (!path) {
    for (const auto& [given, name] : {std::pair{!a.env.empty(), "--env"}, {a.time_limit > 0, "--time-limit"},
                                      {a.adaptive > 0, "--adaptive"}, {a.clamp_indirect > 0, "--clamp-indirect"},
                                      {a.light_sampling != "mis", "--light-sampling"}, {a.sampler != "sobol", "--sampler"},
                                      {a.checkpoint > 0, "--checkpoint"}, {a.resume, "--resume"}})
      if (given) throw UsageError(std::string(name) + " needs --integrator path");
  }
  if (!std::isfinite(a.clamp_indirect) || a.clamp_indirect < 0) throw UsageError("--clamp-indirect must be finite and >= 0 (0 = off)");
  if (!std::isfinite(a.adaptive) || a.adaptive < 0) throw UsageError("--adaptive must be finite and >= 0 (0 = off)");
  if (!std::isfinite(a.time_limit) || a.time_limit < 0) throw UsageError("--time-limit must be a finite number of seconds >= 0");
  if (!std::isfinite(a.checkpoint) || a.checkpoint < 0) throw UsageError("--checkpoint must be a finite number of seconds >= 0");
  if (!std::isfinite(a.env_intensity) || a.env_intensity < 0) throw UsageError("--env-intensity must be finite and >= 0");
  if (!std::isfinite(a.env_rotation)) throw UsageError("--env-rotation must be finite");
  FilterType filter_type = path ? FilterType::BlackmanHarris : FilterType::Box;
  if (!a.filter.empty() && !parse_filter_type(a.filter, filter_type))
    throw UsageError("--filter: unknown filter '" + a.filter + "' (known: box, tent, gaussian, blackman-harris)");
  const float filter_width = a.filter_width > 0 ? a.filter_width : default_filter_width(filter_type);
  if (!std::isfinite(a.filter_width) || a.filter_width < 0 || filter_width > 16)
    throw UsageError("--filter-width must be in (0, 16] pixels");
  // --env: a colour ("r,g,b" or one value) or an image file.
  std::optional<Vec3f> env_colour;
  if (!a.env.empty() && a.env.find_first_not_of("0123456789.,eE+- ") == std::string::npos) env_colour = parse_colour(a.env, "--env");
  int debug_x = -1, debug_y = -1;
  if (!a.debug_pixel.empty()) {
    const auto [x, y] = split_pair(a.debug_pixel, ',', "--debug-pixel", "x,y");
    debug_x = int(parse_integer(x, INT_MIN, INT_MAX, "--debug-pixel x"));
    debug_y = int(parse_integer(y, INT_MIN, INT_MAX, "--debug-pixel y"));
  }
  const AccelConfig accel_config = parse_accel(a.accel, a.accel_params);
  uint64_t seed = 0;
  if (const auto r = std::from_chars(a.seed.data(), a.seed.data() + a.seed.size(), seed);
      a.seed.empty() || a.seed[0] == '-' || a.seed[0] == '+' || r.ec != std::errc() || r.ptr != a.seed.data() + a.seed.size())
    throw UsageError("--seed: '" + a.seed + "' is not an integer in [0, 2^64 - 1]");
  // --aov NAME[,NAME...] (repeatable); "all" = every compositing AOV of the integrator.
  std::set<std::string> aovs;
  for (const auto& item : a.aovs) {
    std::stringstream ss(item);
    std::string name;
    while (std::getline(ss, name, ',')) {
      if (name == "all") {
        aovs.insert({"albedo", "N", "P", "Z", "UV", "id"});
        if (path) aovs.insert({"samples", "variance", "light"});
        continue;
      }
      if (std::find(std::begin(kAovNames), std::end(kAovNames), name) == std::end(kAovNames)) {
        std::string known;
        for (const char* k : kAovNames) known += (known.empty() ? "" : ", ") + std::string(k);
        throw UsageError("--aov: unknown AOV '" + name + "' (known: " + known + ", all)");
      }
      if (!path && (name == "samples" || name == "variance" || name == "light"))
        throw UsageError("--aov " + name + " needs --integrator path");
      aovs.insert(name);
    }
  }
  const bool cost_aov = aovs.count("cost") > 0;
  const bool data_aovs = aovs.count("albedo") || aovs.count("N") || aovs.count("P") || aovs.count("Z") || aovs.count("UV") || aovs.count("id");
  std::optional<fs::path> cost_png;
  if (cost_aov) {
    if (!a.no_png) {
      cost_png = a.cost_png.empty() ? fs::path(out).replace_extension(".cost.png") : fs::path(a.cost_png);
      check_dir(*cost_png, "--cost-png");
      check_display_output(*cost_png, display);
    }
  } else if (!a.cost_png.empty()) {
    throw UsageError("--cost-png needs --aov cost");
  }

  // No two outputs may be one file, and no output may be a file this run reads.
  const bool out_streams = resolve_output(out, "-o").kind == OutputKind::Stream;
  if (out_streams && (a.checkpoint > 0 || a.resume))
    throw UsageError("--checkpoint and --resume keep their state beside -o, which must then be a regular file");
  std::vector<std::pair<std::string, fs::path>> outputs = {{"-o", out}};
  if (path && !out_streams) outputs.push_back({"the resume state", fs::path(out).concat(".resume")});
  if (png) outputs.push_back({"--png", *png});
  if (cost_png) outputs.push_back({"--cost-png", *cost_png});
  if (!a.stats_json.empty()) outputs.push_back({"--stats-json", a.stats_json});
  std::vector<std::pair<std::string, fs::path>> inputs = {{"the scene file", a.scene_file}};
  if (!a.env.empty() && !env_colour) inputs.push_back({"--env", a.env});
  if (!a.ocio_config.empty()) inputs.push_back({"--ocio-config", a.ocio_config});
  else if (const char* ocio = std::getenv("OCIO"); ocio && *ocio) inputs.push_back({"$OCIO", ocio});
  check_distinct_files(outputs, inputs);
  bool paths_to_stdout = true;  // stdout carries the paths written, unless an output streams there
  struct stat stdout_stat {};
  if (::fstat(STDOUT_FILENO, &stdout_stat) == 0)
    for (const auto& [option, file] : outputs) {
      const OutputTarget t = resolve_output(file, option);
      if (t.kind == OutputKind::Stream && t.device == stdout_stat.st_dev && t.inode == stdout_stat.st_ino)
        paths_to_stdout = false;
    }

  std::optional<double> time = a.time;
  if (time && !std::isfinite(*time)) throw UsageError("--time must be a finite number of seconds");
  if (!(std::isfinite(a.fps) && a.fps > 0)) throw UsageError("--fps must be a finite number > 0");
  if (a.frame) time = double(parse_integer(*a.frame, -(1ll << 40), 1ll << 40, "--frame")) / a.fps;

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  // Load.
  g_phase = "loading the scene";
  const auto t_load = Clock::now();
  LoadedScene loaded = load_scene(a.scene_file, a.scene, a.allow_external, a.flatten, a.max_memory, a.quiet, time);
  Scene& scene = loaded.scene;
  const std::vector<fs::path> scene_files = {a.scene_file};
  const double load_s = seconds_since(t_load);

  // Camera and resolution (the image aspect follows the camera's hint unless both are given).
  const int cam_index = a.camera.empty() ? (scene.cameras.empty() ? -1 : 0) : find_camera(scene, a.camera, a.scene_file);
  const float hint = cam_index >= 0 && scene.cameras[size_t(cam_index)].aspect > 0 ? scene.cameras[size_t(cam_index)].aspect : 16.0f / 9.0f;
  RenderConfig cfg;
  cfg.width = a.width;
  cfg.height = a.height;
  if (!cfg.width && !cfg.height) cfg.width = 960;
  if (!cfg.height) cfg.height = std::max(1, int(std::lround(cfg.width / hint)));
  if (!cfg.width) cfg.width = std::max(1, int(std::lround(cfg.height * hint)));
  if (cfg.width > 16384 || cfg.height > 16384)
    throw UsageError("image size " + std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " exceeds 16384 per side");
  cfg.window = parse_window(a, cfg.width, cfg.height);
  const uint64_t budget = a.max_memory.empty() ? default_memory_budget() : parse_bytes(a.max_memory);
  uint64_t committed = 0;  // bytes of the budget the scene and the image buffers take
  {
    // The image buffers of this run, charged with the scene to the one budget before any is made.
    const PixelWindow w = render_window(cfg);
    const uint64_t pixels = uint64_t(w.width()) * uint64_t(w.height());
    const uint64_t image = pixels * image_bytes_per_pixel(path, data_aovs, aovs.count("light") > 0, cost_aov,
                                                          png.has_value(), aovs.size());
    const uint64_t scene_bytes = scene_memory_bytes(scene) + count_stored_triangles(scene) * kAccelBytesPerTriangle;
    if (image > budget || scene_bytes > budget - image)
      throw UsageError("image " + std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " (" + a.integrator +
                       (aovs.empty() ? "" : ", with AOVs") + ") needs " + format_bytes(image) +
                       " for the film and output buffers, over the " + format_bytes(budget) +
                       " budget with the rest of the scene (" + format_bytes(scene_bytes) + ") (--max-memory)");
    committed = image + scene_bytes;
  }
  if (!cfg.window.empty() && cost_aov) throw UsageError("--aov cost renders the whole frame; not with --crop or --tile");
  const Camera camera = cam_index >= 0 ? scene.cameras[size_t(cam_index)]
                                       : frame_bounds(compute_bounds(scene), float(cfg.width) / float(cfg.height));
  // The path tracer's lights: emissive triangles and the environment.
  Environment environment;
  if (env_colour) environment = make_constant_environment(*env_colour * a.env_intensity);
  else if (!a.env.empty()) environment = load_environment(a.env, a.env_intensity, a.env_rotation, budget - committed);
  AreaLights area_lights;
  if (path) area_lights = build_area_lights(scene);
  bool default_light = false;
  if (scene.lights.empty() && (!path || (area_lights.pmf.empty() && is_black(environment)))) {
    scene.lights.push_back(default_key_light(camera));
    default_light = true;
  }
  cfg.spp = a.spp_given ? a.spp : (path ? 64 : 4);
  cfg.threads = a.threads;
  cfg.seed = seed;
  cfg.filter = make_filter(filter_type, filter_width);
  cfg.whitted.max_depth = a.depth_given ? a.max_depth : 5;
  cfg.whitted.background = background;
  cfg.whitted.ambient = ambient;
  cfg.path.max_depth = a.depth_given ? a.max_depth : 12;
  cfg.path.rr_depth = a.rr_depth;
  cfg.path.clamp_indirect = a.clamp_indirect;
  cfg.path.strategy = a.light_sampling == "bsdf" ? LightStrategy::Bsdf : (a.light_sampling == "light" ? LightStrategy::Light : LightStrategy::Mis);
  cfg.sampler = a.sampler == "independent" ? SamplerType::Independent : SamplerType::Sobol;
  cfg.time_limit = a.time_limit;
  cfg.adaptive_threshold = a.adaptive;
  cfg.adaptive_min_spp = a.adaptive_min_spp;
  cfg.light_groups = aovs.count("light") > 0;
  const PathLights path_lights{&area_lights, &environment};
  // What this render is, for its resume state and the metadata of crops and tiles: the content
  // of every file it loaded and every setting that decides its pixels.
  RenderSettings settings;
  std::string scene_sha;
  if (path || !cfg.window.empty()) {
    scene_sha = sha256_of_files(scene_files);
    settings = pixel_settings(a, cfg, camera, scene_sha, !a.env.empty() && !env_colour ? sha256_file(a.env) : "");
  }

  // Build.
  g_phase = "building the acceleration structure";
  const auto t_build = Clock::now();
  auto accel = make_scene_accelerator(a.accel, scene, accel_config);
  const double build_s = seconds_since(t_build);

  if (!a.debug_pixel.empty()) {
    if (debug_x < 0 || debug_y < 0 || debug_x >= cfg.width || debug_y >= cfg.height)
      throw UsageError("--debug-pixel " + a.debug_pixel + " is outside the " + std::to_string(cfg.width) + "x" + std::to_string(cfg.height) + " image");
    float rgba[4];
    RayCounts counts;
    if (path) render_path_pixel(scene, *accel, path_lights, camera, cfg, debug_x, debug_y, rgba, counts);
    else render_whitted_pixel(scene, *accel, camera, cfg, debug_x, debug_y, rgba, counts);
    std::printf("pixel %d,%d: R %.6g G %.6g B %.6g A %.6g (rays: camera %llu, shadow %llu, %s %llu)\n", debug_x, debug_y,
                rgba[0], rgba[1], rgba[2], rgba[3], static_cast<unsigned long long>(counts.camera),
                static_cast<unsigned long long>(counts.shadow), path ? "bounce" : "reflection",
                static_cast<unsigned long long>(counts.reflection));
    return kExitOk;
  }

  // Render.
  g_phase = "rendering";
  ProgressReporter reporter(!a.quiet);
  RenderStats stats;
  Film film;
  PathImage path_image;
  int interrupted = 0;
  bool frame_complete = true;
  if (path) {
    // Resume state beside the output; its header records what determines the pixels.
    const fs::path state_file = fs::path(out).concat(".resume");
    RenderSettings fingerprint = settings;
    const PixelWindow win = render_window(cfg);
    fingerprint.entries["window"] = std::to_string(win.x0) + "," + std::to_string(win.y0) + "-" +
                                    std::to_string(win.x1) + "," + std::to_string(win.y1);
    PathAccumulators state;
    if (a.resume) {
      if (fs::exists(state_file)) {
        state = read_checkpoint(state_file, fingerprint);
        if (!a.quiet)
          std::fprintf(stderr, "resuming %s: %d passes done, %u spp reached\n", state_file.string().c_str(), state.passes, state.reached);
      } else if (!a.quiet) {
        std::fprintf(stderr, "no checkpoint at %s: starting from the beginning\n", state_file.string().c_str());
      }
    }
    auto last_checkpoint = Clock::now();
    const PassFn after_pass = [&](const PathAccumulators& st) {
      if (!(a.checkpoint > 0) || st.complete || seconds_since(last_checkpoint) < a.checkpoint) return;
      ExrOptions cp;
      cp.half = !a.use_float;
      cp.compression = a.compression;
      cp.metadata = {{"penumbra:scene", a.scene_file}, {"penumbra:checkpoint", "passes " + std::to_string(st.passes)}};
      write_exr(resolve_path_image(st, cfg).film, out, cp);
      write_checkpoint(state_file, st, fingerprint);
      last_checkpoint = Clock::now();
    };
    cfg.stop = &g_stop;
    g_graceful = true;
    path_image = render_path(scene, *accel, path_lights, camera, cfg, &stats, [&](int d, int t) { reporter(d, t); },
                             &state, after_pass);
    g_graceful = false;
    film = std::move(path_image.film);
    // A signal during the last pass still ends the run with 128 + signal, the image complete.
    if (g_stop.load()) interrupted = g_signal.load();
    frame_complete = state.complete;
    if (out_streams) {
      // No resume state beside a stream.
    } else if (interrupted && !state.complete) {
      write_checkpoint(state_file, state, fingerprint);
    } else if (state.complete && fs::exists(state_file)) {
      fs::remove(state_file);
    } else if (!state.complete && (a.checkpoint > 0 || a.resume)) {
      write_checkpoint(state_file, state, fingerprint);  // stopped by --time-limit: resumable too
    }
  } else {
    film = render_whitted(scene, *accel, camera, cfg, &stats, [&](int d, int t) { reporter(d, t); });
  }
  reporter.finish();
  const double mean_spp = double(stats.samples) / (double(film.width) * double(film.height));

  // Write.
  const auto t_write = Clock::now();
  ExrOptions exr;
  exr.half = !a.use_float;
  exr.compression = a.compression;
  exr.multipart = a.multipart;
  exr.metadata = {{"penumbra:scene", a.scene_file}, {"penumbra:camera", camera.name},
                  {"penumbra:spp", std::to_string(cfg.spp)}, {"penumbra:integrator", a.integrator},
                  {"penumbra:filter", std::string(filter_name(cfg.filter.type)) + " " + std::to_string(cfg.filter.width)}};
  if (path) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f", mean_spp);
    exr.metadata.push_back({"penumbra:mean_spp", buf});
    exr.metadata.push_back({"penumbra:passes", std::to_string(stats.passes)});
  }
  if (!cfg.window.empty()) {  // merge accepts only parts of one render
    RenderSettings part = settings;
    part.entries["spp"] = std::to_string(cfg.spp);
    std::string layers;
    for (const auto& name : aovs) layers += (layers.empty() ? "" : ",") + name;
    part.entries["aovs"] = layers;
    exr.metadata.push_back({kSceneHashAttribute, scene_sha});
    exr.metadata.push_back({kSettingsAttribute, canonical_text(part)});
  }
  exr.metadata.push_back({"penumbra:command_line", a.command_line});
  exr.metadata.push_back({"penumbra:version", PENUMBRA_VERSION});
  add_camera_metadata(exr, camera, cfg.width, cfg.height);
  exr.float_metadata.push_back({"penumbra:render_seconds", float(stats.seconds)});
  DataAovs data;
  std::vector<float> samples_f;
  if (data_aovs) {
    data = render_data_aovs(scene, *accel, camera, cfg, path ? IntegratorType::Path : IntegratorType::Whitted);
    const ChannelType colour = a.use_float ? ChannelType::Float : ChannelType::Half;
    if (aovs.count("albedo"))
      for (int c = 0; c < 3; ++c) exr.extra.push_back({std::string("albedo.") + "RGB"[c], &data.albedo, colour, 3, c});
    if (aovs.count("N"))
      for (int c = 0; c < 3; ++c) exr.extra.push_back({std::string("N.") + "XYZ"[c], &data.normal, ChannelType::Float, 3, c});
    if (aovs.count("P"))
      for (int c = 0; c < 3; ++c) exr.extra.push_back({std::string("P.") + "XYZ"[c], &data.position, ChannelType::Float, 3, c});
    if (aovs.count("Z")) exr.extra.push_back({"Z", &data.depth, ChannelType::Float});
    if (aovs.count("UV"))
      for (int c = 0; c < 2; ++c) exr.extra.push_back({std::string("UV.") + "UV"[c], &data.uv, ChannelType::Float, 2, c});
    if (aovs.count("id")) {
      exr.extra.push_back({"id.object", &data.object_id, ChannelType::Uint});
      exr.extra.push_back({"id.material", &data.material_id, ChannelType::Uint});
      exr.metadata.push_back({"penumbra:manifest", id_manifest(scene, loaded.info)});
    }
  }
  if (aovs.count("samples")) {
    samples_f.assign(path_image.samples.begin(), path_image.samples.end());
    exr.extra.push_back({"samples", &samples_f, ChannelType::Uint});
  }
  if (aovs.count("variance")) exr.extra.push_back({"variance", &path_image.variance, ChannelType::Float});
  if (aovs.count("light"))
    for (int g = 0; g < 5; ++g)
      for (int c = 0; c < 3; ++c)
        exr.extra.push_back({std::string(kLightGroupNames[g]) + "." + "RGB"[c], &path_image.groups,
                             a.use_float ? ChannelType::Float : ChannelType::Half, 15, g * 3 + c});
  CostImage cost;
  if (cost_aov) {
    cost = render_cost(*accel, camera, cfg, path ? IntegratorType::Path : IntegratorType::Whitted);
    if (cost.counted) {
      exr.extra.push_back({"cost.nodes", &cost.nodes});
      exr.extra.push_back({"cost.triangles", &cost.triangles});
    }
    exr.extra.push_back({"cost.ns", &cost.nanoseconds});
  }
  g_phase = "writing the outputs";
  const bool hashes = !a.stats_json.empty();  // the stats record what they were written with
  std::string exr_sha, png_sha, cost_sha;
  write_exr(film, out, exr, hashes ? &exr_sha : nullptr);
  if (png) write_display_image(film, *png, display, hashes ? &png_sha : nullptr);
  if (cost_png)
    write_heatmap(total_cost(cost), cfg.width, cfg.height, *cost_png, cost_caption(cost, a.accel),
                  hashes ? &cost_sha : nullptr);
  const double write_s = seconds_since(t_write);
  if (!a.stats_json.empty()) {
    nlohmann::ordered_json j;
    j["version"] = PENUMBRA_VERSION;
    j["scene"] = a.scene_file;
    j["output"] = out.string();
    // The SHA-256 of each image as this run wrote it: a reader can tell whether the files now
    // at these paths are the ones these statistics describe.
    j["outputs"]["exr"] = {{"path", out.string()}, {"sha256", exr_sha}};
    if (png) j["outputs"]["png"] = {{"path", png->string()}, {"sha256", png_sha}};
    if (cost_png) j["outputs"]["cost_png"] = {{"path", cost_png->string()}, {"sha256", cost_sha}};
    j["integrator"] = a.integrator;
    j["width"] = cfg.width;
    j["height"] = cfg.height;
    j["window"] = {film.origin_x, film.origin_y, film.origin_x + film.width, film.origin_y + film.height};
    j["spp"] = cfg.spp;
    j["mean_spp"] = mean_spp;
    j["passes"] = stats.passes;
    j["time_limited"] = stats.time_limited;
    j["interrupted"] = interrupted != 0;
    j["threads"] = stats.threads;
    j["accelerator"] = a.accel;
    j["seconds"] = {{"load", load_s}, {"build", build_s}, {"render", stats.seconds}, {"write", write_s}};
    j["rays"] = {{"camera", stats.rays.camera},
                 {"shadow", stats.rays.shadow},
                 {path ? "bounce" : "reflection", stats.rays.reflection},
                 {"total", stats.rays.total()}};
    j["mrays_per_second"] = stats.seconds > 0 ? double(stats.rays.total()) / stats.seconds / 1e6 : 0.0;
    j["peak_memory_mib"] = peak_memory_mib();
    j["triangles"] = count_triangles(scene);
    j["instances"] = scene.instances.size();
    j["lights"] = scene.lights.size();
    const std::string text = j.dump(2) + "\n";
    write_atomically(a.stats_json,
                     [&](const fs::path& temp) { write_file_checked(temp, text.data(), text.size(), a.stats_json); });
  }

  if (!a.quiet) {
    const uint64_t total = stats.rays.total();
    char spp_buf[160];
    if (path)
      std::snprintf(spp_buf, sizeof spp_buf, "%d spp max, %.2f mean in %d passes%s (sampler %s%s)", cfg.spp, mean_spp,
                    stats.passes, stats.time_limited ? ", stopped by --time-limit" : "", a.sampler.c_str(),
                    cfg.adaptive_threshold > 0 ? ", adaptive" : "");
    else
      std::snprintf(spp_buf, sizeof spp_buf, "%d spp", cfg.spp);
    const std::string spp_text = spp_buf;
    std::fprintf(stderr,
                 "penumbra render %s\n"
                 "  scene    %zu meshes in %zu instances, %s triangles (%s stored), %zu materials, %zu lights%s\n"
                 "  camera   %s (%s)\n"
                 "  image    %dx%d, %s, %s max-depth %d, filter %s %.3g px, %d threads, accel %s\n"
                 "  time     load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
                 "  rays     camera %s  shadow %s  %s %s  total %s  (%.2f Mrays/s)\n"
                 "  memory   peak %.1f MiB\n",
                 a.scene_file.c_str(), scene.meshes.size(), scene.instances.size(), human_count(count_triangles(scene)).c_str(),
                 human_count(count_stored_triangles(scene)).c_str(),
                 scene.materials.size(), scene.lights.size(), default_light ? " (default key light)" : "",
                 camera.name.c_str(), camera.projection == Projection::Perspective ? "perspective" : "orthographic",
                 cfg.width, cfg.height, spp_text.c_str(), a.integrator.c_str(),
                 path ? cfg.path.max_depth : cfg.whitted.max_depth, filter_name(cfg.filter.type), double(cfg.filter.width),
                 stats.threads, a.accel.c_str(),
                 load_s, build_s, stats.seconds, write_s, human_count(stats.rays.camera).c_str(),
                 human_count(stats.rays.shadow).c_str(), path ? "bounce" : "reflection", human_count(stats.rays.reflection).c_str(),
                 human_count(total).c_str(), stats.seconds > 0 ? double(total) / stats.seconds / 1e6 : 0.0,
                 peak_memory_mib());
  }
  if (paths_to_stdout) {
    std::printf("%s\n", out.string().c_str());
    if (png) std::printf("%s\n", png->string().c_str());
    if (cost_png) std::printf("%s\n", cost_png->string().c_str());
  }
  if (interrupted) {
    if (frame_complete)
      std::fprintf(stderr, "penumbra: interrupted by signal %d during the last pass: the image is complete\n", interrupted);
    else
      std::fprintf(stderr, "penumbra: interrupted by signal %d after %d passes (%.2f spp): the image holds the finished passes; "
                           "continue with the same command and --resume\n", interrupted, stats.passes, mean_spp);
    return 128 + interrupted;
  }
  return kExitOk;
}

int run_info(const std::string& file, int scene_index, bool allow_external, bool flatten, const std::string& accel_name,
             const std::vector<std::string>& accel_params) {
  const AccelConfig accel_config = parse_accel(accel_name, accel_params);
  LoadedScene loaded = load_scene(file, scene_index, allow_external, flatten, "", false);
  const Scene& s = loaded.scene;
  const GltfInfo& i = loaded.info;
  std::printf("file         %s\n", file.c_str());
  std::printf("asset        glTF %s%s%s\n", i.version.c_str(), i.generator.empty() ? "" : ", generator: ", i.generator.c_str());
  std::printf("scenes       %d", i.scene_count);
  for (int k = 0; k < i.scene_count; ++k)
    std::printf("%s%d: %s%s", k ? ", " : " (", k, i.scene_names[size_t(k)].c_str(), k == i.scene_index ? " [rendered]" : "");
  std::printf("%s\n", i.scene_count ? ")" : "");
  std::printf("nodes        %d\n", i.node_count);
  std::printf("meshes       %d (%d primitives); stored: %zu triangle meshes, %llu triangles\n", i.mesh_count,
              i.primitive_count, s.meshes.size(), static_cast<unsigned long long>(count_stored_triangles(s)));
  const size_t placed = size_t(std::count_if(s.instances.begin(), s.instances.end(), [](const Instance& x) { return !x.identity; }));
  std::printf("instances    %zu (%zu in world space, %zu placed by a transform), %llu triangles rendered\n",
              s.instances.size(), s.instances.size() - placed, placed, static_cast<unsigned long long>(count_triangles(s)));
  std::printf("materials    %zu\n", s.materials.size());
  for (size_t k = 0; k < s.materials.size(); ++k) {
    const auto& m = s.materials[k];
    std::printf("  [%zu] %s: base (%.3g %.3g %.3g) metallic %.3g roughness %.3g emissive (%.3g %.3g %.3g)\n", k,
                m.name.c_str(), m.base_color.x, m.base_color.y, m.base_color.z, m.metallic, m.roughness,
                m.emissive.x, m.emissive.y, m.emissive.z);
  }
  std::printf("cameras      %d defined, %zu in the scene (use --camera N or NAME)\n", i.gltf_camera_count, i.camera_instances.size());
  for (size_t k = 0; k < i.camera_instances.size(); ++k) std::printf("  [%zu] %s\n", k, i.camera_instances[k].c_str());
  std::printf("lights       %d defined, %zu in the scene\n", i.gltf_light_count, s.lights.size());
  for (size_t k = 0; k < s.lights.size(); ++k) {
    const auto& l = s.lights[k];
    const char* type = l.type == LightType::Point ? "point" : (l.type == LightType::Spot ? "spot" : "directional");
    std::printf("  [%zu] %s: %s, intensity %.4g %s\n", k, l.name.c_str(), type, l.intensity,
                l.type == LightType::Directional ? "lux" : "cd");
  }
  std::printf("images       %d, %zu textures decoded\n", i.image_count, s.textures.size());
  std::printf("animations   %d\n", i.animation_count);
  auto join = [](const std::vector<std::string>& v) {
    std::string r;
    for (const auto& x : v) r += (r.empty() ? "" : ", ") + x;
    return r.empty() ? std::string("none") : r;
  };
  std::printf("extensions   used: %s; required: %s\n", join(i.extensions_used).c_str(), join(i.extensions_required).c_str());
  const Bounds3f b = compute_bounds(s);
  if (!b.empty())
    std::printf("bounds       (%.4g, %.4g, %.4g) - (%.4g, %.4g, %.4g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
  else
    std::printf("bounds       empty\n");
  auto accel = make_scene_accelerator(accel_name, s, accel_config);
  const AccelStats st = accel->stats();
  std::printf("accelerator  %s%s%s%s\n", st.name.c_str(), st.config.empty() ? "" : " (", st.config.c_str(),
              st.config.empty() ? "" : ")");
  std::printf("  triangles  %llu\n", static_cast<unsigned long long>(st.triangles));
  if (st.instances > 0) std::printf("  instances  %llu (two levels)\n", static_cast<unsigned long long>(st.instances));
  std::printf("  build      %.3f s\n", st.build_seconds);
  std::printf("  memory     %.2f MiB\n", double(st.bytes) / (1 << 20));
  if (st.nodes > 0) {
    const bool grid = st.name == "grid";
    std::printf("  %s      %llu%s\n", grid ? "cells" : "nodes", static_cast<unsigned long long>(st.nodes),
                grid ? "" : (" (" + std::to_string(st.nodes - st.leaves) + " interior)").c_str());
    if (!grid) std::printf("  leaves     %llu\n", static_cast<unsigned long long>(st.leaves));
    std::printf("  empty      %llu %s\n", static_cast<unsigned long long>(st.empty_leaves), grid ? "cells" : "leaves");
    std::printf("  references %llu (%.2f per triangle)\n", static_cast<unsigned long long>(st.references),
                st.triangles ? double(st.references) / double(st.triangles) : 0.0);
    std::printf("  per %s   avg %.2f, max %llu triangles (non-empty)\n", grid ? "cell" : "leaf", st.avg_leaf_prims,
                static_cast<unsigned long long>(st.max_leaf_prims));
    if (!grid) std::printf("  max depth  %llu\n", static_cast<unsigned long long>(st.max_depth));
    if (st.sah_cost > 0) std::printf("  SAH cost   %.2f\n", st.sah_cost);
  } else if (st.name == "embree") {
    std::printf("  (Embree does not report its node statistics)\n");
  }
  std::printf("warnings     %zu\n", loaded.warnings.size());
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Penumbra: glTF 2.0 batch renderer (Embree + TBB, OpenEXR + OpenColorIO output)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("penumbra " PENUMBRA_VERSION));

  RenderArgs r;
  auto* render = app.add_subcommand("render", "Render a glTF scene to a scene-linear EXR and a display image");
  render->add_option("scene", r.scene_file, "glTF scene (.gltf or .glb)")->required();
  render->add_option("-o,--output", r.output, "output EXR path (written atomically)")->required();
  render->add_option("--png", r.png, "display image path (.png/.jpg/.tif); default: the EXR path with .png");
  render->add_flag("--no-png", r.no_png, "write only the EXR");
  render->add_option("--width", r.width, "image width in pixels (default 960, or from --height and the camera aspect)")->check(CLI::Range(1, 16384));
  render->add_option("--height", r.height, "image height in pixels (default: width / camera aspect)")->check(CLI::Range(1, 16384));
  render->add_option("--integrator", r.integrator, "whitted (default: the course's look, fast) or path (physically based path tracer)")
      ->check(CLI::IsMember({"whitted", "path"}));
  render->add_option("--spp", r.spp, "samples per pixel (default 4 for whitted, 64 for path; with --adaptive the maximum)")->check(CLI::Range(1, 65536));
  render->add_option("--max-depth", r.max_depth, "whitted: maximum mirror bounces (default 5); path: maximum bounces, 0 = direct light only (default 12)")->check(CLI::Range(0, 64));
  render->add_option("--rr-depth", r.rr_depth, "path: Russian roulette from this bounce on (default 3)")->check(CLI::Range(1, 64));
  render->add_option("--clamp-indirect", r.clamp_indirect, "path: clamp each indirect sample's largest channel to this radiance; biased, trades fireflies for energy (default 0 = off)");
  render->add_option("--light-sampling", r.light_sampling, "path: mis (default), bsdf (BSDF sampling only) or light (light sampling only); the single techniques are for validation")
      ->check(CLI::IsMember({"mis", "bsdf", "light"}));
  render->add_option("--sampler", r.sampler, "path: sobol (Owen-scrambled, default) or independent (PCG32)")->check(CLI::IsMember({"sobol", "independent"}));
  render->add_option("--env", r.env, "path: environment light: a radiance r,g,b or grey, or an equirectangular map (.exr, .hdr, any float image OpenImageIO reads)");
  render->add_option("--env-intensity", r.env_intensity, "path: multiplies --env (default 1)");
  render->add_option("--env-rotation", r.env_rotation, "path: turns the --env map about +Y, degrees (default 0)");
  render->add_option("--time-limit", r.time_limit, "path: stop after the pass that would run past this many seconds (default 0 = none)");
  render->add_option("--adaptive", r.adaptive, "path: adaptive sampling threshold, e.g. 0.01: a pixel stops once its error estimate is below it (default 0 = off)");
  render->add_option("--adaptive-min-spp", r.adaptive_min_spp, "path: samples every pixel takes before --adaptive may stop it (default 16)")->check(CLI::Range(2, 65536));
  render->add_option("--filter", r.filter, "pixel filter: box, tent, gaussian or blackman-harris (default: box for whitted, blackman-harris for path)");
  render->add_option("--filter-width", r.filter_width, "pixel filter width in pixels (default: box 1, tent 2, gaussian 3, blackman-harris 1.5)");
  render->add_option("--threads", r.threads, "worker threads (default 0 = all cores)")->check(CLI::Range(0, 1024));
  render->add_option("--scene", r.scene, "glTF scene index (default: the file's default scene)")->check(CLI::Range(0, 1 << 30));
  render->add_option("--camera", r.camera, "camera instance: index as listed by `penumbra info`, or name (default 0; none in the file: frame the bounds)");
  render->add_option("--accel", r.accel, "acceleration structure: embree (default), bvh, kdtree, grid or brute (a linear scan: tests only)");
  render->add_option("--accel-param", r.accel_params, accel_param_help())->type_name("KEY=VALUE");
  render->add_flag("--multipart", r.multipart, "write one EXR part per layer (rgba, albedo, N, Z, ...); lossy --compression then applies to colour parts only");
  render->add_flag("--float", r.use_float, "write 32-bit float EXR channels (default half)");
  render->add_option("--compression", r.compression, "EXR compression (default zip)")
      ->check(CLI::IsMember({"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"}));
  render->add_option("--exposure", r.exposure, "exposure in stops for the display image (default 0)");
  render->add_option("--ocio-config", r.ocio_config, "OpenColorIO config (default: $OCIO, else the shipped config)");
  render->add_option("--display", r.display, "OCIO display (default: the config's default)");
  render->add_option("--view", r.view, "OCIO view: Standard (default), Filmic (ACES 1.0 SDR tone mapping) or Raw with the shipped config");
  render->add_option("--look", r.look, "OCIO look applied before the view: High Contrast, Low Contrast, Plus 1 EV, Minus 1 EV with the shipped config");
  render->add_option("--background", r.background, "whitted: background radiance r,g,b or grey (default 0); background alpha stays 0 (path: use --env)");
  render->add_option("--ambient", r.ambient, "whitted: ambient intensity Ia, r,g,b or grey (default 0.05)");
  render->add_option("--seed", r.seed, "sampler seed (default 0)");
  auto* time_opt = render->add_option("--time", r.time, "animation time in seconds: animations (node TRS, skins, morph weights) are evaluated there (default: the file's static pose)");
  render->add_option("--frame", r.frame, "animation frame N, at time N / --fps")->excludes(time_opt);
  render->add_option("--fps", r.fps, "frames per second for --frame (default 24)");
  render->add_option("--max-memory", r.max_memory, "budget for decoded geometry, e.g. 4G (default: half the RAM)");
  render->add_flag("--allow-external-uris", r.allow_external, "let buffer URIs reach files outside the scene's folder");
  render->add_flag("--flatten", r.flatten, "give every placement of a mesh its own world-space copy instead of instancing it");
  render->add_option("--checkpoint", r.checkpoint, "path: every this many seconds (after a whole pass) write the image so far and the resume state OUT.exr.resume, atomically (default 0 = never)");
  render->add_flag("--resume", r.resume, "path: continue from OUT.exr.resume (written by --checkpoint, --time-limit or an interrupt) to the requested spp; the result equals an uninterrupted render");
  render->add_option("--stats-json", r.stats_json, "also write the run's statistics (times per phase, rays, spp, memory) as JSON to this file");
  render->add_option("--crop", r.crop, "render only x0 x1 y0 y1 (pixels, or fractions with a '.'; x1, y1 exclusive): an EXR data window inside the full frame")
      ->expected(4)->type_name("X0 X1 Y0 Y1");
  render->add_option("--tile", r.tile, "render stripe i of N (i/N, rows split evenly, 0 = top) for farms; `penumbra merge` assembles them");
  render->add_option("--debug-pixel", r.debug_pixel, "render only pixel x,y and print its value");
  render->add_flag("-q,--quiet", r.quiet, "no progress, warnings or summary on stderr");
  render->add_option("--aov", r.aovs,
                     "extra EXR layers, comma-separated or repeated: albedo, N, P, Z, UV, id (id.object, id.material + a "
                     "name manifest), and for the path tracer samples, variance, light (emission, diffuse/specular "
                     "direct/indirect); all = every one of these; cost = traversal cost of the camera rays "
                     "(cost.nodes, cost.triangles, cost.ns) and a heat map");
  render->add_option("--cost-png", r.cost_png, "heat map path for --aov cost (default: the EXR path with .cost.png)");

  std::string info_file, info_accel = "embree";
  std::vector<std::string> info_accel_params;
  int info_scene = -1;
  bool info_external = false, info_flatten = false;
  auto* info = app.add_subcommand("info", "Describe a glTF scene: scenes, meshes, materials, cameras, lights, bounds");
  info->add_option("scene", info_file, "glTF scene (.gltf or .glb)")->required();
  info->add_option("--scene", info_scene, "glTF scene index")->check(CLI::Range(0, 1 << 30));
  info->add_option("--accel", info_accel, "acceleration structure to build and describe: embree (default), bvh, kdtree, grid, brute");
  info->add_option("--accel-param", info_accel_params, accel_param_help())->type_name("KEY=VALUE");
  info->add_flag("--allow-external-uris", info_external, "let buffer URIs reach files outside the scene's folder");
  info->add_flag("--flatten", info_flatten, "as for render: no instancing");

  std::vector<std::string> merge_parts;
  std::string merge_out;
  auto* merge = app.add_subcommand("merge", "Assemble the EXRs of --crop/--tile renders into the full frame (bit for bit)");
  merge->add_option("parts", merge_parts, "part EXRs (together covering the frame once)")->required();
  merge->add_option("-o,--output", merge_out, "full-frame EXR (written atomically)")->required();
  bool merge_force = false;
  std::string merge_memory;
  merge->add_option("--max-memory", merge_memory, "budget for the decoded full frame, e.g. 4G (default: half the RAM)");
  merge->add_flag("--force", merge_force,
                  "merge parts without Penumbra's scene and settings metadata, or with differing metadata (parts "
                  "cut by other tools); the windows and channels are still checked");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitInput;
  }

  for (int i = 0; i < argc; ++i) r.command_line += (i ? " " : "") + std::string(argv[i]);
  r.spp_given = render->count("--spp") > 0;
  r.depth_given = render->count("--max-depth") > 0;
  r.background_given = render->count("--background") > 0;
  r.ambient_given = render->count("--ambient") > 0;
  try {
    if (*render) return run_render(r);
    if (*merge) {
      const fs::path merged(merge_out);
      std::string ext = merged.extension().string();
      for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
      if (ext != ".exr") throw UsageError("-o " + merge_out + ": the output must be an .exr file");
      std::vector<fs::path> parts(merge_parts.begin(), merge_parts.end());
      std::vector<std::pair<std::string, fs::path>> inputs;
      for (size_t k = 0; k < parts.size(); ++k) inputs.push_back({"part " + std::to_string(k + 1), parts[k]});
      check_distinct_files({{"-o", merged}}, inputs);
      MergeOptions merge_options;
      merge_options.force = merge_force;
      merge_options.max_memory_bytes = merge_memory.empty() ? default_memory_budget() : parse_bytes(merge_memory);
      merge_exr_parts(parts, merge_out, merge_options);
      std::printf("%s\n", merge_out.c_str());
      return kExitOk;
    }
    if (*info) return run_info(info_file, info_scene, info_external, info_flatten, info_accel, info_accel_params);
  } catch (const InputError& e) {
    std::fprintf(stderr, "penumbra: error: %s\n", e.what());
    return kExitInput;
  } catch (const UsageError& e) {
    std::fprintf(stderr, "penumbra: error: %s\n", e.what());
    return kExitInput;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "penumbra: error: %s\n", e.what());
    return kExitInput;
  } catch (const std::bad_alloc&) {
    // Outputs are written atomically: nothing half-written is left behind.
    std::fprintf(stderr, "penumbra: error: out of memory while %s; no file is left half-written (a lower "
                 "--max-memory refuses oversized inputs up front)\n", g_phase);
    return kExitInternal;
  } catch (const std::runtime_error& e) {
    // A failed write, sync or rename (full disk, permissions): the message names the file.
    std::fprintf(stderr, "penumbra: error: %s\n", e.what());
    return kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "penumbra: internal error: %s\n", e.what());
    return kExitInternal;
  }
  return kExitInternal;
}
