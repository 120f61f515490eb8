// The benchmark charts: nice ticks (1/2/5 x 10^k steps covering the data), their labels, spreads,
// the panel layout (error bars from min to max on the ticks' axis) and the SVG, read back by
// Python's XML parser through tests/benchmarks/svg_check.py.
#include "benchmarks/chart.h"

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "support/test_util.h"

using namespace penumbra;
using namespace penumbra::bench;

namespace {

/// The next smaller 1/2/5 x 10^k step than m x 10^e.
double smaller_step(int m, int e) {
  return m == 1 ? 5 * std::pow(10.0, e - 1) : (m == 2 ? std::pow(10.0, e) : 2 * std::pow(10.0, e));
}

/// Checks every promise of nice_ticks(lo, hi, target).
void check_ticks(double lo, double hi, int target) {
  INFO("range [" << lo << ", " << hi << "], target " << target);
  const AxisTicks t = nice_ticks(lo, hi, target);
  if (lo == hi) hi = lo + (lo == 0 ? 1.0 : std::fabs(lo));  // an empty range is widened
  REQUIRE(t.values.size() >= 2);
  CHECK(t.lo() <= lo);
  CHECK(t.hi() >= hi);
  CHECK((t.mantissa == 1 || t.mantissa == 2 || t.mantissa == 5));
  CHECK(t.step == Approx(t.mantissa * std::pow(10.0, t.exponent)).epsilon(1e-12));
  for (size_t i = 0; i < t.values.size(); ++i) {
    const double k = t.values[i] / t.step;
    CHECK(std::fabs(k - std::round(k)) < 1e-9 * std::max(1.0, std::fabs(k)));  // a multiple of the step
    if (i > 0)  // evenly spaced, up to the rounding of the values themselves
      CHECK(t.values[i] - t.values[i - 1] ==
            Approx(t.step).epsilon(1e-9).margin(1e-15 * std::fabs(t.values[i])));
  }
  // The first and last ticks are the nearest multiples beyond the data, not one further.
  CHECK(t.values[1] > lo);
  CHECK(t.values[t.values.size() - 2] < hi);
  // The step is the smallest nice one giving at most `target` intervals over the range.
  const double range = hi - lo;
  CHECK(t.step >= range / target * (1 - 1e-12));
  CHECK(smaller_step(t.mantissa, t.exponent) < range / target);
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// Runs tests/benchmarks/svg_check.py on `svg`; returns its exit status and sets `output`.
int run_svg_check(const std::string& svg, const std::string& name, std::string& output) {
  const auto dir = test::temp_dir("chart_" + name);
  std::ofstream(dir / "chart.svg") << svg;
  const auto script = test::source_dir() / "tests/benchmarks/svg_check.py";
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + (dir / "chart.svg").string() +
                          "' > '" + (dir / "out.txt").string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  output = read_text(dir / "out.txt");
  return status;
}

BarChart sample_chart() {
  BarChart c;
  c.title = "throughput & build <test>";
  c.series = {"embree", "bvh", "kdtree"};
  c.row_labels = {"scene-a", "scene \"b\""};
  for (int r = 0; r < 2; ++r) {
    BarPanel p;
    p.title = "1 thread";
    p.x_label = "ray kind";
    p.quantity = "throughput";
    p.unit = "Mrays/s";
    p.groups = {"primary", "shadow"};
    p.values = {{Spread{9.1, 9.5, 9.9}, Spread{6.0, 6.2, 6.3}, std::nullopt},
                {Spread{11.0, 12.5, 13.0}, Spread{0.02, 0.03, 0.05}, Spread{4, 4, 4}}};
    BarPanel b;
    b.title = "build, 2 threads";
    b.x_label = "structure";
    b.quantity = "build time";
    b.unit = "ms";
    b.groups = {""};
    b.values = {{Spread{800, 870.0 + r, 1234.5}, Spread{0.4, 0.5, 0.7}, Spread{0, 0, 0}}};
    c.rows.push_back({p, b});
  }
  c.caption = {"Machine: Test CPU, 4 cores (8 threads), 15.6 GiB RAM.",
               "Settings: 512 x 288 (1 spp), 1, 2 threads; error bars: min to max of 5 passes."};
  return c;
}

}  // namespace

TEST_CASE("nice ticks cover the data range in 1/2/5 x 10^k steps", "[bench][quick]") {
  const double ranges[][2] = {{0, 9.3},   {0, 0.037},     {3.2, 1234},   {-7, 42}, {0, 1},
                              {0, 100},   {1e-9, 3.3e-9}, {0, 1.2e7},    {0, 4.9}, {0.5, 0.5000001},
                              {-1e-3, 0}, {12.5, 12.9},   {0, 5},        {0, 25},  {0, 0.3},
                              {0, 0.7},   {-250, -3},     {0.01, 99999}, {7, 7},   {0, 0}};
  for (const auto& r : ranges)
    for (int target : {1, 3, 5, 8}) check_ticks(r[0], r[1], target);
}

TEST_CASE("nice ticks: known axes and labels", "[bench][quick]") {
  const AxisTicks a = nice_ticks(0, 9.3, 5);  // raw step 1.86 -> 2
  CHECK(a.values == std::vector<double>{0, 2, 4, 6, 8, 10});
  CHECK(format_tick(4, a) == "4");
  const AxisTicks b = nice_ticks(0, 0.037, 5);  // raw 0.0074 -> 0.01
  REQUIRE(b.values.size() == 5);
  CHECK(b.hi() == Approx(0.04));
  CHECK(format_tick(b.values[3], b) == "0.03");
  const AxisTicks c = nice_ticks(0, 0, 5);  // widened to [0, 1]: steps of 0.2
  CHECK(c.values.size() == 6);
  CHECK(format_tick(c.values[1], c) == "0.2");
  const AxisTicks d = nice_ticks(-1, 1, 4);  // 0.5 steps through 0
  REQUIRE(d.values.size() == 5);
  CHECK(format_tick(d.values[2], d) == "0.0");  // every label with the step's one decimal
  CHECK(format_tick(-0.0, d) == "0.0");
  CHECK(format_tick(-1e-17, d) == "0.0");
  CHECK(format_tick(d.values[0], d) == "-1.0");
  const AxisTicks e = nice_ticks(0, 1.2e7, 5);
  CHECK(e.step == 5e6);
  CHECK(format_tick(e.hi(), e) == "15000000");
  CHECK_THROWS_AS(nice_ticks(2, 1), std::invalid_argument);
  CHECK_THROWS_AS(nice_ticks(0, INFINITY), std::invalid_argument);
  CHECK_THROWS_AS(nice_ticks(NAN, 1), std::invalid_argument);
}

TEST_CASE("spread: min, median and max of repeated runs", "[bench][quick]") {
  const std::vector<double> odd{3, 1, 2}, even{4, 1, 3, 2}, one{7};
  const Spread a = spread_of(odd), b = spread_of(even), c = spread_of(one);
  CHECK((a.min == 1 && a.median == 2 && a.max == 3));
  CHECK((b.min == 1 && b.median == 2.5 && b.max == 4));
  CHECK((c.min == 7 && c.median == 7 && c.max == 7));
  CHECK_THROWS_AS(spread_of(std::vector<double>{}), std::invalid_argument);
}

TEST_CASE("panel layout: error bars span min..max on the tick axis", "[bench][quick]") {
  const BarChart chart = sample_chart();
  const BarPanel& p = chart.rows[0][0];
  const PanelGeometry g = layout_panel(p, 3, 100, 50, 300, 180);
  REQUIRE(g.bars.size() == 5);  // one value is missing
  CHECK(g.ticks.lo() == 0);
  CHECK(g.ticks.hi() >= 13.0);
  CHECK(g.y_of(g.ticks.lo()) == Approx(230));  // bottom of the plot
  CHECK(g.y_of(g.ticks.hi()) == Approx(50));   // top
  for (const BarGeometry& b : g.bars) {
    const Spread& v = *p.values[b.group][b.series];
    CHECK(b.y_min == Approx(230 - v.min / g.ticks.hi() * 180));
    CHECK(b.y_max == Approx(230 - v.max / g.ticks.hi() * 180));
    CHECK(b.y_median == Approx(230 - v.median / g.ticks.hi() * 180));
    CHECK(b.y_max <= b.y_median);
    CHECK(b.y_median <= b.y_min);
    CHECK(b.x >= 100);
    CHECK(b.x + b.width <= 400);
  }
  // Bars of one group side by side, in series order, inside the group's share of the width.
  CHECK(g.bars[0].x + g.bars[0].width < g.bars[1].x);
  CHECK(g.bars[1].x + g.bars[1].width <= 250);
  CHECK(g.bars[2].x >= 250);
}

TEST_CASE("wrap_text and xml_escape", "[bench][quick]") {
  const std::string text = "Machine: AMD EPYC, 2 cores (2 threads), 23.5 GiB RAM. Settings: 512 x 288.";
  const auto lines = wrap_text(text, 20);
  std::string joined;
  for (const auto& l : lines) {
    CHECK(l.size() <= 20);
    joined += (joined.empty() ? "" : " ") + l;
  }
  CHECK(joined == text);
  CHECK(wrap_text("averyveryverylongword x", 5) == std::vector<std::string>{"averyveryverylongword", "x"});
  CHECK(xml_escape("a<b & \"c\" 'd'>") == "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;");
}

TEST_CASE("the SVG parses as XML and its ticks, error bars and caption check out", "[bench]") {
  if (!std::filesystem::exists("/usr/bin/python3")) return test::skip("/usr/bin/python3 not found");
  const std::string svg = bar_chart_svg(sample_chart());
  std::string out;
  CHECK(run_svg_check(svg, "good", out) == 0);
  INFO(out);
  CHECK(out.find("ok: 4 panels, 16 bars") != std::string::npos);
  CHECK(svg.find("scene &quot;b&quot;") != std::string::npos);
  CHECK(svg.find("Machine: Test CPU, 4 cores (8 threads), 15.6 GiB RAM.") != std::string::npos);

  // The checker rejects a truncated document and a moved error bar.
  CHECK(run_svg_check(svg.substr(0, svg.size() / 2), "truncated", out) != 0);
  CHECK(out.find("not well-formed XML") != std::string::npos);
  std::string moved = svg;
  const size_t at = moved.find("class=\"spread\"");
  REQUIRE(at != std::string::npos);
  const size_t y2 = moved.find("y2=\"", at) + 4;
  moved.replace(y2, moved.find('"', y2) - y2, "1.00");
  CHECK(run_svg_check(moved, "moved", out) != 0);
  CHECK(out.find("is not min..max") != std::string::npos);
}
