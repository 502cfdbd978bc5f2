#pragma once
// Inline-SVG plots for the reports, written here rather than by a plotting
// library: the reports must be self-contained files with no script (the
// daemon writes them on a robot controller; a reader may open them offline),
// and the few plot kinds needed (scatter, histogram, anchor top view) are a
// few hundred lines with full control over ticks, clipping and print size.
//
// Every plot: 1-2-5 ticks (ticks.h) with the unit in the axis label, the
// frame widened to the ticks so no point is clipped, a zero line, one colour
// per cable (series colour = cable index), the legend in a column right of
// the frame, never over the data. A viewBox and max-width: 100% let the
// page scale each plot down to the screen or the A4 page. Data marks carry
// class="data", so the browser check (tools/check-report) can tell an empty
// plot from one whose only shapes are its legend and reference curves.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "src/report/ticks.h"

namespace cdpr::report {

// Colour of cable i (i >= 0), of the load cell (kLoadCellColour) and of
// anything else (kNeutralColour).
inline constexpr int kLoadCellColour = 4;
inline constexpr int kNeutralColour = 5;
const char* series_colour(int index);

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;
  int colour = kNeutralColour;
};

struct PlotSpec {
  std::string title, x_label, y_label;  // labels with their unit: "residual [mm]"
  // Axis ticks; when empty, from the data. Give the same ticks to plots
  // that are compared (before and after) so they share the scale.
  std::optional<Ticks> x_ticks, y_ticks;
  int width = 440, height = 270;  // [px] before scaling
};

// Range [min, max] of the finite x (or y) values of all series; nullopt when none.
std::optional<std::pair<double, double>> data_range(const std::vector<PlotSeries>& series, bool x);
// 1-2-5 ticks over the data of several plots: one shared axis.
Ticks shared_ticks(const std::vector<const std::vector<PlotSeries>*>& plots, bool x);

// `<svg ...>...</svg>`: dots; empty series skipped, non-finite points dropped.
std::string svg_scatter(const PlotSpec& spec, const std::vector<PlotSeries>& series);

// Histogram of normalised residuals (each in sigmas) as a density over
// [-5, 5] in half-sigma bins (values beyond count in the edge bins), with
// the standard normal density over it: a right model and right sigmas put
// the bars on the curve.
std::string svg_normal_histogram(const PlotSpec& spec, const std::vector<double>& normalised, int colour);
// Highest density svg_normal_histogram draws for these values (bars or curve).
double normal_histogram_peak(const std::vector<double>& normalised);

// One anchor seen from above: the fitted position (centre) with its 1- and
// 3-sigma ellipses from the x-y covariance [m^2], the nominal position and
// (simulated data) the true one, as offsets from the fitted position. A
// point outside the frame is drawn as an arrow on the edge with its distance.
struct AnchorTopView {
  std::string name;  // "anchor 0"
  int colour = 0;
  Eigen::Vector2d fitted = Eigen::Vector2d::Zero(), nominal = Eigen::Vector2d::Zero();
  std::optional<Eigen::Vector2d> truth;
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
};
// The half-width [m] a panel needs to show the 3-sigma ellipse; give the
// largest over the anchors to every panel so they share one scale.
double anchor_view_half_width(const AnchorTopView& anchor);
std::string svg_anchor_top_view(const AnchorTopView& anchor, double half_width_m);
// All anchors at true scale, nominal (open) and fitted (filled), the x-y
// layout of the robot at a glance.
std::string svg_anchor_layout(const std::vector<AnchorTopView>& anchors);

}  // namespace cdpr::report
