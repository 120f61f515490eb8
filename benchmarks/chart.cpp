// Bar charts as SVG: nice axis ticks, the panel layout and the SVG writer (benchmarks/chart.h).
#include "benchmarks/chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace penumbra::bench {

namespace {

/// m x 10^e as the nearest double (dividing by 10^-e for negative e keeps 0.1, 0.2, ... exact).
double scaled(double m, int e) {
  return e >= 0 ? m * std::pow(10.0, e) : m / std::pow(10.0, -e);
}

/// A coordinate or length in SVG user units, two decimals.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", std::fabs(v) < 0.005 ? 0.0 : v);
  return buf;
}

/// A measured value for a tooltip: six significant digits.
std::string value_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

const char* const kColors[] = {"#4e79a7", "#f28e2b", "#59a14f", "#e15759", "#76b7b2", "#b07aa1"};

// Page layout, in SVG user units (px at 100%).
constexpr double kMargin = 16;       // left and right of everything
constexpr double kAxisWidth = 64;    // tick labels and the rotated y label, left of a plot
constexpr double kPlotWidth = 300;   // a panel's plot area
constexpr double kPlotHeight = 180;  //
constexpr double kPanelGap = 26;     // right of a plot
constexpr double kHeader = 64;       // title and legend
constexpr double kRowHeight = 268;   // row label, panel titles, plot, x labels
constexpr double kCaptionLine = 15;  // caption line height
constexpr double kCharWidth = 6.2;   // mean glyph advance of 11 px sans-serif, for wrapping

}  // namespace

AxisTicks nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
    throw std::invalid_argument("nice_ticks: bounds must be finite with lo <= hi");
  target = std::max(target, 1);
  if (lo == hi) hi = lo + (lo == 0 ? 1.0 : std::fabs(lo));
  const double raw = (hi - lo) / target;
  // The smallest 1/2/5 x 10^e not below raw (allowing for rounding in log10).
  AxisTicks t;
  const int e0 = int(std::floor(std::log10(raw)));
  bool found = false;
  for (int e = e0 - 1; e <= e0 + 1 && !found; ++e)
    for (int m : {1, 2, 5})
      if (scaled(m, e) >= raw * (1 - 1e-12)) {
        t.mantissa = m, t.exponent = e, found = true;
        break;
      }
  t.step = scaled(t.mantissa, t.exponent);
  const auto value = [&](double k) { return scaled(k * t.mantissa, t.exponent); };
  double k0 = std::floor(lo / t.step), k1 = std::ceil(hi / t.step);
  while (value(k0) > lo) --k0;
  while (value(k0 + 1) <= lo) ++k0;
  while (value(k1) < hi) ++k1;
  while (k1 - 1 > k0 && value(k1 - 1) >= hi) --k1;
  for (double k = k0; k <= k1; ++k) t.values.push_back(value(k));
  return t;
}

std::string format_tick(double value, const AxisTicks& ticks) {
  if (std::fabs(value) < ticks.step * 1e-6) value = 0;  // no "-0"
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::max(0, -ticks.exponent), value);
  return buf;
}

Spread spread_of(std::span<const double> samples) {
  if (samples.empty()) throw std::invalid_argument("spread_of: no samples");
  std::vector<double> v(samples.begin(), samples.end());
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return {v.front(), n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]), v.back()};
}

double PanelGeometry::y_of(double value) const {
  return top + height - (value - ticks.lo()) / (ticks.hi() - ticks.lo()) * height;
}

PanelGeometry layout_panel(const BarPanel& panel, size_t series, double left, double top, double width,
                           double height) {
  PanelGeometry p;
  p.left = left, p.top = top, p.width = width, p.height = height;
  double vmin = 0, vmax = 0;
  for (const auto& group : panel.values)
    for (const auto& v : group)
      if (v) vmin = std::min(vmin, v->min), vmax = std::max({vmax, v->max, v->median});
  p.ticks = nice_ticks(vmin, vmax, 5);
  const size_t groups = std::max<size_t>(panel.groups.size(), 1), per_group = std::max<size_t>(series, 1);
  const double gw = width / double(groups), bw = gw * 0.8 / double(per_group);
  for (size_t g = 0; g < panel.values.size(); ++g)
    for (size_t s = 0; s < panel.values[g].size(); ++s) {
      const auto& v = panel.values[g][s];
      if (!v) continue;
      BarGeometry b;
      b.group = g, b.series = s;
      b.x = left + double(g) * gw + 0.1 * gw + double(s) * bw + 0.04 * bw;
      b.width = 0.92 * bw;
      b.y_median = p.y_of(v->median);
      b.y_min = p.y_of(v->min);
      b.y_max = p.y_of(v->max);
      p.bars.push_back(b);
    }
  return p;
}

std::vector<std::string> wrap_text(const std::string& text, size_t max_chars) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    if (!line.empty() && line.size() + 1 + word.size() > max_chars) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

std::string xml_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      case '\'':
        o += "&apos;";
        break;
      default:
        if (static_cast<unsigned char>(c) >= 0x20 || c == '\t') o += c;  // no control characters in XML 1.0
    }
  }
  return o;
}

namespace {

/// One panel: grid lines, bars with error bars, then the axes on top.
void write_panel(std::ostringstream& o, const BarPanel& panel, const std::string& row_label,
                 const std::vector<std::string>& series, double cell_left, double row_top) {
  const double left = cell_left + kAxisWidth, top = row_top + 44;
  const PanelGeometry p = layout_panel(panel, series.size(), left, top, kPlotWidth, kPlotHeight);
  const double right = left + p.width, bottom = top + p.height;
  o << "<g class=\"panel\">\n<text class=\"panel-title\" x=\"" << num(left) << "\" y=\"" << num(top - 10)
    << "\" font-weight=\"bold\">" << xml_escape(panel.title) << "</text>\n";
  o << "<g class=\"grid\" stroke=\"#e6e6e6\" stroke-width=\"1\">\n";
  for (double v : p.ticks.values)
    o << "<line x1=\"" << num(left) << "\" y1=\"" << num(p.y_of(v)) << "\" x2=\"" << num(right) << "\" y2=\""
      << num(p.y_of(v)) << "\"/>\n";
  o << "</g>\n";
  for (const BarGeometry& b : p.bars) {
    const Spread& v = *panel.values[b.group][b.series];
    const double cx = b.x + b.width / 2, cap = std::max(b.width / 4, 1.5);
    o << "<g class=\"bar\"><title>"
      << xml_escape(row_label + " \xC2\xB7 " + (b.series < series.size() ? series[b.series] : "") +
                    " \xC2\xB7 " + (b.group < panel.groups.size() ? panel.groups[b.group] : "") +
                    ": median " + value_text(v.median) + " " + panel.unit + " (min " + value_text(v.min) +
                    ", max " + value_text(v.max) + ")")
      << "</title>";
    o << "<rect x=\"" << num(b.x) << "\" y=\"" << num(std::min(b.y_median, p.y_of(0))) << "\" width=\""
      << num(b.width) << "\" height=\"" << num(std::fabs(p.y_of(0) - b.y_median)) << "\" fill=\""
      << kColors[b.series % 6] << "\"/>";
    o << "<line class=\"spread\" x1=\"" << num(cx) << "\" y1=\"" << num(b.y_max) << "\" x2=\"" << num(cx)
      << "\" y2=\"" << num(b.y_min) << "\" stroke=\"#222\" stroke-width=\"1\"/>";
    for (double y : {b.y_max, b.y_min})
      o << "<line class=\"cap\" x1=\"" << num(cx - cap) << "\" y1=\"" << num(y) << "\" x2=\"" << num(cx + cap)
        << "\" y2=\"" << num(y) << "\" stroke=\"#222\" stroke-width=\"1\"/>";
    o << "</g>\n";
  }
  // The y axis: line, ticks with labels, the quantity and its unit.
  o << "<g class=\"y-axis\">\n<line x1=\"" << num(left) << "\" y1=\"" << num(top) << "\" x2=\"" << num(left)
    << "\" y2=\"" << num(bottom) << "\" stroke=\"black\"/>\n";
  for (double v : p.ticks.values)
    o << "<g class=\"tick\"><line x1=\"" << num(left - 4) << "\" y1=\"" << num(p.y_of(v)) << "\" x2=\""
      << num(left) << "\" y2=\"" << num(p.y_of(v)) << "\" stroke=\"black\"/><text x=\"" << num(left - 6)
      << "\" y=\"" << num(p.y_of(v) + 3.5) << "\" text-anchor=\"end\">" << format_tick(v, p.ticks)
      << "</text></g>\n";
  const double lx = left - 50, ly = top + p.height / 2;
  o << "<text class=\"axis-label\" x=\"" << num(lx) << "\" y=\"" << num(ly) << "\" transform=\"rotate(-90 "
    << num(lx) << " " << num(ly) << ")\" text-anchor=\"middle\">"
    << xml_escape(panel.quantity + " (" + panel.unit + ")") << "</text>\n</g>\n";
  // The x axis: the baseline at 0, the category labels and the axis label.
  const double gw = p.width / double(std::max<size_t>(panel.groups.size(), 1));
  o << "<g class=\"x-axis\">\n<line x1=\"" << num(left) << "\" y1=\"" << num(p.y_of(0)) << "\" x2=\""
    << num(right) << "\" y2=\"" << num(p.y_of(0)) << "\" stroke=\"black\"/>\n";
  for (size_t g = 0; g < panel.groups.size(); ++g)
    o << "<text x=\"" << num(left + (double(g) + 0.5) * gw) << "\" y=\"" << num(bottom + 14)
      << "\" text-anchor=\"middle\">" << xml_escape(panel.groups[g]) << "</text>\n";
  o << "<text class=\"axis-label\" x=\"" << num(left + p.width / 2) << "\" y=\"" << num(bottom + 30)
    << "\" text-anchor=\"middle\">" << xml_escape(panel.x_label) << "</text>\n</g>\n</g>\n";
}

}  // namespace

std::string bar_chart_svg(const BarChart& chart) {
  size_t columns = 1;
  for (const auto& row : chart.rows) columns = std::max(columns, row.size());
  const double width = 2 * kMargin + double(columns) * (kAxisWidth + kPlotWidth + kPanelGap);
  std::vector<std::string> caption;
  for (const auto& paragraph : chart.caption)
    for (auto& line : wrap_text(paragraph, size_t((width - 2 * kMargin) / kCharWidth)))
      caption.push_back(std::move(line));
  const double caption_top = kHeader + double(chart.rows.size()) * kRowHeight + 10;
  const double height = caption_top + double(caption.size()) * kCaptionLine + 12;
  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << num(width) << "\" height=\""
    << num(height) << "\" viewBox=\"0 0 " << num(width) << " " << num(height)
    << "\" font-family=\"sans-serif\" font-size=\"11\">\n"
    << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text class=\"title\" x=\"" << num(kMargin) << "\" y=\"22\" font-size=\"15\" font-weight=\"bold\">"
    << xml_escape(chart.title) << "</text>\n<g class=\"legend\">\n";
  double lx = kMargin;
  for (size_t s = 0; s < chart.series.size(); ++s) {
    o << "<rect x=\"" << num(lx) << "\" y=\"34\" width=\"12\" height=\"12\" fill=\"" << kColors[s % 6]
      << "\"/><text x=\"" << num(lx + 16) << "\" y=\"44\">" << xml_escape(chart.series[s]) << "</text>\n";
    lx += 28 + kCharWidth * double(chart.series[s].size());
  }
  o << "</g>\n";
  for (size_t r = 0; r < chart.rows.size(); ++r) {
    const double row_top = kHeader + double(r) * kRowHeight;
    const std::string label = r < chart.row_labels.size() ? chart.row_labels[r] : "";
    o << "<text class=\"row-label\" x=\"" << num(kMargin) << "\" y=\"" << num(row_top + 14)
      << "\" font-size=\"13\" font-weight=\"bold\">" << xml_escape(label) << "</text>\n";
    for (size_t c = 0; c < chart.rows[r].size(); ++c)
      write_panel(o, chart.rows[r][c], label, chart.series,
                  kMargin + double(c) * (kAxisWidth + kPlotWidth + kPanelGap), row_top);
  }
  o << "<g class=\"caption\" fill=\"#333\">\n";
  for (size_t i = 0; i < caption.size(); ++i)
    o << "<text x=\"" << num(kMargin) << "\" y=\"" << num(caption_top + double(i + 1) * kCaptionLine) << "\">"
      << xml_escape(caption[i]) << "</text>\n";
  o << "</g>\n</svg>\n";
  return o.str();
}

}  // namespace penumbra::bench
