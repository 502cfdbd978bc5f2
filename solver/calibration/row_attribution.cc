#include "solver/calibration/row_attribution.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "solver/nls/factor_parameters.h"
#include "solver/nls/trust_region_strategy.h"

namespace cdpr {
namespace {

// The row's own variables (pose, reference force) free, every other one a
// constant copy of the problem's.
struct LocalProblem {
  Problem problem;
  std::vector<int> free;  // variable indices in `problem`
  int columns = 0;
};

LocalProblem local_problem(const Problem& full, const std::vector<int>& row_factors, int pose_index) {
  LocalProblem local;
  for (int f : row_factors) {
    for (const Key& key : full.factors()[f]->keys()) {
      if (local.problem.has(key)) continue;
      const bool own = key == PoseKey(pose_index) || key == ReferenceForceKey(pose_index);
      if (key == PoseKey(pose_index)) {
        local.problem.add_pose(key, full.pose(key));
      } else {
        local.problem.add_vector(key, full.vector(key));
      }
      if (own) {
        local.free.push_back(local.problem.variable_index(key));
      } else {
        local.problem.set_constant(key);
      }
    }
  }
  for (int v : local.free) local.columns += local.problem.variables()[v].tangent_dim;
  return local;
}

struct Linearised {
  bool ok = false;
  Eigen::VectorXd residual;
  Eigen::MatrixXd jacobian;  // residual rows x free columns
};

// (factor, residual row) pairs left out of a refit.
using LeftOut = std::vector<std::pair<int, int>>;

// Residuals and Jacobian of the row's factors, the left-out rows zeroed.
Linearised linearise(const Problem& full, const LocalProblem& local, const std::vector<int>& row_factors,
                     const LeftOut& left_out) {
  int rows = 0;
  for (int f : row_factors) rows += full.factors()[f]->residual_dim();
  Linearised lin;
  lin.residual = Eigen::VectorXd::Zero(rows);
  lin.jacobian = Eigen::MatrixXd::Zero(rows, local.columns);
  int first_row = 0;
  for (int f : row_factors) {
    const Factor& factor = *full.factors()[f];
    const int dim = factor.residual_dim();
    std::vector<std::vector<double>> blocks(factor.keys().size());
    std::vector<double*> jacobians(factor.keys().size(), nullptr);
    std::vector<int> block_column(factor.keys().size(), -1);
    for (std::size_t b = 0; b < factor.keys().size(); ++b) {
      const int v = local.problem.variable_index(factor.keys()[b]);
      int column = 0;
      for (int free : local.free) {
        if (free == v) block_column[b] = column;
        column += local.problem.variables()[free].tangent_dim;
      }
      if (block_column[b] < 0) continue;
      blocks[b].assign(static_cast<std::size_t>(dim) * local.problem.variables()[v].tangent_dim, 0.0);
      jacobians[b] = blocks[b].data();
    }
    std::vector<double> residual(dim, 0.0);
    double cost = 0.0;
    if (!factor.evaluate(parameter_blocks(local.problem, factor).data(), residual.data(), jacobians.data(), &cost)) {
      return lin;
    }
    for (int j = 0; j < dim; ++j) {
      if (std::find(left_out.begin(), left_out.end(), std::pair{f, j}) != left_out.end()) continue;
      lin.residual(first_row + j) = residual[j];
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        if (block_column[b] < 0) continue;
        const int width = static_cast<int>(blocks[b].size()) / dim;
        for (int c = 0; c < width; ++c) lin.jacobian(first_row + j, block_column[b] + c) = blocks[b][j * width + c];
      }
    }
    first_row += dim;
  }
  lin.ok = true;
  return lin;
}

double row_residual(const Problem& full, const LocalProblem& local, int factor_index, int row) {
  const Factor& factor = *full.factors()[factor_index];
  std::vector<double> residual(factor.residual_dim(), 0.0);
  double cost = 0.0;
  if (!factor.evaluate(parameter_blocks(local.problem, factor).data(), residual.data(), nullptr, &cost)) {
    return std::numeric_limits<double>::infinity();
  }
  return residual[row];
}

void apply_step(LocalProblem& local, const Eigen::VectorXd& step) {
  int column = 0;
  for (int v : local.free) {
    local.problem.retract(v, step.data() + column);
    column += local.problem.variables()[v].tangent_dim;
  }
}

// Levenberg-Marquardt on the row's own variables without the left-out
// readings, its steps judged by the solver's TrustRegionStrategy; returns the
// chi-square of the rest (infinity when it cannot be evaluated). The damping
// starts small (the refit starts at the full fit's solution, near the
// refit's own minimum), stays within [1e-12, 1e12] of J^T J's diagonal, and
// the refit stops after 30 trial steps or once a step gains less than 1e-10
// of the chi-square: what is compared across readings is the chi-square, and
// the one left out is far above that.
constexpr TrustRegionOptions kRefitTrustRegion{1e6, 1e12, 1e-12};

double refit_without(const Problem& full, LocalProblem& local, const std::vector<int>& row_factors,
                     const LeftOut& left_out) {
  constexpr int kMaxIterations = 30;
  constexpr double kStopGain = 1e-10;
  Linearised lin = linearise(full, local, row_factors, left_out);
  if (!lin.ok) return std::numeric_limits<double>::infinity();
  double chi2 = lin.residual.squaredNorm();
  TrustRegionStrategy strategy(kRefitTrustRegion);
  for (int it = 0; it < kMaxIterations && !strategy.collapsed(); ++it) {
    const Eigen::MatrixXd jtj = lin.jacobian.transpose() * lin.jacobian;
    const Eigen::VectorXd gradient = lin.jacobian.transpose() * lin.residual;
    Eigen::MatrixXd normal = jtj;
    normal.diagonal() += strategy.damping() * jtj.diagonal().cwiseMax(1e-9);
    const Eigen::VectorXd step = normal.ldlt().solve(-gradient);
    // chi2 = |r|^2: the undamped model's decrease is -(2 g's + s'J'Js).
    const double predicted = -(2.0 * gradient.dot(step) + step.dot(jtj * step));
    const std::vector<double> saved = local.problem.state();
    apply_step(local, step);
    const Linearised next = linearise(full, local, row_factors, left_out);
    const double next_chi2 = next.ok ? next.residual.squaredNorm() : std::numeric_limits<double>::quiet_NaN();
    if (strategy.judge_step(chi2, next_chi2, predicted)) {
      const bool converged = chi2 - next_chi2 < kStopGain * chi2;
      lin = next;
      chi2 = next_chi2;
      if (converged) break;
    } else {
      local.problem.state() = saved;
    }
  }
  return chi2;
}

// Two readings are told apart when leaving out one explains the rest of
// the row better than leaving out the other by more than the chi-square(1)
// quantile at 1e-3: the likelihood ratio of "this one is wrong" against
// "that one is" is then above exp(10.83 / 2) = 225. Below it, which of them
// is wrong is left open.
constexpr double kAmbiguousChi2 = 10.83;

}  // namespace

std::vector<SensorReading> attribute_row(const Problem& problem, int row_id, int pose_index,
                                         const std::vector<int>& row_factors, const std::vector<RowReading>& readings,
                                         double threshold_sigma) {
  // Greedy: leave out the reading whose removal explains the row best, with
  // every reading the data cannot tell from it (its own removal explains the
  // row nearly as well: kAmbiguousChi2 below), and another round while a
  // reading still stands out (a row may hold two gross errors, e.g. a
  // slipped cable and a load-cell spike); at least one reading always stays in.
  const std::size_t n = readings.size();
  std::vector<int> left_out;  // indices into readings
  std::vector<double> residuals(n, 0.0);  // in the refit without those left out
  std::vector<int> groups(n, 0);
  int group_count = 0;
  auto is_out = [&](std::size_t j) {
    return std::find(left_out.begin(), left_out.end(), static_cast<int>(j)) != left_out.end();
  };
  // The refit without the readings left out and `extra` (-1: none): the
  // rest's chi-square, and each reading's normalised residual in it.
  auto refit = [&](int extra, std::vector<double>& normalised) {
    LeftOut pairs;
    for (int o : left_out) pairs.emplace_back(readings[o].factor, readings[o].residual_row);
    if (extra >= 0) pairs.emplace_back(readings[extra].factor, readings[extra].residual_row);
    LocalProblem local = local_problem(problem, row_factors, pose_index);
    const double chi2 = refit_without(problem, local, row_factors, pairs);
    normalised.assign(n, 0.0);
    for (std::size_t r = 0; r < n; ++r) {
      normalised[r] = row_residual(problem, local, readings[r].factor, readings[r].residual_row) / readings[r].spread;
    }
    return chi2;
  };
  while (left_out.size() + 1 < n) {
    std::vector<double> chi2(n, std::numeric_limits<double>::infinity());
    int best = -1;
    for (std::size_t j = 0; j < n; ++j) {
      if (is_out(j)) continue;
      chi2[j] = refit(static_cast<int>(j), residuals);
      if (chi2[j] < (best < 0 ? std::numeric_limits<double>::infinity() : chi2[best])) best = static_cast<int>(j);
    }
    if (best < 0) break;
    // The readings whose removal explains the rest within kAmbiguousChi2 of
    // the best: the data cannot tell which of them is wrong, so all go.
    std::vector<int> group{best};
    for (std::size_t j = 0; j < n; ++j) {
      if (static_cast<int>(j) == best || !(chi2[j] - chi2[best] < kAmbiguousChi2)) continue;
      if (left_out.size() + group.size() + 1 >= n) break;
      group.push_back(static_cast<int>(j));
    }
    const int group_id = group.size() > 1 ? ++group_count : 0;
    for (int j : group) {
      left_out.push_back(j);
      groups[j] = group_id;
    }
    // The row's pose can absorb a second gross error into its prior, leaving
    // every remaining reading small but the rest's chi-square far above it.
    const double rest = refit(-1, residuals);
    bool another = rest > threshold_sigma * threshold_sigma;
    for (std::size_t r = 0; r < n; ++r) another = another || (!is_out(r) && std::abs(residuals[r]) > threshold_sigma);
    if (!another) break;
  }
  std::vector<SensorReading> out;
  for (int j : left_out) out.push_back({row_id, readings[j].sensor, readings[j].cable, residuals[j], groups[j]});
  return out;
}

}  // namespace cdpr
