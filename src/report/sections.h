#pragma once
// The pieces both reports (calibration: calibration_report.h; diagnosis:
// tools/cdpr-calib) are built from: the verdict card's lines and the plot
// sections, so that a solve and a diagnose report read alike.

#include <optional>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/diagnosis/held_out.h"
#include "src/report/residual_trends.h"

namespace cdpr::report {

// "catenary + elasticity + load_cell_bias" (rigid: "rigid").
std::string model_text(const std::vector<std::string>& model);
// Physical values of `names` from [effects] with their sigma and unit:
// "axial_stiffness = 1.49e+06 +- 2.1e+04 N".
std::string effect_values_text(const EffectValues& effects, const std::vector<std::string>& names);
// The unit of an [effects] value by name ("N", "m", "" for a factor).
std::string effect_unit(const std::string& name);
// How far the fitted anchors are from robot.toml's nominal ones and how
// well they are known: "mean 7.12 m, largest 9.87 m (anchor 2); sigma <= 3.1 mm".
std::string anchors_moved_text(const Robot& nominal, const Calibration& calibration);
// The largest distance between the anchors of two fits, in their sigmas:
// "largest 12.3 mm (anchor 1, 4.1 sigma)".
std::string anchors_shift_text(const Calibration& from, const Calibration& to);
// The suspect group `reading` belongs to (SensorReading::group), its
// members in `rejected` order: "encoder 2 or force"; "" when it was named alone.
std::string suspect_group_text(const std::vector<SensorReading>& rejected, const SensorReading& reading);
// Readings left out as gross errors, at most `shown` of them: "row 12
// encoder cable 2 +8.1 sigma; row 30 force +6.0 sigma (suspect group:
// force or encoder cable 3)"; "none".
std::string rejected_text(const std::vector<SensorReading>& rejected, int shown = 4);
// Every rejected reading as a table: row, sensor, cable, residual in sigmas,
// and a suspect-group column when any reading is in one.
std::string rejected_table(const std::vector<SensorReading>& rejected);

// Residual scatter plots: one row per (sensor, quantity) with one plot per
// evaluation side by side (before and after) on shared axes. Encoder and
// height residuals in mm, load-cell residuals in N; a colour per cable.
struct Evaluation {
  std::string caption;  // "before: catenary"
  const HeldOutEvaluation* held_out;
};
std::string residual_plots(const std::vector<Evaluation>& evaluations);
// Normalised residual histograms (encoders, load cell) against N(0, 1), one
// per evaluation, on shared axes.
std::string histogram_plots(const Robot& robot, const std::vector<Evaluation>& evaluations);
// The anchors from above: the layout, then one panel per anchor with its 1-
// and 3-sigma ellipses (x-y block of the fit's covariance), the nominal and
// (with a truth) the true position, all panels at one scale.
std::string anchor_plots(const Robot& nominal, const CalibrationResult& fit, const std::optional<Truth>& truth);
// Per-cable rms of the encoder residuals and the load cell's, one row per evaluation.
std::string rms_table(const std::vector<Evaluation>& evaluations);
// The `count` strongest residual trends as a table (sensor, against, change
// over the data, r, t, p).
std::string trends_table(const std::vector<Trend>& trends, int count);

}  // namespace cdpr::report
