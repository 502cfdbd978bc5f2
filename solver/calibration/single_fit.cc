#include "solver/calibration/single_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <span>

#include "solver/model/cable_prediction.h"
#include "solver/calibration/calibration_stages.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/nls/factor_parameters.h"
#include "solver/calibration/gross_errors.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/calibration/row_attribution.h"

namespace cdpr {
namespace {

using Anchors = std::array<Eigen::Vector3d, kCableCount>;

// Unweighted residual statistics at the solution, with plain least squares.
void fill_fit_rms(const Robot& robot, const std::vector<Sample>& samples, const Problem& problem,
                  const CalibrationOptions& options, FitSummary& fit) {
  Anchors anchors;
  std::array<double, kCableCount> offsets;
  for (int i = 0; i < kCableCount; ++i) {
    anchors[i] = problem.vector(AnchorKey(i));
    offsets[i] = problem.vector(OffsetKey(i))(0);
  }
  double sum_encoder = 0.0, sum_force = 0.0;
  int n_encoder = 0, n_force = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const Key pose_key = PoseKey(static_cast<int>(k));
    const Pose pose = problem.pose(pose_key);
    if (!options.effects.empty()) {
      // The model terms change lengths and readings: ask the factor's own model.
      const EffectPoseFactor factor(robot, static_cast<int>(k), samples[k], options.height_sigma_m, Loss{},
                                    options.effects);
      PosePrediction prediction;
      if (!factor.predict(parameter_blocks(problem, factor).data(), prediction)) continue;
      for (int i = 0; i < kCableCount; ++i) {
        if (samples[k].encoder_left_out[i]) continue;
        sum_encoder += std::pow(prediction.encoder_residual_m[i], 2);
        ++n_encoder;
      }
      if (!samples[k].force_left_out) {
        sum_force += std::pow(prediction.force_residual_n, 2);
        ++n_force;
      }
    } else if (options.cable_model == CableModelKind::kCatenary) {
      const Eigen::Vector2d force = problem.vector(ReferenceForceKey(static_cast<int>(k)));
      const auto cables = predict_cables(robot, anchors, pose, force);
      if (!cables) continue;
      for (int i = 0; i < kCableCount; ++i) {
        if (samples[k].encoder_left_out[i]) continue;
        const double r = (*cables)[i].arc_length_m + offsets[i] - samples[k].encoder_m[i];
        sum_encoder += r * r;
        ++n_encoder;
      }
      if (!samples[k].force_left_out) {
        const double rf = (*cables)[robot.reference_cable].tension_n - samples[k].force_n;
        sum_force += rf * rf;
        ++n_force;
      }
    } else {
      for (int i = 0; i < kCableCount; ++i) {
        const Eigen::Vector3d b = pose.transform(robot.winches[i].attachment_platform);
        const double r = (b - anchors[i]).norm() + offsets[i] - samples[k].encoder_m[i];
        sum_encoder += r * r;
        ++n_encoder;
      }
    }
  }
  fit.rms_encoder_m = n_encoder ? std::sqrt(sum_encoder / n_encoder) : 0.0;
  fit.rms_force_n = n_force ? std::sqrt(sum_force / n_force) : 0.0;
}

// Whether a residual stored after `loss` is the residual itself: the loss
// left its row as least squares would. A Huber residual just beyond the
// width is scaled to just above it, give or take rounding, so those within
// a hair of the width do not count as inside it.
bool unscaled_by(const LossFunction& loss, double stored) {
  constexpr double kWidthMargin = 1.0 - 1e-9;
  return loss.kind == LossKind::kHuber && loss.width > 0.0 ? std::abs(stored) <= kWidthMargin * loss.width
                                                           : loss.quadratic_at(stored);
}

// The whitened residual of every reading at the problem's current values,
// where `lm`'s last solve ended with the readings' loss as it is now. A
// factor whose reading rows that loss left as least squares would is read
// from that solve's last linearisation (the same bits: a factor's
// residuals do not depend on whether its Jacobian is wanted); any other is
// evaluated again without the loss.
std::vector<ReadingResidual> reading_residuals(const BuiltProblem& built, const LevenbergMarquardt& lm,
                                               const CalibrationOptions& options, int reference_cable) {
  const LossFunction kept = *built.reading_loss;
  *built.reading_loss = LossFunction{};
  std::vector<ReadingResidual> out;
  std::vector<double> evaluated;
  const auto& factors = built.problem->factors();
  // The factor's residuals without the loss, or an empty span when it cannot be evaluated.
  auto residuals = [&](int f, std::span<const int> reading_rows) -> std::span<const double> {
    const std::span<const double> stored = lm.last_residuals(f);
    const bool reusable = stored.size() == static_cast<std::size_t>(factors[f]->residual_dim()) &&
                          std::all_of(reading_rows.begin(), reading_rows.end(),
                                      [&](int row) { return unscaled_by(kept, stored[row]); });
    if (reusable) return stored;
    evaluated.assign(factors[f]->residual_dim(), 0.0);
    double cost = 0.0;
    if (!factors[f]->evaluate(parameter_blocks(*built.problem, *factors[f]).data(), evaluated.data(), nullptr,
                              &cost)) {
      return {};
    }
    return evaluated;
  };
  constexpr std::array<int, 1> kRigidRows = {0};
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    const int id = built.samples[k].id;
    if (options.cable_model == CableModelKind::kCatenary) {
      const std::span<const double> residual = residuals(built.reading_factor[k], kReadingRows);
      if (residual.empty()) continue;
      const Sample& sample = built.samples[k];
      for (int i = 0; i < kCableCount; ++i) {
        if (!sample.encoder_left_out[i]) out.push_back({id, SensorKind::kEncoder, i, residual[encoder_row(i)]});
      }
      if (!sample.force_left_out) out.push_back({id, SensorKind::kForce, reference_cable, residual[kForceRow]});
    } else {
      for (int i = 0; i < kCableCount; ++i) {
        const std::span<const double> residual = residuals(built.reading_factor[k] + i, kRigidRows);
        if (!residual.empty()) out.push_back({id, SensorKind::kEncoder, i, residual[0]});
      }
    }
  }
  *built.reading_loss = kept;
  return out;
}

// The readings left out of a catenary fit as it predicts them: each row's
// factor evaluated again without its mask, normalised by the spread of the
// readings that were fitted.
std::vector<SensorReading> left_out_residuals(const Robot& robot, const BuiltProblem& built,
                                              const LevenbergMarquardt& lm, const CalibrationOptions& options) {
  std::vector<SensorReading> out;
  // Clean data leave nothing out: no spreads to evaluate every factor for.
  if (std::none_of(built.samples.begin(), built.samples.end(),
                   [](const Sample& s) { return left_out_rows(s).count > 0; })) {
    return out;
  }
  const ReadingSpreads spreads = reading_spreads(reading_residuals(built, lm, options, robot.reference_cable));
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    const Sample& sample = built.samples[k];
    if (left_out_rows(sample).count == 0) continue;
    Sample whole = sample;
    whole.encoder_left_out = {};
    whole.force_left_out = false;
    const EffectPoseFactor factor(robot, static_cast<int>(k), whole, options.height_sigma_m, Loss{}, options.effects);
    std::vector<double> residual(factor.residual_dim(), 0.0);
    double cost = 0.0;
    if (!factor.evaluate(parameter_blocks(*built.problem, factor).data(), residual.data(), nullptr, &cost)) continue;
    for (int i = 0; i < kCableCount; ++i) {
      if (!sample.encoder_left_out[i]) continue;
      out.push_back({sample.id, SensorKind::kEncoder, i, residual[encoder_row(i)] / spreads.encoder});
    }
    if (sample.force_left_out) {
      out.push_back({sample.id, SensorKind::kForce, robot.reference_cable, residual[kForceRow] / spreads.force});
    }
  }
  return out;
}

// Reading factor `factor`'s part of `lm`'s last linearisation (its pose
// prior precedes it); empty when a block is missing (a variable held
// constant, or a linearisation not made).
std::optional<FittedRowLinearization> row_linearization(const LevenbergMarquardt& lm, int factor) {
  using Row = FittedRowLinearization;
  Row row;
  auto take = [](std::span<const double> from, double* to, std::size_t size) {
    if (from.size() != size) return false;
    std::copy(from.begin(), from.end(), to);
    return true;
  };
  if (!take(lm.last_residuals(factor), row.residual.data(), row.residual.size()) ||
      !take(lm.last_residuals(factor - 1), row.prior_residual.data(), row.prior_residual.size()) ||
      !take(lm.last_jacobian(factor - 1, 0), row.prior_jacobian.data(), row.prior_jacobian.size())) {
    return std::nullopt;
  }
  constexpr std::array<int, EffectPoseFactor::kBaseKeyCount> kBlockDims = {6, 2, 3, 3, 3, 3, 1, 1, 1, 1};
  static_assert(std::accumulate(kBlockDims.begin(), kBlockDims.end(), 0) == Row::kColumns);
  double* block = row.jacobian.data();
  for (int key = 0; key < EffectPoseFactor::kBaseKeyCount; ++key) {
    const std::size_t size = static_cast<std::size_t>(Row::kRows) * kBlockDims[key];
    if (!take(lm.last_jacobian(factor, key), block, size)) return std::nullopt;
    block += size;
  }
  return row;
}

// Residual rows (less the readings left out) less free tangent columns.
int degrees_of_freedom(const Problem& problem, const std::vector<Sample>& samples) {
  int rows = 0, columns = 0;
  for (const auto& factor : problem.factors()) rows += factor->residual_dim();
  for (const Sample& s : samples) rows -= left_out_rows(s).count;
  for (const Problem::Variable& v : problem.variables()) columns += v.constant ? 0 : v.tangent_dim;
  return rows - columns;
}

// Whether the linearisation the last solve ended with is, bit for bit, what
// the factors give with `next` as the readings' loss instead of `current`:
// both leave every reading row as least squares would (no other row sees
// the readings' loss). The stored residuals are after `current`'s scaling.
bool same_linearization(const BuiltProblem& built, const LevenbergMarquardt& lm, const LossFunction& current,
                        const LossFunction& next, bool catenary) {
  auto quadratic = [&](int factor, int row) {
    const std::span<const double> r = lm.last_residuals(factor);
    if (static_cast<std::size_t>(row) >= r.size()) return false;
    return unscaled_by(current, r[row]) && next.quadratic_at(r[row]);
  };
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    const int first = built.reading_factor[k];
    if (catenary) {
      for (int row : kReadingRows) {
        if (!quadratic(first, row)) return false;
      }
    } else {
      for (int i = 0; i < kCableCount; ++i) {
        if (!quadratic(first + i, 0)) return false;
      }
    }
  }
  return true;
}

// The robust stages (CalibrationOptions::robust) on a built problem: Huber,
// then Cauchy when a reading still stands out, then the gross-error test.
// Returns the gross errors (empty on clean data); `summary` accumulates.
std::vector<SensorReading> robust_stages(BuiltProblem& built, LevenbergMarquardt& lm, const CalibrationOptions& options,
                                         int reference_cable, SolverSummary& summary, int& iterations) {
  // Widths in sigma: the 95 %-efficient Huber width is 1.345; 3 leaves
  // clean data at (or within a step of) the least-squares minimum.
  constexpr double kHuberWidth = 3.0;
  constexpr double kCauchyWidth = 3.0;
  auto stage = [&](LossFunction loss) {
    *built.reading_loss = loss;
    lm.set_max_iterations(std::max(options.max_iterations - iterations, 0));
    const SolverSummary s = lm.solve();
    record_stage(loss.kind == LossKind::kHuber ? "robust fit, Huber" : "robust fit, Cauchy", s.message, s.iterations,
                 s.final_cost);
    if (iterations == 0) summary.initial_cost = s.initial_cost;
    iterations += s.iterations;
    summary.iterations = iterations;
    summary.successful_steps += s.successful_steps;
    summary.termination = s.termination;
    summary.message = s.message;
    summary.final_cost = s.final_cost;
    return s.usable();
  };
  if (!stage({LossKind::kHuber, kHuberWidth})) return {};
  const double largest = largest_normalised_residual(reading_residuals(built, lm, options, reference_cable));
  if (largest <= options.rejection_threshold_sigma) return {};
  if (!stage({LossKind::kCauchy, kCauchyWidth})) return {};
  const std::vector<ReadingResidual> residuals = reading_residuals(built, lm, options, reference_cable);
  const std::vector<SensorReading> flagged = gross_errors(residuals, options.rejection_threshold_sigma);
  if (flagged.empty()) {
    record_stage("gross-error test", "no reading beyond the threshold at the Cauchy fit");
    return {};
  }
  // Leave-one-out names the reading of each flagged row (solver/calibration/row_attribution.h).
  const ReadingSpreads spreads = reading_spreads(residuals);
  const LossFunction kept = *built.reading_loss;
  *built.reading_loss = LossFunction{};
  std::vector<int> rows;
  for (const SensorReading& r : flagged) rows.push_back(r.row);
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  std::vector<SensorReading> named;
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    if (!std::binary_search(rows.begin(), rows.end(), built.samples[k].id)) continue;
    const int first = built.reading_factor[k];
    const bool catenary = options.cable_model == CableModelKind::kCatenary;
    std::vector<int> row_factors{first - 1};  // the pose prior precedes the readings
    std::vector<RowReading> readings;
    for (int i = 0; i < kCableCount; ++i) {
      readings.push_back({catenary ? first : first + i, catenary ? encoder_row(i) : 0, SensorKind::kEncoder, i,
                          spreads.encoder});
      if (!catenary) row_factors.push_back(first + i);
    }
    if (catenary) {
      row_factors.push_back(first);
      readings.push_back({first, kForceRow, SensorKind::kForce, reference_cable, spreads.force});
    }
    for (const SensorReading& r : attribute_row(*built.problem, built.samples[k].id, static_cast<int>(k), row_factors,
                                                readings, options.rejection_threshold_sigma)) {
      named.push_back(r);
    }
  }
  *built.reading_loss = kept;
  std::sort(named.begin(), named.end(),
            [](const SensorReading& a, const SensorReading& b) { return std::abs(a.value) > std::abs(b.value); });
  record_stage("gross-error test", std::to_string(flagged.size()) + " readings beyond the threshold on " +
                                       std::to_string(rows.size()) + " rows; leave-one-out names " +
                                       std::to_string(named.size()) + " of them");
  return named;
}

}  // namespace

CalibrationResult calibrate_once(const Robot& robot, const std::vector<Sample>& all_samples,
                                 const CalibrationOptions& options) {
  CalibrationResult result;
  BuiltProblem built = build_calibration_problem(robot, all_samples, options);
  result.rejected_samples = built.rejected_samples;
  if (!built.problem) {
    result.message = built.message;
    record_stage("start", built.message);
    return result;
  }
  if (!built.rejected_samples.empty()) {
    std::string ids;
    for (int id : built.rejected_samples) ids += (ids.empty() ? "" : ", ") + std::to_string(id);
    record_stage("start", std::to_string(built.rejected_samples.size()) + " of " +
                              std::to_string(all_samples.size()) +
                              " rows cannot be started from these anchors (ids " + ids + ")");
  }
  const std::vector<Sample>& samples = built.samples;
  Problem& problem = *built.problem;
  const bool catenary = options.cable_model == CableModelKind::kCatenary;

  SolverOptions solver_options;
  solver_options.max_iterations = options.max_iterations;
  solver_options.progress = options.progress;
  LevenbergMarquardt lm(problem, solver_options);
  int iterations = 0;
  SolverSummary robust_summary;
  if (options.robust) {
    result.gross_errors = robust_stages(built, lm, options, robot.reference_cable, robust_summary, iterations);
    if (!robust_summary.usable()) {
      result.solver = robust_summary;
      result.message = robust_summary.message + " (in the robust fit)";
      return result;
    }
    if (!result.gross_errors.empty()) {
      result.message = "gross errors found; refit without them";
      Calibration& cal = result.calibration;
      cal.winches.resize(kCableCount);
      for (int i = 0; i < kCableCount; ++i) cal.winches[i].anchor_world = problem.vector(AnchorKey(i));
      return result;
    }
  }
  const LossFunction final_loss{LossKind::kHuber, options.huber_width};
  // On clean data the robust stage ends where its loss and the final one
  // are both quadratic at every reading: its last linearisation is the
  // final fit's first. When the robust stage also converged there, that
  // point is the final fit's minimum: the final cost, gradient and
  // curvature are the robust stage's own, so the final solve would only
  // confirm it with one more step. What reads the last linearisation below
  // (covariance, reading residuals, fitted rows) then reads the robust
  // stage's, which is bit for bit the final loss's.
  const bool same = options.robust && same_linearization(built, lm, *built.reading_loss, final_loss, catenary);
  *built.reading_loss = final_loss;
  const char* final_name = options.huber_width > 0.0 ? "final fit, Huber" : "final fit, least squares";
  if (same && robust_summary.termination == TerminationType::kConverged) {
    result.solver = robust_summary;
    record_stage(final_name, "the robust fit's minimum: its loss was quadratic at every reading", 0,
                 robust_summary.final_cost);
  } else {
    if (same) lm.reuse_last_linearization();
    lm.set_max_iterations(std::max(options.max_iterations - iterations, 0));
    result.solver = lm.solve();
    record_stage(final_name, result.solver.message, result.solver.iterations, result.solver.final_cost);
    if (iterations > 0) result.solver.initial_cost = robust_summary.initial_cost;
    result.solver.iterations += iterations;
    result.solver.successful_steps += robust_summary.successful_steps;
  }
  result.message = result.solver.message;
  if (!result.solver.usable()) return result;
  std::vector<Key> globals;
  for (int i = 0; i < kCableCount; ++i) {
    globals.push_back(AnchorKey(i));
    globals.push_back(OffsetKey(i));
  }
  for (Effect e : options.effects) globals.push_back(EffectKey(e));
  // The solve left the values and the loss as they are now.
  lm.reuse_last_linearization();
  const Eigen::MatrixXd covariance = lm.covariance(globals);
  result.global_keys = globals;
  result.global_covariance = covariance;

  Calibration& cal = result.calibration;
  cal.model = {catenary ? "catenary" : "rigid"};
  for (int base = 4 * kCableCount; Effect e : options.effects) {
    FittedEffect fitted{e, {}, {}};
    const Eigen::VectorXd value = problem.vector(EffectKey(e));
    for (int j = 0; j < effect_dimension(e); ++j) {
      fitted.value.push_back(value(j));
      fitted.sigma.push_back(covariance.size() > 0 ? std::sqrt(covariance(base + j, base + j)) : 0.0);
    }
    base += effect_dimension(e);
    cal.model.emplace_back(effect_model_name(e));
    add_effect_values(e, fitted.value, fitted.sigma, cal.effects);
    result.effects.push_back(std::move(fitted));
  }
  cal.samples = static_cast<int>(samples.size());
  cal.winches.resize(kCableCount);
  for (int i = 0; i < kCableCount; ++i) {
    WinchCalibration& w = cal.winches[i];
    w.anchor_world = problem.vector(AnchorKey(i));
    w.offset_m = problem.vector(OffsetKey(i))(0);
    if (covariance.size() > 0) {
      const int base = 4 * i;  // anchor (3) then offset (1) per cable, in `globals` order
      for (int a = 0; a < 3; ++a) w.anchor_sigma(a) = std::sqrt(covariance(base + a, base + a));
      w.offset_sigma_m = std::sqrt(covariance(base + 3, base + 3));
    }
  }
  cal.fit.cost_initial = result.solver.initial_cost;
  cal.fit.cost_final = result.solver.final_cost;
  cal.fit.iterations = result.solver.iterations;
  fill_fit_rms(robot, samples, problem, options, cal.fit);
  if (catenary) {
    result.left_out_residuals = left_out_residuals(robot, built, lm, options);
    result.fitted_rows.reserve(samples.size());
    for (std::size_t k = 0; k < samples.size(); ++k) {
      const int pose = static_cast<int>(k);
      const int factor = built.reading_factor[k];  // its pose prior precedes it; keys: pose, reference force
      result.fitted_rows.push_back({samples[k], problem.pose(PoseKey(pose)), problem.vector(ReferenceForceKey(pose)),
                                    largest_studentised_residual(samples[k], lm.last_residuals(factor),
                                                                 lm.last_jacobian(factor, 0),
                                                                 lm.last_jacobian(factor, 1),
                                                                 lm.last_jacobian(factor - 1, 0)),
                                    options.effects.empty() ? row_linearization(lm, factor) : std::nullopt});
    }
  }
  result.chi_square = 2.0 * result.solver.final_cost;
  result.degrees_of_freedom = degrees_of_freedom(problem, samples);
  result.ok = covariance.size() > 0;
  if (!result.ok) result.message += "; the fit's information matrix is singular: parameters not observable";
  return result;
}

}  // namespace cdpr
