#include "src/calibration/fit_validation.h"

#include <cmath>

#include "src/calibration/message_text.h"

namespace cdpr::calibration {
namespace {

std::string significant3(double value) { return significant(value, 3); }

bool all_finite(const WinchCalibration& winch) {
  return winch.anchor_world.allFinite() && winch.anchor_sigma.allFinite() && std::isfinite(winch.offset_m) &&
         std::isfinite(winch.offset_sigma_m);
}

void check_residuals(const FitSummary& fit, const NoiseSigmas& noise, const ValidationLimits& limits,
                     std::vector<std::string>& reasons) {
  const double encoder_limit_m = limits.max_rms_encoder_sigmas * noise.encoder_m;
  if (!(fit.rms_encoder_m <= encoder_limit_m)) {
    reasons.push_back("encoder residual rms " + significant3(fit.rms_encoder_m) + " m exceeds " +
                      significant3(limits.max_rms_encoder_sigmas) + " sigma (" + significant3(encoder_limit_m) + " m)");
  }
  const double force_limit_n = limits.max_rms_force_sigmas * noise.force_n;
  if (!(fit.rms_force_n <= force_limit_n)) {
    reasons.push_back("force residual rms " + significant3(fit.rms_force_n) + " N exceeds " +
                      significant3(limits.max_rms_force_sigmas) + " sigma (" + significant3(force_limit_n) + " N)");
  }
}

void check_winch(int i, const WinchCalibration& winch, const Calibration* previous, const ValidationLimits& limits,
                 std::vector<std::string>& reasons) {
  const std::string cable = "cable " + std::to_string(i);
  if (!all_finite(winch)) {
    reasons.push_back(cable + ": non-finite anchor, offset or sigma");
    return;
  }
  if (!(winch.anchor_sigma.maxCoeff() <= limits.max_anchor_sigma_m)) {
    reasons.push_back(cable + ": anchor sigma " + significant3(winch.anchor_sigma.maxCoeff()) + " m above " +
                      significant3(limits.max_anchor_sigma_m) + " m (poorly observed: more or wider waypoints)");
  }
  if (!(winch.offset_sigma_m <= limits.max_offset_sigma_m)) {
    reasons.push_back(cable + ": offset sigma " + significant3(winch.offset_sigma_m) + " m above " +
                      significant3(limits.max_offset_sigma_m) + " m");
  }
  if (previous && limits.max_anchor_change_m > 0.0 && i < static_cast<int>(previous->winches.size())) {
    const double change_m = (winch.anchor_world - previous->winches[i].anchor_world).norm();
    if (!(change_m <= limits.max_anchor_change_m)) {
      reasons.push_back(cable + ": anchor moved " + significant3(change_m) + " m since the previous calibration (limit " +
                        significant3(limits.max_anchor_change_m) + " m)");
    }
  }
}

}  // namespace

std::string ValidationResult::summary() const {
  if (accepted()) return "accepted";
  std::string text;
  for (const std::string& reason : reasons) text += (text.empty() ? "" : "; ") + reason;
  return text;
}

ValidationResult validate_fit(const CalibrationResult& result, const Robot& robot, const Calibration* previous,
                              const ValidationLimits& limits) {
  ValidationResult validation;
  std::vector<std::string>& reasons = validation.reasons;
  if (!result.ok) {
    reasons.push_back("solve failed: " + result.message);
    return validation;
  }
  const bool converged =
      result.solver.termination == TerminationType::kConverged ||
      (limits.accept_max_iterations && result.solver.termination == TerminationType::kMaxIterations);
  if (!converged) reasons.push_back("solver did not converge: " + result.solver.message);

  const Calibration& calibration = result.calibration;
  if (static_cast<int>(calibration.winches.size()) != robot.cable_count()) {
    reasons.push_back("calibration has " + std::to_string(calibration.winches.size()) + " cables, robot has " +
                      std::to_string(robot.cable_count()));
    return validation;
  }
  if (calibration.samples < limits.min_samples) {
    reasons.push_back("only " + std::to_string(calibration.samples) + " samples (at least " +
                      std::to_string(limits.min_samples) + " needed)");
  }
  check_residuals(calibration.fit, robot.noise, limits, reasons);
  if (!calibration.model_warning.empty()) reasons.push_back(calibration.model_warning);
  for (int i = 0; i < robot.cable_count(); ++i) check_winch(i, calibration.winches[i], previous, limits, reasons);
  return validation;
}

void stamp_for_commit(Calibration& calibration, const Robot& robot, std::size_t samples,
                      const std::function<std::string()>& utc_now_text) {
  if (utc_now_text) calibration.created = utc_now_text();
  if (calibration.created.empty()) calibration.created = "1970-01-01T00:00:00Z";
  calibration.robot = robot.name;
  calibration.samples = static_cast<int>(samples);
}

}  // namespace cdpr::calibration
