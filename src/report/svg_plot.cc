#include "src/report/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "src/report/ellipse.h"
#include "src/report/html.h"

namespace cdpr::report {
namespace {

// Colour-blind-safe (Okabe-Ito): cables 0-3, load cell, other.
const char* const kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#555555"};

std::string num(double v) { return format("%.1f", v); }

struct LegendEntry {
  std::string name;
  int colour;
  bool line = false;  // a line sample instead of a dot
  bool open = false;  // an open circle (a nominal position) instead of a filled dot
};

double legend_width(const std::vector<LegendEntry>& legend) {
  std::size_t longest = 0;
  for (const LegendEntry& e : legend) longest = std::max(longest, e.name.size());
  return legend.empty() ? 0.0 : 22.0 + 5.6 * static_cast<double>(longest);
}

// Margins of the data area in a plot [px]: tick labels left, title top,
// tick labels and axis label below.
constexpr double kLeft = 52, kTop = 22, kBottom = 34, kRight = 16;

// The frame of one plot: margins, tick labels, axis labels, zero lines and
// the legend column; maps data to pixels.
class Frame {
 public:
  Frame(const PlotSpec& spec, Ticks x, Ticks y, const std::vector<LegendEntry>& legend)
      : x_(std::move(x)), y_(std::move(y)) {
    right_ = kRight + legend_width(legend);
    w_ = spec.width - left_ - right_;
    h_ = spec.height - top_ - bottom_;
    svg_ = format("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 %d %d\" width=\"%d\" height=\"%d\" "
                  "font-family=\"sans-serif\" font-size=\"10\" role=\"img\">",
                  spec.width, spec.height, spec.width, spec.height);
    svg_ += "<title>" + html_escape(spec.title) + "</title>";
    svg_ += "<text x=\"4\" y=\"14\" font-size=\"12\" font-weight=\"bold\">" + html_escape(spec.title) + "</text>";
    for (double v : x_.values) {
      svg_ += "<line x1=\"" + num(px(v)) + "\" x2=\"" + num(px(v)) + "\" y1=\"" + num(top_) + "\" y2=\"" +
              num(top_ + h_ + 3) + "\" stroke=\"#eee\"/>";
      svg_ += "<text x=\"" + num(px(v)) + "\" y=\"" + num(top_ + h_ + 13) + "\" text-anchor=\"middle\">" +
              tick_label(v, x_.step) + "</text>";
    }
    for (double v : y_.values) {
      svg_ += "<line x1=\"" + num(left_ - 3) + "\" x2=\"" + num(left_ + w_) + "\" y1=\"" + num(py(v)) + "\" y2=\"" +
              num(py(v)) + "\" stroke=\"#eee\"/>";
      svg_ += "<text x=\"" + num(left_ - 5) + "\" y=\"" + num(py(v) + 3.5) + "\" text-anchor=\"end\">" +
              tick_label(v, y_.step) + "</text>";
    }
    if (y_.lo < 0.0 && y_.hi > 0.0) {
      svg_ += "<line x1=\"" + num(left_) + "\" x2=\"" + num(left_ + w_) + "\" y1=\"" + num(py(0.0)) + "\" y2=\"" +
              num(py(0.0)) + "\" stroke=\"#777\"/>";
    }
    if (x_.lo < 0.0 && x_.hi > 0.0) {
      svg_ += "<line x1=\"" + num(px(0.0)) + "\" x2=\"" + num(px(0.0)) + "\" y1=\"" + num(top_) + "\" y2=\"" +
              num(top_ + h_) + "\" stroke=\"#777\"/>";
    }
    svg_ += "<rect x=\"" + num(left_) + "\" y=\"" + num(top_) + "\" width=\"" + num(w_) + "\" height=\"" + num(h_) +
            "\" fill=\"none\" stroke=\"#888\"/>";
    svg_ += "<text x=\"" + num(left_ + w_ / 2) + "\" y=\"" + num(spec.height - 6) + "\" text-anchor=\"middle\">" +
            html_escape(spec.x_label) + "</text>";
    svg_ += "<text transform=\"translate(11," + num(top_ + h_ / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
            html_escape(spec.y_label) + "</text>";
    for (std::size_t k = 0; k < legend.size(); ++k) {
      const double lx = left_ + w_ + 10, ly = top_ + 8 + 14 * static_cast<double>(k);
      const char* colour = series_colour(legend[k].colour);
      if (legend[k].line) {
        svg_ += "<line x1=\"" + num(lx) + "\" x2=\"" + num(lx + 10) + "\" y1=\"" + num(ly) + "\" y2=\"" + num(ly) +
                "\" stroke=\"" + colour + "\" stroke-width=\"2\"/>";
      } else if (legend[k].open) {
        svg_ += "<circle cx=\"" + num(lx + 5) + "\" cy=\"" + num(ly) + "\" r=\"3.5\" fill=\"none\" stroke=\"" + colour +
                "\" stroke-width=\"1.5\"/>";
      } else {
        svg_ += "<circle cx=\"" + num(lx + 5) + "\" cy=\"" + num(ly) + "\" r=\"3\" fill=\"" + colour + "\"/>";
      }
      svg_ += "<text x=\"" + num(lx + 14) + "\" y=\"" + num(ly + 3.5) + "\">" + html_escape(legend[k].name) + "</text>";
    }
  }

  double px(double x) const { return left_ + (x - x_.lo) / (x_.hi - x_.lo) * w_; }
  double py(double y) const { return top_ + (y_.hi - y) / (y_.hi - y_.lo) * h_; }
  bool inside(double x, double y) const { return x >= x_.lo && x <= x_.hi && y >= y_.lo && y <= y_.hi; }
  std::string& svg() { return svg_; }
  std::string finish() { return svg_ + "</svg>"; }

 private:
  
  Ticks x_, y_;
  double left_ = kLeft, top_ = kTop, bottom_ = kBottom, right_ = kRight, w_ = 0, h_ = 0;
  std::string svg_;
};

Ticks ticks_or_data(const std::optional<Ticks>& given, const std::vector<PlotSeries>& series, bool x) {
  if (given) return *given;
  const auto range = data_range(series, x);
  return range ? nice_ticks(range->first, range->second) : nice_ticks(0.0, 1.0);
}

double normal_density(double z) { return std::exp(-0.5 * z * z) / std::sqrt(2.0 * std::numbers::pi); }

// Sizes `spec` for a square data area of `side` px beside the legend: equal
// scales on x and y.
void square_data_area(PlotSpec& spec, const std::vector<LegendEntry>& legend, int side) {
  spec.width = static_cast<int>(std::ceil(kLeft + side + kRight + legend_width(legend)));
  spec.height = static_cast<int>(kTop + side + kBottom);
}

constexpr double kHistogramEdge = 5.0, kBinWidth = 0.5;

std::vector<double> histogram_density(const std::vector<double>& values) {
  const int bins = static_cast<int>(2.0 * kHistogramEdge / kBinWidth);
  std::vector<double> density(static_cast<std::size_t>(bins), 0.0);
  std::size_t n = 0;
  for (double v : values) n += std::isfinite(v);
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    const int k = std::clamp(static_cast<int>(std::floor((v + kHistogramEdge) / kBinWidth)), 0, bins - 1);
    density[static_cast<std::size_t>(k)] += 1.0 / (static_cast<double>(n) * kBinWidth);
  }
  return density;
}

}  // namespace

const char* series_colour(int index) { return kColours[std::clamp(index, 0, 5)]; }

std::optional<std::pair<double, double>> data_range(const std::vector<PlotSeries>& series, bool x) {
  double lo = INFINITY, hi = -INFINITY;
  for (const PlotSeries& s : series) {
    for (double v : x ? s.x : s.y) {
      if (!std::isfinite(v)) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (lo > hi) return std::nullopt;
  return std::pair{lo, hi};
}

Ticks shared_ticks(const std::vector<const std::vector<PlotSeries>*>& plots, bool x) {
  double lo = INFINITY, hi = -INFINITY;
  for (const std::vector<PlotSeries>* p : plots) {
    if (const auto r = data_range(*p, x)) {
      lo = std::min(lo, r->first);
      hi = std::max(hi, r->second);
    }
  }
  return lo > hi ? nice_ticks(0.0, 1.0) : nice_ticks(lo, hi);
}

std::string svg_scatter(const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  std::vector<LegendEntry> legend;
  for (const PlotSeries& s : series) {
    if (!s.x.empty() && series.size() > 1) legend.push_back({s.name, s.colour});
  }
  Frame frame(spec, ticks_or_data(spec.x_ticks, series, true), ticks_or_data(spec.y_ticks, series, false), legend);
  for (const PlotSeries& s : series) {
    for (std::size_t j = 0; j < s.x.size() && j < s.y.size(); ++j) {
      if (!std::isfinite(s.x[j]) || !std::isfinite(s.y[j]) || !frame.inside(s.x[j], s.y[j])) continue;
      frame.svg() += "<circle class=\"data\" cx=\"" + num(frame.px(s.x[j])) + "\" cy=\"" + num(frame.py(s.y[j])) +
                     "\" r=\"2.4\" fill=\"" + series_colour(s.colour) + "\" fill-opacity=\"0.8\"/>";
    }
  }
  return frame.finish();
}

double normal_histogram_peak(const std::vector<double>& normalised) {
  const std::vector<double> density = histogram_density(normalised);
  return std::max(normal_density(0.0), *std::max_element(density.begin(), density.end()));
}

std::string svg_normal_histogram(const PlotSpec& spec, const std::vector<double>& normalised, int colour) {
  std::size_t n = 0;
  for (double v : normalised) n += std::isfinite(v);
  const Ticks x = spec.x_ticks ? *spec.x_ticks : nice_ticks(-kHistogramEdge, kHistogramEdge, 10);
  const Ticks y = spec.y_ticks ? *spec.y_ticks : nice_ticks(0.0, normal_histogram_peak(normalised), 4);
  Frame frame(spec, x, y, {{format("data (%zu)", n), colour}, {"N(0, 1)", kNeutralColour, true}});
  const std::vector<double> density = histogram_density(normalised);
  for (std::size_t k = 0; k < density.size(); ++k) {
    if (density[k] <= 0.0) continue;
    const double x0 = -kHistogramEdge + kBinWidth * static_cast<double>(k);
    const double top = std::min(density[k], y.hi);
    frame.svg() += "<rect class=\"data\" x=\"" + num(frame.px(x0)) + "\" y=\"" + num(frame.py(top)) + "\" width=\"" +
                   num(frame.px(x0 + kBinWidth) - frame.px(x0)) + "\" height=\"" + num(frame.py(0.0) - frame.py(top)) +
                   "\" fill=\"" + series_colour(colour) + "\" fill-opacity=\"0.55\" stroke=\"#fff\"/>";
  }
  std::string path;
  for (int j = 0; j <= 100; ++j) {
    const double z = -kHistogramEdge + 2.0 * kHistogramEdge * j / 100.0;
    path += (j ? " L" : "M") + num(frame.px(z)) + "," + num(frame.py(normal_density(z)));
  }
  frame.svg() += "<path d=\"" + path + "\" fill=\"none\" stroke=\"" + series_colour(kNeutralColour) +
                 "\" stroke-width=\"1.5\"/>";
  return frame.finish();
}

double anchor_view_half_width(const AnchorTopView& a) {
  return std::max(1e-4, 1.25 * sigma_ellipse(a.covariance, 3.0).major);
}

std::string svg_anchor_top_view(const AnchorTopView& a, double half_width_m) {
  // Millimetres below a metre of half-width: anchor sigmas are mm to cm.
  const bool mm = half_width_m < 1.0;
  const double unit = mm ? 1000.0 : 1.0;
  const Ticks t = nice_ticks(-half_width_m * unit, half_width_m * unit, 4);
  PlotSpec spec{a.name + " (top view)", format("x - fitted [%s]", mm ? "mm" : "m"),
                format("y - fitted [%s]", mm ? "mm" : "m"), t, t, 250, 0};
  std::vector<LegendEntry> legend{
      {"fitted", a.colour}, {"1, 3 sigma", a.colour, true}, {"nominal", kNeutralColour, false, true}};
  if (a.truth) legend.push_back({"true", kLoadCellColour, false, true});
  square_data_area(spec, legend, 180);
  Frame frame(spec, t, t, legend);
  const auto point = [&](const Eigen::Vector2d& world) -> Eigen::Vector2d { return (world - a.fitted) * unit; };
  for (double k : {1.0, 3.0}) {
    std::string path;
    const std::vector<Eigen::Vector2d> points =
        ellipse_points(Eigen::Vector2d::Zero(), sigma_ellipse(a.covariance * unit * unit, k), 72);
    for (std::size_t j = 0; j < points.size(); ++j) {
      path += (j ? " L" : "M") + num(frame.px(points[j].x())) + "," + num(frame.py(points[j].y()));
    }
    frame.svg() += "<path class=\"data\" d=\"" + path + " Z\" fill=\"none\" stroke=\"" + series_colour(a.colour) + "\"" +
                   (k > 1.0 ? " stroke-dasharray=\"4,3\"" : "") + "/>";
  }
  frame.svg() += "<circle class=\"data\" cx=\"" + num(frame.px(0)) + "\" cy=\"" + num(frame.py(0)) + "\" r=\"3\" fill=\"" +
                 series_colour(a.colour) + "\"/>";
  const auto mark = [&](const Eigen::Vector2d& world, int colour, const char* name, int row) {
    const Eigen::Vector2d p = point(world);
    const char* c = series_colour(colour);
    if (frame.inside(p.x(), p.y())) {
      frame.svg() += "<circle cx=\"" + num(frame.px(p.x())) + "\" cy=\"" + num(frame.py(p.y())) +
                     "\" r=\"3.5\" fill=\"none\" stroke=\"" + c + "\" stroke-width=\"1.5\"/>";
      return;
    }
    // Off the frame: an arrow from the centre towards it, to the frame's edge, and its distance.
    const double r = t.hi * 0.9 / std::max(std::abs(p.x()), std::abs(p.y()));
    const Eigen::Vector2d edge = p * r;
    frame.svg() += "<line x1=\"" + num(frame.px(0)) + "\" y1=\"" + num(frame.py(0)) + "\" x2=\"" +
                   num(frame.px(edge.x())) + "\" y2=\"" + num(frame.py(edge.y())) + "\" stroke=\"" + c +
                   "\" stroke-dasharray=\"2,2\"/>";
    frame.svg() += "<circle cx=\"" + num(frame.px(edge.x())) + "\" cy=\"" + num(frame.py(edge.y())) +
                   "\" r=\"3.5\" fill=\"none\" stroke=\"" + c + "\" stroke-width=\"1.5\"/>";
    frame.svg() += "<text x=\"" + num(frame.px(t.lo) + 4) + "\" y=\"" + num(frame.py(t.lo) - 6 - 12 * row) +
                   "\" fill=\"" + c + "\">" + format("%s %.3g m away", name, (world - a.fitted).norm()) + "</text>";
  };
  mark(a.nominal, kNeutralColour, "nominal", 0);
  if (a.truth) mark(*a.truth, kLoadCellColour, "true", 1);
  return frame.finish();
}

std::string svg_anchor_layout(const std::vector<AnchorTopView>& anchors) {
  std::vector<PlotSeries> series;
  for (const AnchorTopView& a : anchors) {
    series.push_back({a.name, {a.fitted.x(), a.nominal.x()}, {a.fitted.y(), a.nominal.y()}, a.colour});
  }
  // Equal scale on both axes: one range for x and y.
  const auto x = data_range(series, true), y = data_range(series, false);
  const double lo = std::min(x ? x->first : 0.0, y ? y->first : 0.0);
  const double hi = std::max(x ? x->second : 1.0, y ? y->second : 1.0);
  const Ticks t = nice_ticks(lo, hi, 5);
  std::vector<LegendEntry> legend;
  for (const AnchorTopView& a : anchors) legend.push_back({a.name, a.colour});
  // The symbols in the anchors' colours: filled where the fit put them, open at robot.toml's nominal.
  legend.push_back({"fitted", kNeutralColour});
  legend.push_back({"nominal", kNeutralColour, false, true});
  PlotSpec spec{"anchors seen from above", "x [m]", "y [m]", t, t, 0, 0};
  square_data_area(spec, legend, 220);
  Frame frame(spec, t, t, legend);
  for (const AnchorTopView& a : anchors) {
    const char* c = series_colour(a.colour);
    frame.svg() += "<circle class=\"data\" cx=\"" + num(frame.px(a.nominal.x())) + "\" cy=\"" + num(frame.py(a.nominal.y())) +
                   "\" r=\"5\" fill=\"none\" stroke=\"" + c + "\" stroke-width=\"1.5\"/>";
    frame.svg() += "<circle class=\"data\" cx=\"" + num(frame.px(a.fitted.x())) + "\" cy=\"" + num(frame.py(a.fitted.y())) +
                   "\" r=\"3\" fill=\"" + c + "\"/>";
  }
  return frame.finish();
}

}  // namespace cdpr::report
