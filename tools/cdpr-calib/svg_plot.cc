#include "svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cdpr::tools {
namespace {

const char* const kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"};

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", v);
  return buffer;
}

// Range of the finite values, widened so a single value or a flat series still plots.
void range_of(const std::vector<PlotSeries>& series, bool use_x, double& lo, double& hi) {
  lo = 1e300;
  hi = -1e300;
  for (const PlotSeries& s : series) {
    for (double v : use_x ? s.x : s.y) {
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (lo > hi) lo = 0.0, hi = 1.0;
  const double pad = hi > lo ? 0.05 * (hi - lo) : std::max(1e-9, 0.1 * std::abs(lo));
  lo -= pad;
  hi += pad;
}

}  // namespace

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string svg_scatter(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  const double left = 62, right = 10, top = 22, bottom = 38;
  const double w = spec.width - left - right, h = spec.height - top - bottom;
  double x_lo, x_hi, y_lo, y_hi;
  range_of(series, true, x_lo, x_hi);
  range_of(series, false, y_lo, y_hi);
  const auto px = [&](double x) { return left + (x - x_lo) / (x_hi - x_lo) * w; };
  const auto py = [&](double y) { return top + (y_hi - y) / (y_hi - y_lo) * h; };

  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(spec.width) +
                    "\" height=\"" + std::to_string(spec.height) + "\" font-family=\"sans-serif\" font-size=\"10\">";
  svg += "<text x=\"" + number(left) + "\" y=\"14\" font-size=\"12\">" + html_escape(spec.title) + "</text>";
  svg += "<rect x=\"" + number(left) + "\" y=\"" + number(top) + "\" width=\"" + number(w) + "\" height=\"" +
         number(h) + "\" fill=\"none\" stroke=\"#888\"/>";
  for (int k = 0; k <= 4; ++k) {  // ticks
    const double xv = x_lo + k * (x_hi - x_lo) / 4, yv = y_lo + k * (y_hi - y_lo) / 4;
    svg += "<text x=\"" + number(px(xv)) + "\" y=\"" + number(top + h + 12) + "\" text-anchor=\"middle\">" +
           number(xv) + "</text>";
    svg += "<text x=\"" + number(left - 4) + "\" y=\"" + number(py(yv) + 3) + "\" text-anchor=\"end\">" +
           number(yv) + "</text>";
  }
  if (y_lo < 0.0 && y_hi > 0.0) {
    svg += "<line x1=\"" + number(left) + "\" x2=\"" + number(left + w) + "\" y1=\"" + number(py(0.0)) + "\" y2=\"" +
           number(py(0.0)) + "\" stroke=\"#bbb\" stroke-dasharray=\"3,3\"/>";
  }
  svg += "<text x=\"" + number(left + w / 2) + "\" y=\"" + number(spec.height - 4) + "\" text-anchor=\"middle\">" +
         html_escape(spec.x_label) + "</text>";
  svg += "<text transform=\"translate(12," + number(top + h / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
         html_escape(spec.y_label) + "</text>";
  int colour = 0, legend = 0;
  for (const PlotSeries& s : series) {
    if (s.x.empty()) continue;
    const std::string fill = kColours[colour++ % 6];
    for (std::size_t j = 0; j < s.x.size() && j < s.y.size(); ++j) {
      if (!std::isfinite(s.x[j]) || !std::isfinite(s.y[j])) continue;
      svg += "<circle cx=\"" + number(px(s.x[j])) + "\" cy=\"" + number(py(s.y[j])) + "\" r=\"2.5\" fill=\"" + fill +
             "\"/>";
    }
    if (series.size() > 1) {
      svg += "<text x=\"" + number(left + w - 4) + "\" y=\"" + number(top + 12 + 11 * legend++) +
             "\" text-anchor=\"end\" fill=\"" + fill + "\">" + html_escape(s.name) + "</text>";
    }
  }
  return svg + "</svg>";
}

}  // namespace cdpr::tools
