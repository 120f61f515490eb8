// Progress lines and the render summary.
#include "apps/penumbra/progress.h"

#include <unistd.h>

#include <cstdio>

#include "apps/penumbra/render_job.h"

namespace penumbra::cli {

ProgressReporter::ProgressReporter(bool enabled) : m_enabled(enabled), m_tty(isatty(STDERR_FILENO)) {}

void ProgressReporter::operator()(int done, int total) {
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
  std::fprintf(stderr, "%srender %5.1f%%  elapsed %6.1fs  eta %6.1fs%s", m_tty ? "\r" : "", 100 * frac,
               elapsed, eta, m_tty ? (done == total ? "\n" : "") : "\n");
  std::fflush(stderr);
}

void ProgressReporter::finish() {
  std::lock_guard lock(m_mutex);
  if (m_open) std::fputc('\n', stderr);
  m_open = false;
}

void print_render_summary(const RenderJob& job) {
  const RenderArgs& a = job.args;
  const RenderConfig& cfg = job.cfg;
  const RenderStats& stats = job.stats;
  const Scene& scene = job.loaded.scene;
  const bool path = job.request.path;
  const uint64_t total = stats.rays.total();
  const std::string spp_text =
      path ? format("%d spp max, %.2f mean in %d passes%s (sampler %s%s)", cfg.spp, job.mean_spp,
                    stats.passes, stats.time_limited ? ", stopped by --time-limit" : "", a.sampler.c_str(),
                    cfg.adaptive_threshold > 0 ? ", adaptive" : "")
           : format("%d spp", cfg.spp);
  const std::string shapes_text = scene.shapes.empty()
                                      ? std::string()
                                      : format(" and %zu shapes (%llu placed)", scene.shapes.size(),
                                               static_cast<unsigned long long>(count_shape_instances(scene)));
  std::fprintf(
      stderr,
      "penumbra render %s\n"
      "  scene    %zu meshes%s in %zu instances, %s triangles (%s stored), %zu materials, %zu lights%s\n"
      "  camera   %s (%s)\n"
      "  image    %dx%d, %s, %s max-depth %d, filter %s %.3g px, %d threads, accel %s\n"
      "  time     load %.3fs  build %.3fs  render %.3fs  write %.3fs\n"
      "  rays     camera %s  shadow %s  %s %s  total %s  (%.2f Mrays/s)\n"
      "  memory   peak %.1f MiB\n",
      a.scene_file.c_str(), scene.meshes.size(), shapes_text.c_str(), scene.instances.size(),
      human_count(count_triangles(scene)).c_str(), human_count(count_stored_triangles(scene)).c_str(),
      scene.materials.size(), scene.lights.size(), job.default_light ? " (default key light)" : "",
      job.camera.name.c_str(),
      job.camera.projection == Projection::Perspective ? "perspective" : "orthographic", cfg.width,
      cfg.height, spp_text.c_str(), a.integrator.c_str(), path ? cfg.path.max_depth : cfg.whitted.max_depth,
      filter_name(cfg.filter.type), double(cfg.filter.width), stats.threads, a.accel.c_str(), job.load_s,
      job.build_s, stats.seconds, job.write_s, human_count(stats.rays.camera).c_str(),
      human_count(stats.rays.shadow).c_str(), path ? "bounce" : "reflection",
      human_count(stats.rays.reflection).c_str(), human_count(total).c_str(),
      stats.seconds > 0 ? double(total) / stats.seconds / 1e6 : 0.0, peak_memory_mib());
}

}  // namespace penumbra::cli
