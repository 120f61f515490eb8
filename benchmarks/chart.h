// Bar charts of benchmark results as plain SVG 1.1 (no scripts, no external fonts): y axes with
// ticks at 1, 2 or 5 x 10^k, light grid lines, units in the axis labels, a bar per series and
// category with its min-max spread as an error bar, a legend and a caption of wrapped lines under
// the chart. Knows nothing about acceleration structures: benchmarks/report.h fills a BarChart.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

namespace penumbra::bench {

/// The ticks of a linear axis: values[0] <= the data minimum, values.back() >= the maximum,
/// successive values `step` apart, step = m x 10^exponent with m in {1, 2, 5}.
struct AxisTicks {
  std::vector<double> values;
  double step = 1;
  int mantissa = 1;  ///< 1, 2 or 5
  int exponent = 0;  ///< step = mantissa x 10^exponent
  double lo() const { return values.front(); }
  double hi() const { return values.back(); }
};

/// Ticks covering [lo, hi] (finite, lo <= hi) in about `target` (>= 1) intervals: the step is the
/// smallest 1/2/5 x 10^k at least (hi - lo) / target, and the first and last ticks are the
/// multiples of it at or just beyond lo and hi. An empty range (lo == hi) is widened to one step
/// around it ([0, 1] for 0). Throws std::invalid_argument for non-finite or reversed bounds.
AxisTicks nice_ticks(double lo, double hi, int target = 5);

/// A tick value as its label, with as many decimals as the step needs (step 5: "10"; step 0.5:
/// "1.5", "0.0"; step 0.02: "0.06"); values within 10^-6 steps of 0 print as 0, never "-0".
std::string format_tick(double value, const AxisTicks& ticks);

/// Median and range of repeated measurements.
struct Spread {
  double min = 0, median = 0, max = 0;
};

/// The spread of `samples` (non-empty; the median of an even count is the mean of the middle two).
Spread spread_of(std::span<const double> samples);

/// One chart panel: categories along x (`groups`), one bar per series in each, heights from 0.
struct BarPanel {
  std::string title;     ///< above the panel, e.g. "1 thread"
  std::string x_label;   ///< e.g. "ray kind"
  std::string quantity;  ///< e.g. "throughput"
  std::string unit;      ///< e.g. "Mrays/s"; the y label is "quantity (unit)"
  std::vector<std::string> groups;
  std::vector<std::vector<std::optional<Spread>>> values;  ///< [group][series]; nullopt: no bar
};

/// A grid of panels: one row per label (e.g. per scene), a legend of the series, a caption.
struct BarChart {
  std::string title;
  std::vector<std::string> series;          ///< legend order; series i has colour i (mod 6)
  std::vector<std::string> row_labels;      ///< one per row
  std::vector<std::vector<BarPanel>> rows;  ///< rows[r]: the panels of row r, left to right
  std::vector<std::string> caption;         ///< paragraphs under the chart, wrapped to its width
};

/// Where one bar and its error bar are drawn (SVG user units, y down).
struct BarGeometry {
  size_t group = 0, series = 0;
  double x = 0, width = 0;      ///< left edge and width of the bar
  double y_median = 0;          ///< top of the bar
  double y_min = 0, y_max = 0;  ///< ends of the error bar (y_min >= y_max: y grows downwards)
};

/// A panel's plot area, its y axis and its bars.
struct PanelGeometry {
  double left = 0, top = 0, width = 0, height = 0;  ///< the plot area
  AxisTicks ticks;                                  ///< y axis, from ticks.lo() at the bottom
  std::vector<BarGeometry> bars;                    ///< one per value present
  /// The y coordinate of `value` on this panel's axis.
  double y_of(double value) const;
};

/// Lays out `panel` (values >= 0) with `series` bars per group in the plot area at (left, top)
/// of the given size: the y axis runs from 0 to the tick at or above the largest max, groups
/// share the width equally, the bars of a group fill 80% of its share.
PanelGeometry layout_panel(const BarPanel& panel, size_t series, double left, double top, double width,
                           double height);

/// `text` broken at spaces into lines of at most `max_chars` characters (longer words stay whole).
std::vector<std::string> wrap_text(const std::string& text, size_t max_chars);

/// `s` with &, <, >, " and ' escaped for XML text and attribute values.
std::string xml_escape(const std::string& s);

/// The chart as a standalone SVG document (UTF-8, SVG 1.1). Elements carry classes for tools and
/// tests: g.panel, g.grid, g.y-axis > g.tick (line + label), g.bar (title, rect, line.spread,
/// two line.cap), text.axis-label, g.legend, g.caption.
std::string bar_chart_svg(const BarChart& chart);

}  // namespace penumbra::bench
