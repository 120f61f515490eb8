// Progress lines (text and JSON), announcements and the render summary.
#include "apps/penumbra/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "apps/penumbra/render_job.h"

namespace penumbra::cli {

namespace {

/// Seconds between two JSON progress lines of a phase (its first and last line aside).
constexpr double kJsonInterval = 0.25;

/// Seconds to the millisecond, for lines a person may read too.
double milliseconds(double s) {
  return std::round(s * 1000) / 1000;
}

void print_json_line(const nlohmann::ordered_json& j) {
  const std::string line = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::fprintf(stderr, "%s\n", line.c_str());
  std::fflush(stderr);
}

}  // namespace

const std::vector<std::string>& progress_modes() {
  static const std::vector<std::string> modes = {"auto", "text", "json", "none"};
  return modes;
}

std::string progress_option_help() {
  return "progress on stderr: auto (default: a line updated in place on a terminal, one per 10% in logs), "
         "text (one line per 10%), json (one JSON object per line for each phase: phase, fraction, elapsed, "
         "eta, frame; no summary) or none";
}

ProgressMode progress_mode(const std::string& name, bool quiet) {
  if (name == "text") return ProgressMode::Text;
  if (name == "json") return ProgressMode::Json;
  if (name == "none") return ProgressMode::None;
  if (name != "auto" && !name.empty()) throw UsageError("--progress: unknown mode '" + name + "'");
  return quiet ? ProgressMode::None : ProgressMode::Auto;
}

void announce(ProgressMode mode, const std::string& what) {
  if (mode != ProgressMode::Auto && mode != ProgressMode::Text) return;
  std::fprintf(stderr, "penumbra: %s\u2026\n", what.c_str());
  std::fflush(stderr);
}

void print_json_warnings(const std::string& file, const std::vector<std::string>& warnings) {
  const size_t shown = std::min<size_t>(warnings.size(), 20);
  for (size_t i = 0; i < shown; ++i) print_json_line({{"warning", file + ": " + warnings[i]}});
  if (warnings.size() > shown)
    print_json_line(
        {{"warning", file + ": ... and " + std::to_string(warnings.size() - shown) + " more warnings"}});
}

ProgressReporter::ProgressReporter(ProgressMode mode, const char* phase, std::optional<int64_t> frame)
    : m_mode(mode),
      m_phase(phase),
      m_frame(frame),
      m_tty(mode == ProgressMode::Auto && isatty(STDERR_FILENO)) {
  if (m_mode == ProgressMode::Json) {
    std::lock_guard lock(m_mutex);
    print_json(0, 0);
  }
}

void ProgressReporter::print_json(double fraction, double elapsed) {
  m_last_fraction = std::max(m_last_fraction, fraction);
  m_last = elapsed;
  const double f = m_last_fraction;
  nlohmann::ordered_json j;
  j["phase"] = m_phase;
  j["fraction"] = f;
  j["elapsed"] = milliseconds(elapsed);
  j["eta"] = f > 0 ? nlohmann::ordered_json(milliseconds(elapsed * (1 - f) / f)) : nlohmann::ordered_json();
  j["frame"] = m_frame ? nlohmann::ordered_json(*m_frame) : nlohmann::ordered_json();
  print_json_line(j);
  if (f >= 1) m_done = true;
}

void ProgressReporter::operator()(int done, int total) {
  if (m_mode == ProgressMode::None || total <= 0) return;
  std::lock_guard lock(m_mutex);
  const double elapsed = seconds_since(m_start);
  const double frac = std::clamp(double(done) / double(total), 0.0, 1.0);
  if (m_mode == ProgressMode::Json) {
    if (m_done || (frac < 1 && elapsed - m_last < kJsonInterval)) return;
    print_json(frac, elapsed);
    return;
  }
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
  std::fprintf(stderr, "%srender %5.1f%%  elapsed %6.1fs  eta %6.1fs%s", m_tty ? "\r" : "", 100 * frac,
               elapsed, eta, m_tty ? (done == total ? "\n" : "") : "\n");
  std::fflush(stderr);
}

void ProgressReporter::finish() {
  std::lock_guard lock(m_mutex);
  if (m_mode == ProgressMode::Json && !m_done) print_json(1, seconds_since(m_start));
  if (m_open) std::fputc('\n', stderr);
  m_open = false;
}

void print_render_summary(const RenderReport& r) {
  const RenderSpec& spec = r.prepared.spec;
  const RenderConfig& cfg = r.prepared.config;
  const RenderStats& stats = r.image.stats;
  const Scene& scene = r.scene;
  const bool path = spec.integrator == "path";
  const uint64_t total = stats.rays.total();
  const std::string spp_text =
      path ? format("%d spp max, %.2f mean in %d passes%s (sampler %s%s)", cfg.spp, r.mean_spp, stats.passes,
                    stats.time_limited ? ", stopped by --time-limit" : "", spec.sampler.c_str(),
                    cfg.adaptive_threshold > 0 ? ", adaptive" : "")
           : format("%d spp", cfg.spp);
  const std::string shapes_text = scene.shapes.empty()
                                      ? std::string()
                                      : format(" and %zu shapes (%llu placed)", scene.shapes.size(),
                                               static_cast<unsigned long long>(count_shape_instances(scene)));
  const std::string depth_text =
      spec.integrator == "raster"
          ? "shadows " + spec.raster_shadows
          : "max-depth " + std::to_string(path ? cfg.path.max_depth : cfg.whitted.max_depth);
  std::fprintf(
      stderr,
      "penumbra render %s\n"
      "  scene    %zu meshes%s in %zu instances, %s triangles (%s stored), %zu materials, %zu lights%s\n"
      "  camera   %s (%s)\n"
      "  image    %dx%d, %s, %s %s, filter %s %.3g px, %d threads, accel %s\n"
      "  time     load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
      "  rays     camera %s  shadow %s  %s %s  total %s  (%.2f Mrays/s)\n"
      "  memory   peak %.1f MiB\n",
      r.scene_file.c_str(), scene.meshes.size(), shapes_text.c_str(), scene.instances.size(),
      human_count(count_triangles(scene)).c_str(), human_count(count_stored_triangles(scene)).c_str(),
      scene.materials.size(), scene.lights.size(), r.prepared.default_light ? " (default key light)" : "",
      r.prepared.camera.name.c_str(),
      r.prepared.camera.projection == Projection::Perspective ? "perspective" : "orthographic", cfg.width,
      cfg.height, spp_text.c_str(), spec.integrator.c_str(), depth_text.c_str(), filter_name(cfg.filter.type),
      double(cfg.filter.width), stats.threads, r.traced ? spec.accel.c_str() : "none (nothing traced)",
      r.load_s, r.build_s, stats.seconds, r.write_s, human_count(stats.rays.camera).c_str(),
      human_count(stats.rays.shadow).c_str(), path ? "bounce" : "reflection",
      human_count(stats.rays.reflection).c_str(), human_count(total).c_str(),
      stats.seconds > 0 ? double(total) / stats.seconds / 1e6 : 0.0, peak_memory_mib());
}

}  // namespace penumbra::cli
