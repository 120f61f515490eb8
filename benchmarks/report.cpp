// penumbra-bench's table and chart from its result rows (benchmarks/report.h).
#include "benchmarks/report.h"

#include <algorithm>
#include <cstdio>

namespace penumbra::bench {

namespace {

/// `s` appended to `v` unless already there (first-appearance order).
void add_unique(std::vector<std::string>& v, const std::string& s) {
  if (std::find(v.begin(), v.end(), s) == v.end()) v.push_back(s);
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

std::string number(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string threads_title(int t) {
  return std::to_string(t) + (t == 1 ? " thread" : " threads");
}

}  // namespace

std::string format_sah(const std::optional<double>& sah) {
  return sah ? number("%.2f", *sah) : "n/a";
}

std::string sah_legend(const SahConstants& c) {
  return "SAH: expected cost of a random ray through the root box, " + number("C_T = %g", c.traversal) +
         " per node visit and " + number("C_I = %g", c.intersection) +
         " per primitive test for every structure, from the node boxes of each built tree; n/a: none under "
         "these constants (embree: nodes not accessible; grid, brute: no tree; two-level builds)\n";
}

std::string table_header(std::span<const int> threads) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-28s %-7s %-8s %9s %9s %8s %8s %9s %6s %5s %9s", "scene", "accel", "rays",
                "build ms", "MiB", "B/tri", "SAH", "count", "wrong", "ties", "evals/ray");
  std::string s = buf;
  for (int t : threads) {
    std::snprintf(buf, sizeof buf, "  %4dT Mrays/s (x Embree)", t);
    s += buf;
  }
  return s + "\n";
}

std::string table_row(const Row& r) {
  char buf[512];
  std::snprintf(buf, sizeof buf, "%-28.28s %-7s %-8s %9.2f %9.2f %8.1f %8s %9llu %6llu %5llu",
                r.scene.c_str(), r.accel.c_str(), r.kind.c_str(), r.build_s.median * 1e3,
                double(r.bytes) / (1 << 20), r.triangles ? double(r.bytes) / double(r.triangles) : 0.0,
                format_sah(r.sah).c_str(), static_cast<unsigned long long>(r.rays),
                static_cast<unsigned long long>(r.mismatches), static_cast<unsigned long long>(r.ties));
  std::string s = buf;
  if (r.evals >= 0)
    std::snprintf(buf, sizeof buf, " %9.2f", r.evals);
  else
    std::snprintf(buf, sizeof buf, " %9s", "-");
  s += buf;
  for (size_t i = 0; i < r.mrays.size(); ++i) {
    std::snprintf(buf, sizeof buf, "  %12.2f (%5.2fx)      ", r.mrays[i].mrays.median,
                  i < r.vs_embree.size() ? r.vs_embree[i] : 0.0);
    s += buf;
  }
  return s + "\n";
}

BarChart results_chart(const std::vector<Row>& rows, const RunSettings& settings) {
  BarChart chart;
  chart.title =
      "penumbra-bench: ray throughput (Mrays/s, higher is better) and build time (ms, lower is better)";
  std::vector<std::string> scenes, kinds, scene_sizes;
  for (const auto& r : rows) {
    add_unique(chart.series, r.accel);
    add_unique(kinds, r.kind);
    if (std::find(scenes.begin(), scenes.end(), r.scene) == scenes.end()) {
      scenes.push_back(r.scene);
      std::string size = std::to_string(r.triangles) + " triangles";
      if (r.shapes > 0) size += ", " + std::to_string(r.shapes) + " shapes";
      scene_sizes.push_back(r.scene + " (" + size + ")");
    }
  }
  const auto find = [&](const std::string& scene, const std::string& accel, const std::string* kind) {
    for (const auto& r : rows)
      if (r.scene == scene && r.accel == accel && (!kind || r.kind == *kind)) return &r;
    return static_cast<const Row*>(nullptr);
  };
  for (const auto& scene : scenes) {
    chart.row_labels.push_back(scene);
    std::vector<BarPanel> panels;
    for (size_t c = 0; c < settings.threads.size(); ++c) {
      BarPanel p;
      p.title = threads_title(settings.threads[c]);
      p.x_label = "ray kind";
      p.quantity = "throughput";
      p.unit = "Mrays/s";
      p.groups = kinds;
      for (const auto& kind : kinds) {
        std::vector<std::optional<Spread>> bars;
        for (const auto& accel : chart.series) {
          const Row* r = find(scene, accel, &kind);
          bars.push_back(r && c < r->mrays.size() ? std::optional<Spread>(r->mrays[c].mrays) : std::nullopt);
        }
        p.values.push_back(bars);
      }
      panels.push_back(p);
    }
    BarPanel build;
    build.title = "build, " + threads_title(settings.build_threads);
    build.x_label = "structure (as in the legend)";
    build.quantity = "build time";
    build.unit = "ms";
    build.groups = {""};
    std::vector<std::optional<Spread>> bars;
    for (const auto& accel : chart.series) {
      const Row* r = find(scene, accel, nullptr);
      if (r)
        bars.push_back(Spread{r->build_s.min * 1e3, r->build_s.median * 1e3, r->build_s.max * 1e3});
      else
        bars.push_back(std::nullopt);
    }
    build.values.push_back(bars);
    panels.push_back(build);
    chart.rows.push_back(panels);
  }
  std::vector<std::string> thread_list;
  for (int t : settings.threads) thread_list.push_back(std::to_string(t));
  chart.caption = {
      "Machine: " + settings.machine + ". Software: " + settings.software + ".",
      "Rays: " + join(kinds, ", ") + "; primary rays " + std::to_string(settings.width) + " x " +
          std::to_string(settings.height) +
          " (1 spp: one ray through each pixel centre); every structure answers the same rays, each answer "
          "checked against Embree.",
      "Bars: median of " + std::to_string(settings.repeats) +
          " timed passes after a warm-up pass (throughput, at " +
          (settings.threads.size() == 1 ? threads_title(settings.threads[0])
                                        : join(thread_list, ", ") + " threads") +
          ") and of " + std::to_string(settings.builds) + " builds on " +
          threads_title(settings.build_threads) +
          " (build time); error bars: minimum to maximum of those passes and builds.",
      "Scenes: " + join(scene_sizes, "; ") + "."};
  return chart;
}

}  // namespace penumbra::bench
