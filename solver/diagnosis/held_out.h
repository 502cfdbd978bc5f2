#pragma once
// How well a calibration predicts poses it was not fitted to: the global
// parameters (anchors, offsets, model terms) are held at their fitted values
// and only each held-out pose's own variables (pose, reference force) are
// solved, so the remaining misfit is what the model cannot explain.

#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/nls/pose.h"

namespace cdpr {

struct HeldOutPose {
  Sample sample;
  Pose world_T_platform;  // fitted
  PosePrediction prediction;
  double chi2 = 0.0;  // this pose's squared whitened residuals, pose prior included
};

struct HeldOutEvaluation {
  bool ok = false;
  std::string message;           // why it failed
  std::vector<HeldOutPose> poses;  // the poses the model could be evaluated at
  std::vector<int> rejected_samples;
  // Sum of squared whitened residuals (sensor, height and pose-prior) and its
  // degrees of freedom: residual count minus the per-pose unknowns.
  double chi2 = 0.0;
  int dof = 0;
  // The residuals' rms over `poses` (set_residual_rms).
  double rms_encoder_m = 0.0;
  double rms_height_m = 0.0;
  double rms_force_n = 0.0;
  // What chi2 would be on average if the model were right: dof plus the
  // misfit the training fit's own uncertainty causes, tr(H_held_out Sigma_train)
  // (H: the held-out poses' information on the global parameters with their
  // own variables eliminated; Sigma: the training covariance).
  double expected_chi2 = 0.0;
  // chi2's variance if the model were right: the training fit's error is
  // shared by all the poses of a fold, so it is more than 2 expected_chi2.
  // Folds are pooled as if independent.
  double chi2_variance = 0.0;
  // sqrt(chi2 / expected_chi2): 1 at the noise floor.
  double normalized_rms() const;
};

// The rms of the held-out encoder residuals of the readings the fits used
// (a reading left out as a gross error is predicted too, but is no evidence
// of misfit): every cable's, or cable `cable`'s alone. 0 with none.
double encoder_rms_m(const std::vector<HeldOutPose>& poses, int cable = -1);
// Sets h's rms_encoder_m, rms_height_m and rms_force_n from h.poses (the
// encoders and the load cell as encoder_rms_m: readings used only).
void set_residual_rms(HeldOutEvaluation& h);

// `trained` must be an ok result of calibrate() with the same options
// (cable model catenary; options.effects in the same order as trained.effects).
HeldOutEvaluation evaluate_held_out(const Robot& robot, const std::vector<Sample>& held_out,
                                    const CalibrationOptions& options, const CalibrationResult& trained);

}  // namespace cdpr
