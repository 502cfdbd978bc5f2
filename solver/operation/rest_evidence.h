#pragma once
// What one rest says about the calibration's terms (solver/operation/health_watch.h):
// the check fit of the rest (its kineto-static factor and, when asked, its
// measured pose; the pose and reference force free, the calibration held
// fixed), its standardised residuals, and the whitened derivatives of its
// residuals by every fault term projected off the rest's own pose and force.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "solver/model/calibration.h"
#include "solver/model/effects.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/nls/pose.h"
#include "solver/operation/health_watch.h"

namespace cdpr {

struct RestEvidenceInputs {
  const Robot* robot = nullptr;
  const Robot* heavier = nullptr;  // robot with the platform mass + mass_step_kg
  double mass_step_kg = 0.0;
  const Calibration* calibration = nullptr;
  std::vector<Effect> calibration_effects;
  double height_sigma_m = 1e-2;
  bool use_measured_pose = true;
  double reference_payout_m = 1.0;  // elongation columns: metres at this payout
};

struct RestEvidence {
  RestInformation information;
  std::array<double, kCableCount> encoder_residual_sigma{};
  double force_residual_sigma = 0.0;
  bool used_measured_pose = false;
};

// The check fit from `start` (pose and reference force). Empty with *why
// when it cannot be evaluated or solved.
std::optional<RestEvidence> rest_evidence(const RestEvidenceInputs& in, const Sample& rest, const Pose& start,
                                          const Eigen::Vector2d& start_force, int rest_index, std::string* why);

}  // namespace cdpr
