#include "solver/calibration/term_tests.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "solver/calibration/absent_term_columns.h"
#include "solver/calibration/chi_square.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/fitted_row_factors.h"
#include "solver/linalg/block_copy.h"
#include "solver/linalg/dense_kernels.h"
#include "solver/linalg/group_kernels.h"

namespace cdpr {
namespace {

// A direction of a term whose information with the fitted unknowns
// profiled out is below this share of its own is carried by them: the data
// cannot tell the term there from the fitted model.
constexpr double kIdentifiableShare = 1e-10;

constexpr int kLocalDim = 8;                  // pose tangent (6) and reference force (2)
constexpr int kBaseGlobalDim = 4 * kCableCount;  // anchor (3) and offset (1) per cable
constexpr int kPriorRows = 6;

bool in_model(const CalibrationOptions& options, Effect e) {
  return std::find(options.effects.begin(), options.effects.end(), e) != options.effects.end();
}

// The terms to test and the model they are linearised in: the fitted
// model's terms, then every other term that can join it. load_cell_bias is
// load_cell's bias column, so when both are tested only load_cell is added.
struct Extension {
  std::vector<Effect> tested;
  std::vector<Effect> effects;  // of the extended factor: the model's, then the added ones
  std::vector<int> column;      // per effect of `effects`: its first global column
  int global_dim = kBaseGlobalDim;
  int fitted_dim = kBaseGlobalDim;  // the globals of the fit come first
  // The columns of a tested term.
  std::pair<int, int> columns(Effect e) const {
    const bool via_load_cell = e == Effect::kLoadCellBias &&
                               std::find(effects.begin(), effects.end(), e) == effects.end();
    const Effect held = via_load_cell ? Effect::kLoadCell : e;
    const auto at = std::find(effects.begin(), effects.end(), held) - effects.begin();
    return {column[at], via_load_cell ? 1 : effect_dimension(e)};
  }
};

Extension extension_of(const CalibrationOptions& options) {
  Extension x;
  x.effects = options.effects;
  for (Effect e : kAllEffects) {
    if (in_model(options, e)) continue;
    std::vector<Effect> with = options.effects;
    with.push_back(e);
    if (effect_set_conflict(with).empty()) x.tested.push_back(e);
  }
  const bool load_cell_tested = std::find(x.tested.begin(), x.tested.end(), Effect::kLoadCell) != x.tested.end();
  for (Effect e : x.tested) {
    if (!(e == Effect::kLoadCellBias && load_cell_tested)) x.effects.push_back(e);
  }
  for (std::size_t j = 0; j < x.effects.size(); ++j) {
    x.column.push_back(x.global_dim);
    x.global_dim += effect_dimension(x.effects[j]);
    if (j < options.effects.size()) x.fitted_dim = x.global_dim;
  }
  return x;
}

// The reduced normal equations over the global variables (fitted and added)
// at the fit: S = sum over poses of C_k - B_k' A_k^-1 B_k and
// b = sum of b_g,k - B_k' A_k^-1 b_l,k, with each pose's own unknowns
// eliminated; `own` is diag(J_g' J_g) before elimination over the added
// globals (0 over the fitted ones, which are not tested).
struct ReducedSystem {
  Eigen::MatrixXd matrix;
  Eigen::VectorXd gradient;
  Eigen::VectorXd own;
};

bool reduce(const Robot& robot, const CalibrationOptions& options, const CalibrationResult& result,
            const Extension& x, ReducedSystem& out) {
  const int g = x.global_dim;

  // Parameter blocks in EffectPoseFactor's keys() order.
  std::array<double, 7> pose{};
  std::array<double, 2> force{};
  std::array<std::array<double, 3>, kCableCount> anchors{};
  std::array<double, kCableCount> offsets{};
  std::vector<std::vector<double>> effect_values;
  for (Effect e : x.effects) effect_values.emplace_back(effect_dimension(e), 0.0);
  for (int i = 0; i < kCableCount; ++i) {
    const WinchCalibration& w = result.calibration.winches[i];
    for (int a = 0; a < 3; ++a) anchors[i][a] = w.anchor_world(a);
    offsets[i] = w.offset_m;
  }
  for (std::size_t j = 0; j < options.effects.size(); ++j) effect_values[j] = result.effects[j].value;
  std::vector<const double*> parameters{pose.data(), force.data()};
  std::vector<int> block_dims{6, 2};
  std::vector<int> block_column{-1, -1};
  for (int i = 0; i < kCableCount; ++i) {
    parameters.push_back(anchors[i].data());
    block_dims.push_back(3);
    block_column.push_back(4 * i);
  }
  for (int i = 0; i < kCableCount; ++i) {
    parameters.push_back(&offsets[i]);
    block_dims.push_back(1);
    block_column.push_back(4 * i + 3);
  }
  for (std::size_t j = 0; j < x.effects.size(); ++j) {
    parameters.push_back(effect_values[j].data());
    block_dims.push_back(effect_dimension(x.effects[j]));
    block_column.push_back(x.column[j]);
  }
  std::vector<std::vector<double>> blocks;
  std::vector<double*> jacobians;
  for (int d : block_dims) blocks.emplace_back(EffectPoseFactor::kResidualDim * d, 0.0);
  for (auto& b : blocks) jacobians.push_back(b.data());
  std::array<double, kPriorRows * 6> prior_jacobian{};
  double* prior_jacobians[] = {prior_jacobian.data()};

  const Loss loss{options.huber_width};
  // Per pose, with J_l its own columns (pose, reference force), J_g the
  // global ones (its factor's rows only: the prior reaches the pose alone)
  // and A = J_l'J_l (the prior's rows included) = U'U: W = U'^-1 J_l'J_g,
  // so the pose adds J_g'J_g - W'W to S and J_g'r - W'U'^-1 J_l'r to b,
  // straight into S's upper triangle: no stacked rows, no products over
  // all poses at the end. The dense kernels take row-major blocks and
  // fill column-major S and A.
  constexpr int kFactorRows = EffectPoseFactor::kResidualDim;
  std::vector<double> global(kFactorRows * g), coupling(kLocalDim * g), eliminated(kLocalDim * g);
  std::vector<double> reduced(static_cast<std::size_t>(g) * g, 0.0), own(g, 0.0);
  std::array<double, kFactorRows * kLocalDim> local;
  std::array<double, kLocalDim * kLocalDim> a;
  std::array<double, kLocalDim> inverse, local_gradient;
  std::array<double, kFactorRows> residual;
  std::array<double, kPriorRows> prior_residual;
  out.gradient = Eigen::VectorXd::Zero(g);
  // A base catenary fit kept its last linearisation of each row: only the
  // added terms' columns are new (absent_term_columns.h). Otherwise the
  // extended factor is evaluated at the fit.
  const bool from_fit =
      options.effects.empty() && std::all_of(result.fitted_rows.begin(), result.fitted_rows.end(),
                                             [](const FittedRow& row) { return row.linearization.has_value(); });
  std::array<Eigen::Vector3d, kCableCount> anchor_world;
  for (int i = 0; i < kCableCount; ++i) anchor_world[i] = result.calibration.winches[i].anchor_world;
  auto linearise = [&](int k) {
    const FittedRow& row = result.fitted_rows[k];
    if (!from_fit) {
      return evaluate_fitted_row(robot, row, k, options.height_sigma_m, loss, x.effects, pose.data(), force.data(),
                                 parameters.data(),
                                 {prior_residual.data(), prior_jacobians, residual.data(), jacobians.data()});
    }
    const FittedRowLinearization& fit = *row.linearization;
    std::copy(fit.residual.begin(), fit.residual.end(), residual.begin());
    std::copy(fit.prior_residual.begin(), fit.prior_residual.end(), prior_residual.begin());
    std::copy(fit.prior_jacobian.begin(), fit.prior_jacobian.end(), prior_jacobian.begin());
    const double* block = fit.jacobian.data();
    for (int b = 0; b < EffectPoseFactor::kBaseKeyCount; ++b) {
      std::copy_n(block, blocks[b].size(), blocks[b].begin());
      block += blocks[b].size();
    }
    return absent_term_jacobians(
        robot, {row.sample, row.world_T_platform, row.reference_force, anchor_world, offsets}, options.height_sigma_m,
        loss, x.effects, jacobians.data() + EffectPoseFactor::kBaseKeyCount);
  };
  const int n = static_cast<int>(result.fitted_rows.size());
  for (int k = 0; k < n; ++k) {
    if (!linearise(k)) return false;
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      const int d = block_dims[b];
      const int column = b == 0 ? 0 : b == 1 ? 6 : block_column[b];
      double* target = b < 2 ? local.data() + column : global.data() + column;
      const int stride = b < 2 ? kLocalDim : g;
      copy_block_columns(kFactorRows, d, blocks[b].data(), target, stride);
    }
    if (!all_finite(residual.data(), residual.size()) || !all_finite(prior_residual.data(), prior_residual.size()) ||
        !all_finite(local.data(), local.size()) || !all_finite(prior_jacobian.data(), prior_jacobian.size()) ||
        !all_finite(global.data(), global.size())) {
      return false;
    }
    a.fill(0.0);
    add_transposed_product(kFactorRows, kLocalDim, kLocalDim, local.data(), kLocalDim, local.data(), kLocalDim,
                           a.data(), kLocalDim, 1.0, true);
    add_transposed_product(kPriorRows, 6, 6, prior_jacobian.data(), 6, prior_jacobian.data(), 6, a.data(), kLocalDim,
                           1.0, true);
    if (!group_kernels::cholesky_upper<kLocalDim>(a.data(), kLocalDim, inverse.data())) return false;
    local_gradient.fill(0.0);
    add_transposed_times_vector(kFactorRows, kLocalDim, local.data(), kLocalDim, residual.data(), 1.0,
                                local_gradient.data());
    add_transposed_times_vector(kPriorRows, 6, prior_jacobian.data(), 6, prior_residual.data(), 1.0,
                                local_gradient.data());
    group_kernels::solve_upper_transposed<kLocalDim>(a.data(), inverse.data(), kLocalDim, local_gradient.data());
    // J_l'J_g as g x 8 column-major: the 8 x g row-major coupling.
    std::fill(coupling.begin(), coupling.end(), 0.0);
    add_transposed_product(kFactorRows, g, kLocalDim, global.data(), g, local.data(), kLocalDim, coupling.data(), g,
                           1.0, false);
    solve_upper_transposed_rows(kLocalDim, a.data(), inverse.data(), g, coupling.data(), eliminated.data());
    add_transposed_product(kFactorRows, g, g, global.data(), g, global.data(), g, reduced.data(), g, 1.0, true);
    add_transposed_product(kLocalDim, g, g, eliminated.data(), g, eliminated.data(), g, reduced.data(), g, -1.0, true);
    add_transposed_times_vector(kFactorRows, g, global.data(), g, residual.data(), 1.0, out.gradient.data());
    add_transposed_times_vector(kLocalDim, g, eliminated.data(), g, local_gradient.data(), -1.0, out.gradient.data());
    for (int r = 0; r < kFactorRows; ++r) {
      for (int c = x.fitted_dim; c < g; ++c) own[c] += global[r * g + c] * global[r * g + c];
    }
  }
  out.matrix = Eigen::Map<const Eigen::MatrixXd>(reduced.data(), g, g).selfadjointView<Eigen::Upper>();
  out.own = Eigen::Map<const Eigen::VectorXd>(own.data(), g);
  return true;
}

// S = u' M^-1 u over the directions of the term the data see (its
// profiled information, relative to its own, above kIdentifiableShare).
TermTest score(Effect e, int first, int dim, const Eigen::MatrixXd& profiled, const Eigen::VectorXd& score,
               const Eigen::VectorXd& own, double dispersion) {
  TermTest t;
  t.effect = e;
  Eigen::VectorXd scale(dim);
  for (int j = 0; j < dim; ++j) scale(j) = own(first + j) > 0.0 ? 1.0 / std::sqrt(own(first + j)) : 0.0;
  const Eigen::MatrixXd share =
      scale.asDiagonal() * profiled.block(first, first, dim, dim) * scale.asDiagonal();
  const Eigen::VectorXd u = scale.asDiagonal() * score.segment(first, dim);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(share);
  double s = 0.0;
  for (int j = 0; j < dim; ++j) {
    const double lambda = eigen.eigenvalues()(j);
    if (!(lambda > kIdentifiableShare)) continue;
    s += std::pow(eigen.eigenvectors().col(j).dot(u), 2) / lambda;
    ++t.dof;
  }
  t.identifiable = t.dof > 0;
  if (!t.identifiable) return t;
  t.statistic = s / dispersion;
  t.p = chi_square_upper_tail(t.statistic, t.dof);
  return t;
}

std::string evidence_text(const TermTest& t) {
  char text[160];
  std::snprintf(text, sizeof text, "%s (%.1f for %d degree%s of freedom, p = %.1e)",
                std::string(effect_model_name(t.effect)).c_str(), t.statistic, t.dof, t.dof == 1 ? "" : "s", t.p);
  return text;
}

}  // namespace

void test_missing_terms(const Robot& robot, const CalibrationOptions& options, CalibrationResult& result) {
  if (!result.ok || options.cable_model != CableModelKind::kCatenary || !(options.term_test_alpha > 0.0) ||
      !(options.misfit_alpha > 0.0) || result.fitted_rows.empty() ||
      result.degrees_of_freedom < static_cast<int>(result.global_covariance.rows()) ||
      result.calibration.winches.size() != static_cast<std::size_t>(kCableCount) ||
      result.effects.size() != options.effects.size()) {
    return;
  }
  const Extension x = extension_of(options);
  if (x.tested.empty()) return;
  ReducedSystem reduced;
  if (!reduce(robot, options, result, x, reduced)) return;

  // Profile the fit's globals out of the added ones.
  const int t = x.fitted_dim, e = x.global_dim - x.fitted_dim;
  const Eigen::LLT<Eigen::MatrixXd> fitted(reduced.matrix.topLeftCorner(t, t));
  if (fitted.info() != Eigen::Success) return;
  const Eigen::MatrixXd taken = fitted.solve(reduced.matrix.topRightCorner(t, e));
  Eigen::MatrixXd profiled = Eigen::MatrixXd::Zero(x.global_dim, x.global_dim);
  profiled.bottomRightCorner(e, e) = reduced.matrix.bottomRightCorner(e, e) - reduced.matrix.bottomLeftCorner(e, t) * taken;
  Eigen::VectorXd efficient = Eigen::VectorXd::Zero(x.global_dim);
  efficient.tail(e) = reduced.gradient.tail(e) - taken.transpose() * reduced.gradient.head(t);

  const double dispersion =
      std::max(1.0, result.degrees_of_freedom > 0 ? result.chi_square / result.degrees_of_freedom : 1.0);
  for (Effect effect : x.tested) {
    const auto [first, dim] = x.columns(effect);
    result.term_tests.push_back(score(effect, first, dim, profiled, efficient, reduced.own, dispersion));
  }
  const auto identifiable = std::count_if(result.term_tests.begin(), result.term_tests.end(),
                                          [](const TermTest& test) { return test.identifiable; });
  if (identifiable == 0) return;
  result.term_test_level = options.term_test_alpha / static_cast<double>(identifiable);
  std::vector<const TermTest*> asked;
  for (TermTest& test : result.term_tests) {
    test.asked_for = test.identifiable && test.p < result.term_test_level;
    if (test.asked_for) asked.push_back(&test);
  }
  if (asked.empty()) return;
  std::stable_sort(asked.begin(), asked.end(), [](const TermTest* a, const TermTest* b) { return a->p < b->p; });

  char level[160];
  std::snprintf(level, sizeof level, " < %.1e, the level %.0e shared among %d terms", result.term_test_level,
                options.term_test_alpha, static_cast<int>(identifiable));
  std::string text = "the model lacks a term the data ask for: " + evidence_text(*asked.front());
  text.insert(text.size() - 1, level);
  text += " by a score test at the fit";
  if (asked.size() > 1) {
    text += "; also ";
    for (std::size_t j = 1; j < asked.size(); ++j) text += (j > 1 ? ", " : "") + evidence_text(*asked[j]);
  }
  text += ". Without it the anchors are biased beyond their sigmas: add it to the model, or run cdpr-calib "
          "diagnose to choose among the terms";
  std::string& warning = result.calibration.model_warning;
  warning = warning.empty() ? text : warning + "; " + text;
  result.misfit = true;
  if (result.misfit_cause == MisfitCause::kNone) result.misfit_cause = MisfitCause::kModel;
}

}  // namespace cdpr
