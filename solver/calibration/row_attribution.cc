#include "solver/calibration/row_attribution.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>

#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/fitted_row_factors.h"
#include "solver/linalg/block_copy.h"
#include "solver/linalg/dense_kernels.h"
#include "solver/linalg/group_kernels.h"
#include "solver/nls/factor_parameters.h"
#include "solver/nls/dense_damped_solver.h"

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

// The row's own variables refitted without the left-out readings
// (solver/nls/dense_damped_solver.h, on the pose's manifold); returns the
// chi-square of the rest (infinity when it cannot be evaluated) and leaves
// `local` at the refit. The damping starts small (the refit starts at the
// full fit's solution, near the refit's own minimum) and stays within
// [1e-12, 1e12]; the refit stops after 30 trial steps or once a step gains
// less than 1e-10 of the chi-square: what is compared across readings is
// the chi-square, and the one left out is far above that.
double refit_without(const Problem& full, LocalProblem& local, const std::vector<int>& row_factors,
                     const LeftOut& left_out) {
  DenseDampedOptions options;
  options.trust_region = {1e6, 1e12, 1e-12};
  options.max_trials = 30;
  options.gain_tolerance = 1e-10;
  auto evaluate = [&](const std::vector<double>& state, Eigen::VectorXd& residual, Eigen::MatrixXd* jacobian) {
    local.problem.state() = state;
    Linearised lin = linearise(full, local, row_factors, left_out);
    residual = std::move(lin.residual);
    *jacobian = std::move(lin.jacobian);
    return lin.ok;
  };
  auto retract = [&](const std::vector<double>& state, const Eigen::VectorXd& step, std::vector<double>& out) {
    out = state;
    int column = 0;
    for (int v : local.free) {
      local.problem.retract(v, step.data() + column, out.data());
      column += local.problem.variables()[v].tangent_dim;
    }
  };
  std::vector<double> state = local.problem.state();
  DenseDampedSolver<Eigen::Dynamic, Eigen::Dynamic> solver(options);
  const DenseDampedSummary summary = solver.minimize_on_manifold(state, evaluate, retract);
  local.problem.state() = state;
  if (summary.stop == DenseDampedStop::kNotEvaluable) return std::numeric_limits<double>::infinity();
  return summary.final_chi2;
}

// Two choices of readings to leave out are told apart when one explains
// the rest of the row better than the other by more than the chi-square(1)
// quantile at 1e-3: the likelihood ratio of "these are wrong" against
// "those are" is then above exp(10.83 / 2) = 225. Below it, which of them
// is wrong is left open.
constexpr double kAmbiguousChi2 = 10.83;

}  // namespace

std::vector<SensorReading> attribute_row(const Problem& problem, int row_id, int pose_index,
                                         const std::vector<int>& row_factors, const std::vector<RowReading>& readings,
                                         double threshold_sigma) {
  const std::size_t n = readings.size();
  std::vector<int> left_out;  // indices into readings
  std::vector<int> groups(n, 0);
  int group_count = 0;
  auto is_out = [&](int j) { return std::find(left_out.begin(), left_out.end(), j) != left_out.end(); };
  // One choice of readings to leave out beside `left_out`: the rest's
  // chi-square, each reading's normalised residual in that refit, and
  // whether the rest is explained (no reading left in beyond the threshold,
  // the chi-square within the threshold squared: the row's pose can absorb
  // a gross error into its prior, leaving every reading small but the
  // chi-square far above it).
  struct Choice {
    std::vector<int> out;
    double chi2 = std::numeric_limits<double>::infinity();
    std::vector<double> residuals;
    bool explained = false;
  };
  auto refit = [&](std::vector<int> out) {
    Choice c;
    c.out = std::move(out);
    LeftOut pairs;
    for (int o : left_out) pairs.emplace_back(readings[o].factor, readings[o].residual_row);
    for (int o : c.out) pairs.emplace_back(readings[o].factor, readings[o].residual_row);
    LocalProblem local = local_problem(problem, row_factors, pose_index);
    c.chi2 = refit_without(problem, local, row_factors, pairs);
    c.residuals.assign(n, 0.0);
    c.explained = c.chi2 <= threshold_sigma * threshold_sigma;
    for (std::size_t r = 0; r < n; ++r) {
      c.residuals[r] = row_residual(problem, local, readings[r].factor, readings[r].residual_row) / readings[r].spread;
      const bool out_now = is_out(static_cast<int>(r)) ||
                           std::find(c.out.begin(), c.out.end(), static_cast<int>(r)) != c.out.end();
      if (!out_now && std::abs(c.residuals[r]) > threshold_sigma) c.explained = false;
    }
    return c;
  };
  // Every choice of `size` readings not yet out, each refitted.
  auto choices = [&](std::size_t size) {
    std::vector<Choice> all;
    for (std::size_t a = 0; a < n; ++a) {
      if (is_out(static_cast<int>(a))) continue;
      if (size == 1) {
        all.push_back(refit({static_cast<int>(a)}));
        continue;
      }
      for (std::size_t b = a + 1; b < n; ++b) {
        if (!is_out(static_cast<int>(b))) all.push_back(refit({static_cast<int>(a), static_cast<int>(b)}));
      }
    }
    return all;
  };
  // Leaves out the best of `all` (of those that explain the row when
  // `only_explained`) and every reading of the choices the data cannot tell
  // from it (kAmbiguousChi2): readings in all of those choices
  // are named alone, the others as one suspect group; at least one reading
  // stays in. Returns the refit without everything now left out.
  auto take = [&](const std::vector<Choice>& all, bool only_explained) {
    const Choice* best = nullptr;
    for (const Choice& c : all) {
      if ((c.explained || !only_explained) && (!best || c.chi2 < best->chi2)) best = &c;
    }
    std::vector<int> common = best->out, either;
    for (const Choice& c : all) {
      if (!(c.chi2 - best->chi2 < kAmbiguousChi2)) continue;
      for (int j : c.out) {
        if (std::find(either.begin(), either.end(), j) == either.end()) either.push_back(j);
      }
      std::erase_if(common, [&](int j) { return std::find(c.out.begin(), c.out.end(), j) == c.out.end(); });
    }
    const int group_id = common.size() < either.size() ? ++group_count : 0;
    // The best choice's own readings first, so a cut keeps them.
    std::stable_partition(either.begin(), either.end(), [&](int j) {
      return std::find(best->out.begin(), best->out.end(), j) != best->out.end();
    });
    for (int j : either) {
      if (left_out.size() + 1 >= n) break;
      left_out.push_back(j);
      groups[j] = std::find(common.begin(), common.end(), j) != common.end() ? 0 : group_id;
    }
    return refit({});
  };
  // The fewest readings that explain the row: each single reading, then
  // each pair, left out (a pair found together is not masked by a first
  // choice that was wrong: a slipped cable and a load-cell spike in one row
  // can make a third reading's removal look best); beyond two, greedily,
  // one reading (or group) more per round while the rest is not explained.
  Choice now;
  for (std::size_t size = 1; size <= 2 && left_out.size() + size < n; ++size) {
    std::vector<Choice> all = choices(size);
    if (all.empty()) break;
    const bool any = std::any_of(all.begin(), all.end(), [](const Choice& c) { return c.explained; });
    const bool last = size == 2 || left_out.size() + size + 1 >= n;
    if (!any && !last) continue;
    // The best choice that explains the row (when none does, the best of
    // all, and the greedy rounds below go on); every choice is its rival.
    now = take(all, any);
    break;
  }
  while (!now.explained && left_out.size() + 1 < n && !now.residuals.empty()) {
    std::vector<Choice> all = choices(1);
    if (all.empty()) break;
    now = take(all, false);
  }
  std::vector<SensorReading> out;
  for (int j : left_out) out.push_back({row_id, readings[j].sensor, readings[j].cable, now.residuals[j], groups[j]});
  return out;
}

namespace {

constexpr int kRowFactorRows = EffectPoseFactor::kResidualDim;
constexpr int kRowPriorRows = 6;
constexpr int kRowUnknowns = 8;  // pose tangent (6), reference force (2)
using RowJacobian = Eigen::Matrix<double, kRowFactorRows + kRowPriorRows, kRowUnknowns>;
using RowResidual = std::array<double, kRowFactorRows>;

// A kept reading of a row and 1 - h, h its leverage in the row's fit.
struct Studentised {
  SensorReading reading;  // value: the whitened residual
  double free = 0.0;
};

// Every reading the row kept, with 1 - h from `j` (the reading factor's
// rows, then the pose prior's; pose then reference-force columns). False
// when `j` is not finite or the row's information not positive definite.
bool studentise(const Robot& robot, const Sample& sample, const RowJacobian& j, const RowResidual& residual,
                std::vector<Studentised>& out) {
  out.clear();
  if (!j.allFinite()) return false;
  const Eigen::LDLT<Eigen::Matrix<double, kRowUnknowns, kRowUnknowns>> information(j.transpose() * j);
  if (information.info() != Eigen::Success || !information.isPositive()) return false;
  const LeftOutRows left_out = left_out_rows(sample);
  for (int reading = 0; reading <= kCableCount; ++reading) {
    const int r = kReadingRows[reading];
    if (left_out.contains(r)) continue;
    const Eigen::Matrix<double, kRowUnknowns, 1> jr = j.row(r).transpose();
    const bool force_row = reading == kCableCount;
    out.push_back({{sample.id, force_row ? SensorKind::kForce : SensorKind::kEncoder,
                    force_row ? robot.reference_cable : reading, residual[r]},
                   1.0 - jr.dot(information.solve(jr))});
  }
  return true;
}

// The row's Jacobian from its reading factor's pose and force blocks
// (kRowFactorRows x 6, x 2) and its pose prior's pose block (kRowPriorRows x 6),
// each row-major.
RowJacobian row_jacobian(const double* pose_jacobian, const double* force_jacobian, const double* prior_jacobian) {
  RowJacobian j = RowJacobian::Zero();
  for (int r = 0; r < kRowFactorRows; ++r) {
    for (int c = 0; c < 6; ++c) j(r, c) = pose_jacobian[r * 6 + c];
    for (int c = 0; c < 2; ++c) j(r, 6 + c) = force_jacobian[r * 2 + c];
  }
  for (int r = 0; r < kRowPriorRows; ++r) {
    for (int c = 0; c < 6; ++c) j(kRowFactorRows + r, c) = prior_jacobian[r * 6 + c];
  }
  return j;
}

// A row's screening value below the bar by less than this fraction, or a
// reading's 1 - h below kScreenFree, is not trusted to rule the row out:
// the two evaluations agree to rounding, far inside both.
constexpr double kScreenMargin = 1e-3;
constexpr double kScreenFree = 1e-3;

}  // namespace

double largest_studentised_residual(const Sample& sample, std::span<const double> residual,
                                    std::span<const double> pose_jacobian, std::span<const double> force_jacobian,
                                    std::span<const double> prior_jacobian) {
  constexpr double kUnknown = std::numeric_limits<double>::infinity();
  if (residual.size() != kRowFactorRows || pose_jacobian.size() != kRowFactorRows * 6 ||
      force_jacobian.size() != kRowFactorRows * 2 || prior_jacobian.size() != kRowPriorRows * 6) {
    return kUnknown;
  }
  // h = |U'^-1 j_r|^2 with J^T J = U'U, by the solver's dense kernels: far
  // cheaper than studentise()'s pivoted LDLT, and the margins cover the
  // difference. The factor's rows as one 9 x 8 matrix (pose, then force).
  std::array<double, kRowFactorRows * kRowUnknowns> local;
  copy_block_columns(kRowFactorRows, 6, pose_jacobian.data(), local.data(), kRowUnknowns);
  copy_block_columns(kRowFactorRows, 2, force_jacobian.data(), local.data() + 6, kRowUnknowns);
  if (!all_finite(local.data(), local.size()) || !all_finite(prior_jacobian.data(), prior_jacobian.size())) {
    return kUnknown;
  }
  std::array<double, kRowUnknowns * kRowUnknowns> u{};
  std::array<double, kRowUnknowns> inverse;
  add_transposed_product(kRowFactorRows, kRowUnknowns, kRowUnknowns, local.data(), kRowUnknowns, local.data(),
                         kRowUnknowns, u.data(), kRowUnknowns, 1.0, true);
  add_transposed_product(kRowPriorRows, 6, 6, prior_jacobian.data(), 6, prior_jacobian.data(), 6, u.data(),
                         kRowUnknowns, 1.0, true);
  if (!group_kernels::cholesky_upper<kRowUnknowns>(u.data(), kRowUnknowns, inverse.data())) return kUnknown;
  const LeftOutRows left_out = left_out_rows(sample);
  double largest = 0.0;
  for (int r : kReadingRows) {
    if (left_out.contains(r)) continue;
    std::array<double, kRowUnknowns> w;
    std::copy_n(local.data() + r * kRowUnknowns, kRowUnknowns, w.data());
    group_kernels::solve_upper_transposed<kRowUnknowns>(u.data(), inverse.data(), kRowUnknowns, w.data());
    double h = 0.0;
    for (double x : w) h += x * x;
    const double free = 1.0 - h;
    if (!(free >= kScreenFree) || !std::isfinite(residual[r])) return kUnknown;
    largest = std::max(largest, std::abs(residual[r]) / std::sqrt(free));
  }
  return largest;
}

std::vector<SensorReading> hidden_gross_errors(const Robot& robot, const CalibrationOptions& options,
                                               const CalibrationResult& result, double bar_sigma) {
  std::vector<SensorReading> out;
  if (!result.ok || options.cable_model != CableModelKind::kCatenary ||
      result.calibration.winches.size() != static_cast<std::size_t>(kCableCount) ||
      result.effects.size() != options.effects.size()) {
    return out;
  }
  // Parameter blocks in EffectPoseFactor's keys() order.
  std::array<double, 7> pose{};
  std::array<double, 2> force{};
  std::array<std::array<double, 3>, kCableCount> anchors{};
  std::array<double, kCableCount> offsets{};
  std::vector<std::vector<double>> effect_values;
  std::vector<const double*> parameters{pose.data(), force.data()};
  for (int i = 0; i < kCableCount; ++i) {
    for (int a = 0; a < 3; ++a) anchors[i][a] = result.calibration.winches[i].anchor_world(a);
    offsets[i] = result.calibration.winches[i].offset_m;
    parameters.push_back(anchors[i].data());
  }
  for (int i = 0; i < kCableCount; ++i) parameters.push_back(&offsets[i]);
  for (const FittedEffect& e : result.effects) effect_values.push_back(e.value);
  for (const std::vector<double>& v : effect_values) parameters.push_back(v.data());

  std::array<double, kRowFactorRows * 6> pose_jacobian{};
  std::array<double, kRowFactorRows * 2> force_jacobian{};
  std::vector<double*> jacobians(parameters.size(), nullptr);
  jacobians[0] = pose_jacobian.data();
  jacobians[1] = force_jacobian.data();
  std::array<double, kRowPriorRows * 6> prior_jacobian{};
  double* prior_jacobians[] = {prior_jacobian.data()};
  RowResidual residual{};
  std::array<double, kRowPriorRows> prior_residual{};
  std::vector<Studentised> readings;
  const Loss loss{options.huber_width};
  for (std::size_t k = 0; k < result.fitted_rows.size(); ++k) {
    const FittedRow& row = result.fitted_rows[k];
    // A row the fit's own linearisation puts clearly below the bar has
    // no reading to name.
    if (row.largest_studentised * (1.0 + kScreenMargin) < bar_sigma) continue;
    if (!evaluate_fitted_row(robot, row, static_cast<int>(k), options.height_sigma_m, loss, options.effects,
                             pose.data(), force.data(), parameters.data(),
                             {prior_residual.data(), prior_jacobians, residual.data(), jacobians.data()})) {
      continue;
    }
    if (!studentise(robot, row.sample,
                    row_jacobian(pose_jacobian.data(), force_jacobian.data(), prior_jacobian.data()), residual,
                    readings)) {
      continue;
    }
    std::vector<SensorReading> studentised;
    for (const Studentised& s : readings) {
      if (!(s.free > 1e-9) || !std::isfinite(s.reading.value)) continue;
      SensorReading t = s.reading;
      t.value /= std::sqrt(s.free);
      studentised.push_back(t);
    }
    for (const SensorReading& s : studentised) {
      const bool told_apart = std::all_of(studentised.begin(), studentised.end(), [&](const SensorReading& o) {
        return &o == &s || s.value * s.value - o.value * o.value > kAmbiguousChi2;
      });
      if (std::abs(s.value) > bar_sigma && told_apart) out.push_back(s);
    }
  }
  std::sort(out.begin(), out.end(),
            [](const SensorReading& a, const SensorReading& b) { return std::abs(a.value) > std::abs(b.value); });
  return out;
}

}  // namespace cdpr
