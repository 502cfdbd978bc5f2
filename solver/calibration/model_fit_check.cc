#include "solver/calibration/model_fit_check.h"

#include <cmath>
#include <cstdio>

#include "solver/calibration/chi_square.h"

namespace cdpr {

void assess_model_fit(CalibrationResult& result, const CalibrationOptions& options) {
  Calibration& cal = result.calibration;
  const int globals = static_cast<int>(result.global_covariance.rows());
  char text[512];
  if (result.degrees_of_freedom < globals) {
    std::snprintf(text, sizeof text,
                  "under-determined: %d samples leave %d redundant rows for %d global unknowns (anchors, offsets, "
                  "model terms); the sigmas are large and may not hold; add poses",
                  cal.samples, result.degrees_of_freedom, globals);
    result.misfit = true;
    cal.model_warning = text;
    return;
  }
  result.misfit_probability = chi_square_upper_tail(result.chi_square, result.degrees_of_freedom);
  if (result.misfit_probability >= options.misfit_alpha) return;
  const double ratio = result.chi_square / result.degrees_of_freedom;
  const double scale = std::sqrt(ratio);
  std::snprintf(text, sizeof text,
                "the model does not fit the data: chi-square %.1f for %d degrees of freedom (%.2f times the noise "
                "of robot.toml, p = %.1e < %.0e); rms encoder %.4f m, rms force %.2f N; sigmas scaled up by %.2f. "
                "A hidden effect (elasticity, centre of mass, density, load cell, ...) or wrong noise sigmas: run "
                "cdpr-calib diagnose",
                result.chi_square, result.degrees_of_freedom, ratio, result.misfit_probability, options.misfit_alpha,
                cal.fit.rms_encoder_m, cal.fit.rms_force_n, scale);
  result.misfit = true;
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
