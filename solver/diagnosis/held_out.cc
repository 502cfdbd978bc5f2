#include "solver/diagnosis/held_out.h"

#include <algorithm>
#include <cmath>

#include "solver/nls/factor_parameters.h"
#include "solver/calibration/pose_prior_factor.h"

namespace cdpr {

double HeldOutEvaluation::normalized_rms() const {
  return expected_chi2 > 0.0 ? std::sqrt(chi2 / expected_chi2) : 0.0;
}

namespace {

int tangent_dim(const Key& key) {
  switch (key.kind) {
    case VariableKind::kPose: return 6;
    case VariableKind::kReferenceForce: return 2;
    case VariableKind::kAnchor: return 3;
    case VariableKind::kOffset: return 1;
    case VariableKind::kEffect: return effect_dimension(static_cast<Effect>(key.index));
  }
  return 0;
}

// Column of each of the factor's keys in the training covariance, -1 for the pose's own variables.
std::vector<int> global_columns(const EffectPoseFactor& factor, const CalibrationResult& trained) {
  std::vector<int> columns;
  for (const Key& key : factor.keys()) {
    int column = 0, found = -1;
    for (const Key& global : trained.global_keys) {
      if (global == key) found = column;
      column += tangent_dim(global);
    }
    columns.push_back(found);
  }
  return columns;
}

// Adds one held-out pose's information on the globals to `h`: its
// residuals' Jacobian J = [J_l J_g] over its own variables l (pose 6,
// reference force 2) and the globals g, J_g^T J_g - J_g^T J_l (J_l^T J_l)^-1
// J_l^T J_g (l eliminated). Adds nothing when the pose cannot be evaluated.
void add_held_out_information(const EffectPoseFactor& factor, const PosePriorFactor& prior,
                              const std::vector<const double*>& blocks, const CalibrationResult& trained,
                              const std::vector<int>& global_column, Eigen::MatrixXd& h) {
  const int p = static_cast<int>(trained.global_covariance.rows());
  constexpr int kLocal = 8, kRows = EffectPoseFactor::kResidualDim + 6;
  Eigen::MatrixXd j_local = Eigen::MatrixXd::Zero(kRows, kLocal), j_global = Eigen::MatrixXd::Zero(kRows, p);
  const std::span<const Key> keys = factor.keys();
  std::vector<std::vector<double>> storage(keys.size());
  std::vector<double*> jacobians(keys.size());
  std::vector<int> dims(keys.size());
  for (std::size_t b = 0; b < keys.size(); ++b) {
    dims[b] = tangent_dim(keys[b]);
    storage[b].assign(EffectPoseFactor::kResidualDim * dims[b], 0.0);
    jacobians[b] = storage[b].data();
  }
  std::array<double, EffectPoseFactor::kResidualDim> residual;
  double cost = 0.0;
  if (!factor.evaluate(blocks.data(), residual.data(), jacobians.data(), &cost)) return;
  for (std::size_t b = 0; b < keys.size(); ++b) {
    for (int r = 0; r < EffectPoseFactor::kResidualDim; ++r) {
      for (int c = 0; c < dims[b]; ++c) {
        const double v = storage[b][r * dims[b] + c];
        if (b == 0) j_local(r, c) = v;
        else if (b == 1) j_local(r, 6 + c) = v;
        else if (global_column[b] >= 0) j_global(r, global_column[b] + c) = v;
      }
    }
  }
  std::array<double, 36> prior_jacobian{};
  double* prior_blocks[1] = {prior_jacobian.data()};
  std::array<double, 6> prior_residual;
  if (!prior.evaluate(blocks.data(), prior_residual.data(), prior_blocks, &cost)) return;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) j_local(EffectPoseFactor::kResidualDim + r, c) = prior_jacobian[r * 6 + c];
  }
  // No global unknowns (every anchor and offset held): nothing to add, and
  // Eigen's solve on an empty right-hand side binds a null reference.
  if (j_global.cols() == 0) return;
  const Eigen::MatrixXd lg = j_local.transpose() * j_global;
  h += j_global.transpose() * j_global - lg.transpose() * (j_local.transpose() * j_local).ldlt().solve(lg);
}

}  // namespace

double encoder_rms_m(const std::vector<HeldOutPose>& poses, int cable) {
  double sum = 0.0;
  int count = 0;
  for (const HeldOutPose& pose : poses) {
    for (int i = 0; i < kCableCount; ++i) {
      if ((cable >= 0 && i != cable) || pose.sample.encoder_left_out[i]) continue;
      sum += std::pow(pose.prediction.encoder_residual_m[i], 2);
      ++count;
    }
  }
  return std::sqrt(sum / std::max(1, count));
}

void set_residual_rms(HeldOutEvaluation& h) {
  double sum_height = 0.0, sum_force = 0.0;
  int force_count = 0;
  for (const HeldOutPose& pose : h.poses) {
    for (int i = 0; i < kCableCount; ++i) sum_height += std::pow(pose.prediction.height_residual_m[i], 2);
    if (pose.sample.force_left_out) continue;
    sum_force += std::pow(pose.prediction.force_residual_n, 2);
    ++force_count;
  }
  h.rms_encoder_m = encoder_rms_m(h.poses);
  h.rms_height_m = std::sqrt(sum_height / std::max<std::size_t>(1, kCableCount * h.poses.size()));
  h.rms_force_n = std::sqrt(sum_force / std::max(1, force_count));
}

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

  const Eigen::MatrixXd& sigma = trained.global_covariance;
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(sigma.rows(), sigma.cols());
  int residual_count = 0;
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    const int pose_index = static_cast<int>(k);
    const EffectPoseFactor factor(robot, pose_index, built.samples[k], options.height_sigma_m, Loss{}, options.effects);
    const std::vector<const double*> blocks = parameter_blocks(problem, factor);
    HeldOutPose pose{built.samples[k], problem.pose(PoseKey(pose_index)), {}, 0.0};
    const SampleSigmas sigma = reading_sigmas(robot, built.samples[k]);
    const PosePriorFactor prior(pose_index, {built.samples[k].position_world, built.samples[k].world_R_platform},
                                sigma.position_m, sigma.orientation_rad, Loss{});
    std::array<double, EffectPoseFactor::kResidualDim> residual;
    std::array<double, 6> prior_residual;
    double cost = 0.0, prior_cost = 0.0;
    if (!factor.predict(blocks.data(), pose.prediction) ||
        !factor.evaluate(blocks.data(), residual.data(), nullptr, &cost) ||
        !prior.evaluate(blocks.data(), prior_residual.data(), nullptr, &prior_cost)) {
      out.rejected_samples.push_back(built.samples[k].id);
      continue;
    }
    pose.chi2 = 2.0 * (cost + prior_cost);
    residual_count += EffectPoseFactor::kResidualDim + 6;  // + the pose prior
    add_held_out_information(factor, prior, blocks, trained, global_columns(factor, trained), information);
    out.poses.push_back(pose);
  }
  if (out.poses.empty()) {
    out.message = "no held-out pose could be evaluated";
    return out;
  }
  set_residual_rms(out);
  // The solver's cost is 0.5 chi2 over every factor (no robust loss here);
  // each pose has 8 unknowns of its own (pose 6, reference force 2).
  out.chi2 = 2.0 * summary.final_cost;
  out.dof = residual_count - 8 * static_cast<int>(out.poses.size());
  // The training fit's error d ~ N(0, Sigma) is shared by every pose of
  // this fold: chi2 = |e|^2 + 2 e'J_g d + d'H d over the held-out noise e,
  // so its mean is dof + tr(H Sigma) and its variance 2 dof + 4 tr(H Sigma)
  // + 2 tr((H Sigma)^2), more than a chi-square of that mean has.
  const Eigen::MatrixXd h_sigma = information * sigma;
  const double inflation = h_sigma.trace();
  out.expected_chi2 = out.dof + inflation;
  out.chi2_variance = 2.0 * out.dof + 4.0 * inflation + 2.0 * h_sigma.cwiseProduct(h_sigma.transpose()).sum();
  out.ok = true;
  return out;
}

}  // namespace cdpr
