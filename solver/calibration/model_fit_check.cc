#include "solver/calibration/model_fit_check.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "solver/calibration/chi_square.h"

namespace cdpr {

namespace {

// chi2 / dof above which a misfit is a fit that did not reach the readings
// (rms normalised residual 100).
constexpr double kUnreachedChiSquareRatio = 1e4;

// What a fit that did not reach its minimum asks of the user.
constexpr const char* kStartAdvice = "nominal anchors closer to the truth, more poses, or check the readings";

}  // namespace

const char* misfit_advice(MisfitCause cause) {
  switch (cause) {
    case MisfitCause::kNone: return "";
    case MisfitCause::kUnderDetermined: return "add poses, spread over the workspace";
    case MisfitCause::kNotConverged:
    case MisfitCause::kUnreached: return kStartAdvice;
    case MisfitCause::kModel: return "run cdpr-calib diagnose on the same data to find the missing model term";
  }
  return "";
}

void assess_model_fit(CalibrationResult& result, const CalibrationOptions& options) {
  Calibration& cal = result.calibration;
  const int globals = static_cast<int>(result.global_covariance.rows());
  char text[640];
  if (result.degrees_of_freedom < globals) {
    std::snprintf(text, sizeof text,
                  "under-determined: %d samples leave %d redundant rows for %d global unknowns (anchors, offsets, "
                  "model terms); the sigmas are large and may not hold; add poses",
                  cal.samples, result.degrees_of_freedom, globals);
    result.misfit = true;
    result.misfit_cause = MisfitCause::kUnderDetermined;
    cal.model_warning = text;
    return;
  }
  result.misfit_probability = chi_square_upper_tail(result.chi_square, result.degrees_of_freedom);
  const bool stopped = result.solver.termination == TerminationType::kMaxIterations;
  if (stopped) {
    std::snprintf(text, sizeof text,
                  "not converged: the solver stopped at its iteration limit (%d iterations), not at a minimum "
                  "(chi-square %.1f for %d degrees of freedom, p = %.1e); the anchors and their sigmas do not hold: "
                  "%s",
                  result.solver.iterations, result.chi_square, result.degrees_of_freedom, result.misfit_probability,
                  kStartAdvice);
    result.misfit = true;
    result.misfit_cause = MisfitCause::kNotConverged;
    cal.model_warning = text;
  }
  if (result.misfit_probability >= options.misfit_alpha) return;
  const double ratio = result.chi_square / result.degrees_of_freedom;
  const double scale = std::sqrt(ratio);
  // Residuals far beyond what any missing model term leaves (a weightless
  // cable fitted as a catenary: chi2 / dof about 100) say the fit did not
  // reach the readings, not that the model lacks a term.
  const std::string why =
      stopped ? std::string("The solver stopped at its iteration limit, not at a minimum: ") + kStartAdvice
      : ratio > kUnreachedChiSquareRatio
          ? std::string("No missing model term leaves residuals this large: the fit did not reach the readings; the "
                        "anchors and their sigmas mean nothing: ") + kStartAdvice + " (readings of taut cables?)"
          : std::string("A hidden effect (elasticity, centre of mass, density, load cell, ...) or wrong noise sigmas: "
                        "run cdpr-calib diagnose");
  std::snprintf(text, sizeof text,
                "the model does not fit the data: chi-square %.1f for %d degrees of freedom (%.2f times the noise "
                "of robot.toml, p = %.1e < %.0e); rms encoder %.4f m, rms force %.2f N; sigmas scaled up by %.2f. %s",
                result.chi_square, result.degrees_of_freedom, ratio, result.misfit_probability, options.misfit_alpha,
                cal.fit.rms_encoder_m, cal.fit.rms_force_n, scale, why.c_str());
  result.misfit = true;
  if (!stopped) result.misfit_cause = ratio > kUnreachedChiSquareRatio ? MisfitCause::kUnreached : MisfitCause::kModel;
  cal.model_warning = text;
  for (WinchCalibration& w : cal.winches) {
    w.anchor_sigma *= scale;
    w.offset_sigma_m *= scale;
  }
  for (FittedEffect& e : result.effects) {
    for (double& sigma : e.sigma) sigma *= scale;
  }
  for (auto& [name, values] : cal.effects) {
    if (name.size() > 6 && name.ends_with("_sigma")) {
      for (double& v : values) v *= scale;
    }
  }
  result.global_covariance *= ratio;
}

}  // namespace cdpr
