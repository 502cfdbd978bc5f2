#pragma once
// A small inline-SVG scatter plot (no library, no script): axes with tick
// labels, a zero line, one colour per series and a legend. For the HTML
// report of `cdpr-calib diagnose`.

#include <string>
#include <vector>

namespace cdpr::tools {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
};

struct PlotSpec {
  std::string title, x_label, y_label;
  int width = 420, height = 260;  // [px]
};

// `<svg ...>...</svg>`; empty series are skipped, non-finite points dropped.
std::string svg_scatter(const PlotSpec& spec, const std::vector<PlotSeries>& series);

// Text with &, <, >, " escaped for HTML and SVG.
std::string html_escape(const std::string& text);

}  // namespace cdpr::tools
