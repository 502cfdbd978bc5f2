#include "solver/operation/rest_evidence.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <Eigen/Dense>

#include "solver/calibration/effect_pose_factor.h"
#include "solver/nls/levenberg_marquardt.h"
#include "solver/nls/problem.h"
#include "solver/operation/calibration_variables.h"
#include "solver/operation/rest_problem.h"

namespace cdpr {
namespace {

constexpr int kNuisance = 8;  // the rest's pose (6) and reference force (2)
constexpr int kOffsetColumn = 0, kAnchorColumn = 4, kElongationColumn = 16, kLoadColumn = 20, kBiasColumn = 24;

// The effects of the check factor: the calibration's, plus encoder scale
// and centre-of-mass offset (zero when the calibration has none), whose
// derivatives are the elongation and centre-of-mass columns.
std::vector<Effect> check_effects(std::vector<Effect> effects) {
  for (Effect e : {Effect::kEncoderScale, Effect::kComOffset}) {
    if (std::find(effects.begin(), effects.end(), e) == effects.end()) effects.push_back(e);
  }
  return effects;
}

// One factor's whitened residuals and Jacobian blocks at the problem's values.
struct Evaluation {
  Eigen::VectorXd residual;
  std::vector<Eigen::MatrixXd> blocks;  // per key, residual_dim x tangent dim
};

std::optional<Evaluation> evaluate(const Problem& problem, const Factor& factor, bool with_jacobians) {
  const auto keys = factor.keys();
  std::vector<const double*> parameters;
  Evaluation out;
  out.residual.resize(factor.residual_dim());
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> row_major;
  std::vector<double*> jacobians;
  for (const Key& key : keys) {
    const Problem::Variable& v = problem.variables()[problem.variable_index(key)];
    parameters.push_back(problem.state().data() + v.ambient_offset);
    row_major.emplace_back(factor.residual_dim(), v.tangent_dim);
  }
  for (auto& block : row_major) jacobians.push_back(block.data());
  double cost = 0.0;
  if (!factor.evaluate(parameters.data(), out.residual.data(), with_jacobians ? jacobians.data() : nullptr, &cost)) {
    return std::nullopt;
  }
  if (with_jacobians) {
    for (const auto& block : row_major) out.blocks.emplace_back(block);
  }
  return out;
}

}  // namespace

std::optional<RestEvidence> rest_evidence(const RestEvidenceInputs& in, const Sample& rest, const Pose& start,
                                          const Eigen::Vector2d& start_force, int rest_index, std::string* why) {
  const std::vector<Effect> effects = check_effects(in.calibration_effects);
  Problem problem;
  problem.add_pose(PoseKey(0), start);
  problem.add_vector(ReferenceForceKey(0), start_force);
  if (!add_calibration_variables(problem, *in.calibration, in.calibration_effects,
                                 CalibrationUncertainty::kHeldConstant, why)) {
    return std::nullopt;
  }
  for (Effect e : effects) {
    if (problem.has(EffectKey(e))) continue;
    problem.add_vector(EffectKey(e), Eigen::VectorXd::Zero(effect_dimension(e)));
    problem.set_constant(EffectKey(e));
  }
  const bool with_pose = in.use_measured_pose && has_measured_pose(rest);
  problem.add_factor(std::make_unique<EffectPoseFactor>(*in.robot, 0, rest, in.height_sigma_m, Loss{}, effects));
  if (with_pose) problem.add_factor(make_measured_pose_factor(*in.robot, 0, rest));
  {
    SolverOptions solver_options;
    solver_options.max_iterations = 50;
    LevenbergMarquardt lm(problem, solver_options);
    const SolverSummary summary = lm.solve();
    if (!summary.usable()) {
      if (why) *why = "the check fit failed: " + summary.message;
      return std::nullopt;
    }
  }

  // Stack the rows: the rest factor's 9, then the measured pose's 6.
  const Factor& rest_factor = *problem.factors()[0];
  const std::optional<Evaluation> cables = evaluate(problem, rest_factor, true);
  const EffectPoseFactor heavier_factor(*in.heavier, 0, rest, in.height_sigma_m, Loss{}, effects);
  const std::optional<Evaluation> heavier = evaluate(problem, heavier_factor, false);
  std::optional<Evaluation> pose_prior;
  if (with_pose) pose_prior = evaluate(problem, *problem.factors()[1], true);
  if (!cables || !heavier || (with_pose && !pose_prior)) {
    if (why) *why = "the model cannot be evaluated at the check fit";
    return std::nullopt;
  }
  const int m_cables = static_cast<int>(cables->residual.size());
  const int m = m_cables + (with_pose ? 6 : 0);
  Eigen::VectorXd r(m);
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(m, kNuisance);
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(m, kFaultColumns);
  r.head(m_cables) = cables->residual;
  N.topLeftCorner(m_cables, 6) = cables->blocks[0];
  N.block(0, 6, m_cables, 2) = cables->blocks[1];
  for (int i = 0; i < kCableCount; ++i) {
    G.block(0, kAnchorColumn + 3 * i, m_cables, 3) = cables->blocks[2 + i];
    G.col(kOffsetColumn + i).head(m_cables) = cables->blocks[2 + kCableCount + i];
  }
  const auto slot = [&](Effect e) {
    return 2 + 2 * kCableCount + static_cast<int>(std::find(effects.begin(), effects.end(), e) - effects.begin());
  };
  // Elongation e of cable i: the cable longer than the encoder counts by e
  // at the reference payout, i.e. encoder scale s_i = -e / L_ref.
  G.block(0, kElongationColumn, m_cables, kCableCount) =
      -cables->blocks[slot(Effect::kEncoderScale)] / in.reference_payout_m;
  G.block(0, kLoadColumn + 1, m_cables, 3) = cables->blocks[slot(Effect::kComOffset)];
  G.col(kLoadColumn).head(m_cables) = (heavier->residual - cables->residual) / in.mass_step_kg;
  const SampleSigmas sigma = reading_sigmas(*in.robot, rest);
  G(2 * kCableCount, kBiasColumn) = 1.0 / sigma.force_n;  // Eq. (16): the bias adds to the reading's model
  if (with_pose) {
    r.tail(6) = pose_prior->residual;
    N.bottomLeftCorner(6, 6) = pose_prior->blocks[0];
  }

  // Project off the rest's own pose and force: G~ = (I - N (N^T N)^-1 N^T) G.
  const Eigen::LDLT<Eigen::MatrixXd> normal(N.transpose() * N);
  if (normal.info() != Eigen::Success || !normal.isPositive()) {
    if (why) *why = "the rest's pose is not observable in the check fit";
    return std::nullopt;
  }
  const Eigen::MatrixXd G_projected = G - N * normal.solve(N.transpose() * G);
  const Eigen::MatrixXd hat = N * normal.solve(N.transpose());

  RestEvidence out;
  out.used_measured_pose = with_pose;
  out.information.rest = rest_index;
  // r ~ r_true - G theta for a change theta of the terms: the score is -G~^T r.
  out.information.score = -(G_projected.transpose() * r);
  out.information.information = G_projected.transpose() * G_projected;
  const auto standardised = [&](int row) {
    const double leverage = std::min(hat(row, row), 1.0 - 1e-9);
    return r(row) / std::sqrt(1.0 - leverage);
  };
  for (int i = 0; i < kCableCount; ++i) out.encoder_residual_sigma[i] = standardised(i);
  out.force_residual_sigma = standardised(2 * kCableCount);
  return out;
}

}  // namespace cdpr
