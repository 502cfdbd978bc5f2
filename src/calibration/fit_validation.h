#pragma once
// Accepts or refuses a calibration before it may replace the stored one
// (docs/DESIGN.md, data flow step 6). A refused fit is never committed;
// every reason is stated so the operator knows what to fix (more waypoints,
// a loose cable, a moved pulley, a noisy sensor).
//
// Checks, each with its own reason when it fails:
//  - the solver converged (kConverged; kMaxIterations only if allowed);
//  - one result per cable, every value finite, enough samples;
//  - residuals consistent with the sensor noise of robot.toml [noise]:
//    rms_encoder <= max_rms_encoder_sigmas * noise.encoder, same for force;
//  - the model fits (calibrate()'s model-fit test: no model_warning);
//  - uncertainty small: every anchor_sigma axis and offset_sigma below limits;
//  - plausible change from the previous calibration: each anchor moved at
//    most max_anchor_change_m (a pulley does not wander metres between
//    calibrations; a big jump means a bad fit or a mechanical problem that a
//    person must look at). Offsets are not compared: re-homing an encoder
//    legitimately changes them.
// Pure logic.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/model/calibration.h"
#include "solver/model/robot.h"

namespace cdpr::calibration {

struct ValidationLimits {
  bool accept_max_iterations = false;  // accept a fit that ran out of iterations
  int min_samples = 10;
  double max_rms_encoder_sigmas = 3.0;
  double max_rms_force_sigmas = 3.0;
  double max_anchor_sigma_m = 0.05;    // per axis, 1-sigma [m]
  double max_offset_sigma_m = 0.05;    // 1-sigma [m]
  double max_anchor_change_m = 0.5;    // |anchor - previous anchor| per cable [m]; <= 0: not checked
};

struct ValidationResult {
  std::vector<std::string> reasons;  // empty when accepted
  bool accepted() const { return reasons.empty(); }
  // "accepted", or the reasons joined by "; "
  std::string summary() const;
};

// `previous` may be null (first calibration).
ValidationResult validate_fit(const CalibrationResult& result, const Robot& robot, const Calibration* previous,
                              const ValidationLimits& limits);

// Fills in what a validated fit needs before the store commits it: `created`
// from utc_now_text (the epoch when it gives nothing), the robot's name and
// the number of samples fitted.
void stamp_for_commit(Calibration& calibration, const Robot& robot, std::size_t samples,
                      const std::function<std::string()>& utc_now_text);

}  // namespace cdpr::calibration
