#pragma once
// Residual structure on held-out (or fitted) poses: each sensor's residuals
// against the quantities an unmodelled effect would scale with (cable
// length, tension, platform height) and against the sample order, the time
// of the run (a slipping encoder, a drifting load cell), as a straight-line
// trend with its significance. Pure functions of a HeldOutEvaluation,
// shared by the text and HTML reports.

#include <string>
#include <vector>

#include "solver/diagnosis/held_out.h"

namespace cdpr::report {

inline constexpr const char* kSampleOrder = "sample order";

// One residual channel of the poses: (x, residual) pairs.
struct ResidualSeries {
  std::string sensor;    // "encoder 2", "height 0", "load cell"
  std::string against;   // "cable length [m]", "cable tension [N]", "platform height [m]", kSampleOrder
  std::string unit;      // of the residual: "m" or "N"
  int cable = -1;        // of an encoder or height channel; -1 for the load cell
  std::vector<double> x, residual;
};

// Every (sensor, quantity) series the reports look at. Sample order is the
// samples.csv id (the daemon numbers a run's samples in the order it
// measured them).
std::vector<ResidualSeries> residual_series(const HeldOutEvaluation& held_out);

struct Trend {
  std::string sensor, against, unit;
  int cable = -1;
  double slope = 0.0;        // residual unit per x unit
  double correlation = 0.0;  // Pearson r
  double t_statistic = 0.0;  // r sqrt((n - 2) / (1 - r^2))
  double p_value = 1.0;      // two-sided, of t with n - 2 degrees of freedom (normal approximation)
  double x_span = 0.0;       // max x - min x: slope * x_span is the change over the data
  int count = 0;
};

// Least-squares line of each series, strongest |t| first.
std::vector<Trend> residual_trends(const HeldOutEvaluation& held_out);

// The strongest trend in words, with the other encoders that show one
// against the same quantity (p below alpha over the number of trends), e.g.
// "encoder residuals grow with sample order on cables 0 and 3 (cable 0:
// +41 mm over the run, t = +9.2, p = 2e-12)". Empty without trends.
std::string strongest_trend_text(const std::vector<Trend>& trends, double alpha = 0.01);

// Normalised residuals (residual / the reading's sigma) of the encoders of
// all cables and of the load cell, for histograms against N(0, 1).
struct NormalisedResiduals {
  std::vector<double> encoder, force;
};
NormalisedResiduals normalised_residuals(const Robot& robot, const HeldOutEvaluation& held_out);

}  // namespace cdpr::report
