#pragma once
// The report of one calibration (`cdpr-calib solve --report`, and the
// daemon beside each committed calibration): a verdict card (model, fitted
// terms, misfit against the noise, how far the anchors moved, rejected
// readings, one-line conclusion), then the anchors from above, the
// residuals of the fit and, collapsed, the numbers.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/diagnosis/held_out.h"

namespace cdpr::report {

struct CalibrationReport {
  std::string title;               // "Calibration of robot large"
  const Robot* nominal = nullptr;  // robot.toml the fit started from
  const CalibrationResult* fit = nullptr;  // ok
  // The fit's residuals at its own samples (fitted_residuals); not ok: no residual plots.
  const HeldOutEvaluation* residuals = nullptr;
  std::optional<Truth> truth;      // simulated data: errors against it
  // Lines about the run that produced the data (the daemon's run.toml:
  // robot time, waypoints planned, sampled, skipped and why), shown on the card.
  std::vector<std::pair<std::string, std::string>> run_facts;
};

// The residuals of `fit` at `samples`: each pose re-solved with the fit's
// anchors, offsets and terms held (solver/diagnosis/held_out.h). Needs the
// catenary model; otherwise not ok, with the reason.
HeldOutEvaluation fitted_residuals(const Robot& robot, const std::vector<Sample>& samples,
                                   const CalibrationOptions& options, const CalibrationResult& fit);

std::string calibration_report_html(const CalibrationReport& report);

// The report of a finished fit of `robot` to `samples` (as made with
// `options`), titled "Calibration of robot <name>", with its residuals
// (fitted_residuals): what `cdpr-calib solve --report` and the daemon write.
// `facts`: lines about the data (its files, or the run that measured it).
std::string fitted_calibration_report_html(const Robot& robot, const std::vector<Sample>& samples,
                                           const CalibrationOptions& options, const CalibrationResult& fit,
                                           const std::optional<Truth>& truth,
                                           std::vector<std::pair<std::string, std::string>> facts);

}  // namespace cdpr::report
