#pragma once
// Residual structure on held-out poses: each sensor's residuals against the
// quantities an unmodelled effect would scale with (cable length, tension,
// platform height), as a straight-line trend with its significance. A pure
// function of a HeldOutEvaluation, shared by the text and HTML reports.

#include <string>
#include <vector>

#include "solver/diagnosis/held_out.h"

namespace cdpr::tools {

// One residual channel of the held-out poses: (x, residual) pairs.
struct ResidualSeries {
  std::string sensor;    // "encoder 2", "height 0", "load cell"
  std::string against;   // "cable length [m]", "tension [N]", "platform height [m]"
  std::string unit;      // of the residual: "m" or "N"
  std::vector<double> x, residual;
};

// Every (sensor, quantity) series the reports look at.
std::vector<ResidualSeries> residual_series(const HeldOutEvaluation& held_out);

struct Trend {
  std::string sensor, against, unit;
  double slope = 0.0;        // residual unit per x unit
  double correlation = 0.0;  // Pearson r
  double t_statistic = 0.0;  // r sqrt((n - 2) / (1 - r^2))
};

// Least-squares line of each series, strongest |t| first.
std::vector<Trend> residual_trends(const HeldOutEvaluation& held_out);

}  // namespace cdpr::tools
