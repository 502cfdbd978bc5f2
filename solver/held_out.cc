#include "solver/held_out.h"

#include <cmath>

#include "solver/factor_parameters.h"

namespace cdpr {

double HeldOutEvaluation::normalized_rms() const { return dof > 0 ? std::sqrt(chi2 / dof) : 0.0; }

HeldOutEvaluation evaluate_held_out(const Robot& robot, const std::vector<Sample>& held_out,
                                    const CalibrationOptions& options, const CalibrationResult& trained) {
  HeldOutEvaluation out;
  if (!trained.ok || trained.calibration.winches.size() != kCableCount ||
      trained.effects.size() != options.effects.size()) {
    out.message = "the training fit has no usable result";
    return out;
  }
  // Pose starts from the fitted anchors, as in any calibration.
  Robot fitted = robot;
  for (int i = 0; i < kCableCount; ++i) fitted.winches[i].anchor_world = trained.calibration.winches[i].anchor_world;
  CalibrationOptions held = options;
  held.progress = nullptr;
  BuiltProblem built = build_calibration_problem(fitted, held_out, held);
  out.rejected_samples = built.rejected_samples;
  if (!built.problem) {
    out.message = "held-out poses: " + built.message;
    return out;
  }
  Problem& problem = *built.problem;
  for (int i = 0; i < kCableCount; ++i) {
    problem.set_vector(OffsetKey(i), Eigen::Matrix<double, 1, 1>(trained.calibration.winches[i].offset_m));
    problem.set_constant(AnchorKey(i));
    problem.set_constant(OffsetKey(i));
  }
  for (const FittedEffect& e : trained.effects) {
    problem.set_vector(EffectKey(e.effect), Eigen::Map<const Eigen::VectorXd>(e.value.data(), e.value.size()));
    problem.set_constant(EffectKey(e.effect));
  }

  SolverOptions solver_options;
  solver_options.max_iterations = options.max_iterations;
  LevenbergMarquardt lm(problem, solver_options);
  const SolverSummary summary = lm.solve();
  if (!summary.usable()) {
    out.message = "held-out poses: " + summary.message;
    return out;
  }

  double sum_encoder = 0.0, sum_height = 0.0, sum_force = 0.0;
  int residual_count = 0;
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    const int pose_index = static_cast<int>(k);
    const EffectPoseFactor factor(robot, pose_index, built.samples[k], options.height_sigma_m, Loss{}, options.effects);
    const std::vector<const double*> blocks = parameter_blocks(problem, factor);
    HeldOutPose pose{built.samples[k], problem.pose(PoseKey(pose_index)), {}};
    if (!factor.predict(blocks.data(), pose.prediction)) {
      out.rejected_samples.push_back(built.samples[k].id);
      continue;
    }
    for (int i = 0; i < kCableCount; ++i) {
      sum_encoder += std::pow(pose.prediction.encoder_residual_m[i], 2);
      sum_height += std::pow(pose.prediction.height_residual_m[i], 2);
    }
    sum_force += std::pow(pose.prediction.force_residual_n, 2);
    residual_count += EffectPoseFactor::kResidualDim + 6;  // + the pose prior
    out.poses.push_back(pose);
  }
  if (out.poses.empty()) {
    out.message = "no held-out pose could be evaluated";
    return out;
  }
  const double n = static_cast<double>(out.poses.size());
  out.rms_encoder_m = std::sqrt(sum_encoder / (kCableCount * n));
  out.rms_height_m = std::sqrt(sum_height / (kCableCount * n));
  out.rms_force_n = std::sqrt(sum_force / n);
  // The solver's cost is 0.5 chi2 over every factor (no robust loss here);
  // each pose has 8 unknowns of its own (pose 6, reference force 2).
  out.chi2 = 2.0 * summary.final_cost;
  out.dof = residual_count - 8 * static_cast<int>(out.poses.size());
  out.ok = true;
  return out;
}

}  // namespace cdpr
