// penumbra-bench's table and chart: "n/a" in the SAH column of structures without one (measured
// on real builds), the column alignment, and the chart of result rows: one panel per thread count
// plus build time, the spreads carried over, a caption naming the machine and the settings, and
// an SVG that Python's XML parser reads back (tests/benchmarks/svg_check.py).
#include "benchmarks/report.h"

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "renderer/accel/factory.h"
#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::bench;

namespace {

/// The text of `line` under the header column that ends with `name` (right-aligned columns).
std::string column(const std::string& header, const std::string& line, const std::string& name) {
  const size_t end = header.find(" " + name + " ") + 1 + name.size();
  size_t begin = end;
  while (begin > 0 && line[begin - 1] != ' ') --begin;
  return line.substr(begin, end - begin);
}

Row make_row(const std::string& scene, const std::string& accel, const std::string& kind, double base) {
  Row r;
  r.scene = scene, r.accel = accel, r.kind = kind;
  r.triangles = 1000, r.rays = 576, r.bytes = 50000;
  r.build_s = {0.001 * base, 0.0012 * base, 0.0015 * base};
  for (int t : {1, 2}) r.mrays.push_back({t, Spread{base * t * 0.9, base * t, base * t * 1.05}});
  r.vs_embree = {1, 1};
  return r;
}

}  // namespace

TEST_CASE("table: n/a in the SAH column of structures without one", "[bench][accel]") {
  CHECK(format_sah(std::nullopt) == "n/a");
  CHECK(format_sah(12.5) == "12.50");
  // Two triangles, every structure built for real; only the BVH's and kD-tree's nodes are visible.
  const std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {9, 0, 0}, {10, 0, 0}, {9, 1, 0}};
  const std::vector<uint32_t> indices{0, 1, 2, 3, 4, 5};
  const std::vector<GeometryView> views{GeometryView{positions, indices}};
  const std::vector<InstanceView> instances{InstanceView{0, {}}};
  const std::vector<int> threads{1, 2};
  const std::string header = table_header(threads);
  AccelConfig config;
  config.bvh.width = 2;
  for (const std::string name : {"embree", "bvh", "kdtree", "grid", "brute"}) {
    INFO(name);
    const auto accel = make_accelerator(name, views, instances, config);
    Row r = make_row("two-triangles", name, "primary", 3);
    r.sah = measure_structure_sah(name, views, instances, config, *accel).cost;
    r.builder_sah = accel->stats().sah_cost;
    const std::string line = table_row(r);
    CHECK(line.back() == '\n');
    CHECK(column(header, line, "SAH") == (name == "bvh" ? "1.20" : name == "kdtree" ? "2.10" : "n/a"));
    CHECK(column(header, line, "B/tri") == "50.0");
    CHECK(column(header, line, "count") == "576");
  }
  CHECK(sah_legend({1, 1}).find("C_T = 1 per node visit and C_I = 1 per primitive test") !=
        std::string::npos);
  CHECK(sah_legend({1, 1.5}).find("C_I = 1.5") != std::string::npos);
}

TEST_CASE("chart of result rows: panels, spreads and caption", "[bench][quick]") {
  std::vector<Row> rows;
  for (const char* scene : {"scene-a", "scene-b"})
    for (const auto& [accel, base] : {std::pair<const char*, double>{"embree", 10}, {"bvh", 7}})
      for (const char* kind : {"primary", "shadow"}) rows.push_back(make_row(scene, accel, kind, base));
  rows[0].shapes = 3;
  RunSettings s;
  s.width = 512, s.height = 288, s.builds = 5, s.repeats = 7, s.build_threads = 2;
  s.threads = {1, 2};
  s.machine = "Test CPU, 2 cores (4 threads), 7.8 GiB RAM";
  s.software = "Penumbra test";
  const BarChart c = results_chart(rows, s);
  CHECK(c.series == std::vector<std::string>{"embree", "bvh"});
  CHECK(c.row_labels == std::vector<std::string>{"scene-a", "scene-b"});
  REQUIRE(c.rows.size() == 2);
  for (const auto& panels : c.rows) {
    REQUIRE(panels.size() == 3);  // 1 thread, 2 threads, build
    CHECK(panels[0].title == "1 thread");
    CHECK(panels[1].title == "2 threads");
    CHECK(panels[0].unit == "Mrays/s");
    CHECK(panels[2].unit == "ms");
    CHECK(panels[0].groups == std::vector<std::string>{"primary", "shadow"});
    const Spread bvh2 = *panels[1].values[1][1];  // 2 threads, shadow, bvh
    CHECK(bvh2.min == Approx(7 * 2 * 0.9));
    CHECK(bvh2.median == Approx(14));
    CHECK(bvh2.max == Approx(7 * 2 * 1.05));
    const Spread build = *panels[2].values[0][0];  // embree, in ms
    CHECK(build.min == Approx(10));
    CHECK(build.median == Approx(12));
    CHECK(build.max == Approx(15));
  }
  std::string caption;
  for (const auto& p : c.caption) caption += p + "\n";
  for (const char* needed :
       {"Machine: Test CPU, 2 cores (4 threads), 7.8 GiB RAM.", "Penumbra test", "512 x 288 (1 spp",
        "median of 7 timed passes", "at 1, 2 threads", "5 builds on 2 threads",
        "error bars: minimum to maximum", "scene-a (1000 triangles, 3 shapes); scene-b (1000 triangles)",
        "primary, shadow"})
    CHECK(caption.find(needed) != std::string::npos);

  if (!std::filesystem::exists("/usr/bin/python3")) return test::skip("/usr/bin/python3 not found");
  const auto dir = test::temp_dir("report_chart");
  std::ofstream(dir / "chart.svg") << bar_chart_svg(c);
  const std::string cmd = "/usr/bin/python3 '" +
                          (test::source_dir() / "tests/benchmarks/svg_check.py").string() + "' '" +
                          (dir / "chart.svg").string() + "' > '" + (dir / "out.txt").string() + "' 2>&1";
  CHECK(std::system(cmd.c_str()) == 0);
  std::ifstream out(dir / "out.txt");
  std::string first;
  std::getline(out, first);
  CHECK(first == "ok: 6 panels, 20 bars");  // 2 scenes x (2 threads x 2 kinds x 2 structures + 2 builds)
}
