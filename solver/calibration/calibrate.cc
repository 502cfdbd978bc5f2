#include "solver/calibration/calibrate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>

#include "solver/model/cable_prediction.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/nls/factor_parameters.h"
#include "solver/calibration/gross_errors.h"
#include "solver/calibration/model_fit_check.h"
#include "solver/calibration/pose_factor_rows.h"
#include "solver/calibration/row_attribution.h"
#include "solver/calibration/start_selection.h"

namespace cdpr {
namespace {

using Anchors = std::array<Eigen::Vector3d, kCableCount>;

// Unweighted residual statistics at the solution, with plain least squares.
void fill_fit_rms(const Robot& robot, const std::vector<Sample>& samples, const Problem& problem,
                  const CalibrationOptions& options, FitSummary& fit) {
  Anchors anchors;
  for (int i = 0; i < kCableCount; ++i) anchors[i] = problem.vector(AnchorKey(i));
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
        const double r = (*cables)[i].arc_length_m + problem.vector(OffsetKey(i))(0) - samples[k].encoder_m[i];
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
        const double r = (b - anchors[i]).norm() + problem.vector(OffsetKey(i))(0) - samples[k].encoder_m[i];
        sum_encoder += r * r;
        ++n_encoder;
      }
    }
  }
  fit.rms_encoder_m = n_encoder ? std::sqrt(sum_encoder / n_encoder) : 0.0;
  fit.rms_force_n = n_force ? std::sqrt(sum_force / n_force) : 0.0;
}

// The whitened residual of every reading at the problem's current values.
std::vector<ReadingResidual> reading_residuals(const BuiltProblem& built, const CalibrationOptions& options,
                                               int reference_cable) {
  const LossFunction kept = *built.reading_loss;
  *built.reading_loss = LossFunction{};
  std::vector<ReadingResidual> out;
  std::vector<double> residual;
  const auto& factors = built.problem->factors();
  for (std::size_t k = 0; k < built.samples.size(); ++k) {
    const int id = built.samples[k].id;
    auto evaluate = [&](const Factor& factor) {
      residual.assign(factor.residual_dim(), 0.0);
      double cost = 0.0;
      return factor.evaluate(parameter_blocks(*built.problem, factor).data(), residual.data(), nullptr, &cost);
    };
    if (options.cable_model == CableModelKind::kCatenary) {
      if (!evaluate(*factors[built.reading_factor[k]])) continue;
      const Sample& sample = built.samples[k];
      for (int i = 0; i < kCableCount; ++i) {
        if (!sample.encoder_left_out[i]) out.push_back({id, SensorKind::kEncoder, i, residual[encoder_row(i)]});
      }
      if (!sample.force_left_out) out.push_back({id, SensorKind::kForce, reference_cable, residual[kForceRow]});
    } else {
      for (int i = 0; i < kCableCount; ++i) {
        if (evaluate(*factors[built.reading_factor[k] + i])) out.push_back({id, SensorKind::kEncoder, i, residual[0]});
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
                                              const CalibrationOptions& options) {
  std::vector<SensorReading> out;
  // Clean data leave nothing out: no spreads to evaluate every factor for.
  if (std::none_of(built.samples.begin(), built.samples.end(),
                   [](const Sample& s) { return left_out_rows(s).count > 0; })) {
    return out;
  }
  const ReadingSpreads spreads = reading_spreads(reading_residuals(built, options, robot.reference_cable));
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

// Residual rows (less the readings left out) less free tangent columns.
int degrees_of_freedom(const Problem& problem, const std::vector<Sample>& samples) {
  int rows = 0, columns = 0;
  for (const auto& factor : problem.factors()) rows += factor->residual_dim();
  for (const Sample& s : samples) rows -= left_out_rows(s).count;
  for (const Problem::Variable& v : problem.variables()) columns += v.constant ? 0 : v.tangent_dim;
  return rows - columns;
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
    if (iterations == 0) summary.initial_cost = s.initial_cost;
    iterations += s.iterations;
    summary.termination = s.termination;
    summary.message = s.message;
    summary.final_cost = s.final_cost;
    return s.usable();
  };
  if (!stage({LossKind::kHuber, kHuberWidth})) return {};
  const double largest = largest_normalised_residual(reading_residuals(built, options, reference_cable));
  if (largest <= options.rejection_threshold_sigma) return {};
  if (!stage({LossKind::kCauchy, kCauchyWidth})) return {};
  const std::vector<ReadingResidual> residuals = reading_residuals(built, options, reference_cable);
  const std::vector<SensorReading> flagged = gross_errors(residuals, options.rejection_threshold_sigma);
  if (flagged.empty()) return {};
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
  return named;
}

// One fit: robust stages (when asked), then the final loss. When the robust
// stages find gross errors, returns them in result.gross_errors with the
// robust fit's anchors and ok = false, for the caller to refit without them.
CalibrationResult calibrate_once(const Robot& robot, const std::vector<Sample>& all_samples,
                                 const CalibrationOptions& options) {
  CalibrationResult result;
  BuiltProblem built = build_calibration_problem(robot, all_samples, options);
  result.rejected_samples = built.rejected_samples;
  if (!built.problem) {
    result.message = built.message;
    return result;
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
  *built.reading_loss = LossFunction{LossKind::kHuber, options.huber_width};
  lm.set_max_iterations(std::max(options.max_iterations - iterations, 0));
  result.solver = lm.solve();
  if (iterations > 0) result.solver.initial_cost = robust_summary.initial_cost;
  result.solver.iterations += iterations;
  result.message = result.solver.message;
  if (!result.solver.usable()) return result;
  std::vector<Key> globals;
  for (int i = 0; i < kCableCount; ++i) {
    globals.push_back(AnchorKey(i));
    globals.push_back(OffsetKey(i));
  }
  for (Effect e : options.effects) globals.push_back(EffectKey(e));
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
  if (catenary) result.left_out_residuals = left_out_residuals(robot, built, options);
  result.chi_square = 2.0 * result.solver.final_cost;
  result.degrees_of_freedom = degrees_of_freedom(problem, samples);
  result.ok = covariance.size() > 0;
  if (!result.ok) result.message += "; the fit's information matrix is singular: parameters not observable";
  return result;
}

}  // namespace

namespace {

// Sets of at most this many rows, where one row is a large share of the
// data, get the leave-one-row-out hypotheses and the swap test: each is a
// handful of full fits, too many for large sets, which do not need them.
constexpr std::size_t kSmallSetRows = 20;

// "; N readings with gross errors left out" on a fit's message.
void note_left_out(CalibrationResult& fit) {
  fit.message += "; " + std::to_string(fit.gross_errors.size()) + " readings with gross errors left out";
}

bool has_anchors(const CalibrationResult& result) {
  return result.calibration.winches.size() == static_cast<std::size_t>(kCableCount);
}

// `robot` with the anchors of a fit as its nominal ones: a start for another fit.
Robot started_at(const Robot& robot, const CalibrationResult& fit) {
  Robot start = robot;
  for (int i = 0; i < kCableCount; ++i) start.winches[i].anchor_world = fit.calibration.winches[i].anchor_world;
  return start;
}

// The share of rows with a gross error.
double gross_error_row_fraction(const CalibrationResult& result, std::size_t rows) {
  std::vector<int> ids;
  for (const SensorReading& r : result.gross_errors) ids.push_back(r.row);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return rows ? static_cast<double>(ids.size()) / static_cast<double>(rows) : 0.0;
}

CalibrationResult calibrate_with_restart(const Robot& robot, const std::vector<Sample>& samples,
                                         const CalibrationOptions& options) {
  // A fit to keep: converged, or gross errors to leave out that are few
  // enough (a start that ended in a wrong minimum makes many rows look bad).
  auto usable = [&](const CalibrationResult& r) {
    return r.ok || (!r.gross_errors.empty() &&
                    gross_error_row_fraction(r, samples.size()) <= options.max_rejected_fraction);
  };
  CalibrationResult first = calibrate_once(robot, samples, options);
  if (usable(first) || options.cable_model != CableModelKind::kCatenary) return first;
  auto restart_from = [&](const CalibrationResult& coarse) {
    Robot restart = robot;
    for (int i = 0; i < kCableCount; ++i) restart.winches[i].anchor_world = coarse.calibration.winches[i].anchor_world;
    return calibrate_once(restart, samples, options);
  };
  // A tight Eq. (15) makes the cost landscape narrow; far from the solution
  // LM can stall where the anchors are unobservable. Continuation: solve with
  // a ten times looser height consistency from the nominal anchors, then
  // with the requested one from there.
  CalibrationOptions loose = options;
  loose.height_sigma_m *= 10.0;
  const CalibrationResult coarse = calibrate_once(robot, samples, loose);
  std::string why = "from the nominal anchors: " + first.message;
  if (!coarse.calibration.winches.empty()) {
    CalibrationResult second = restart_from(coarse);
    if (usable(second)) {
      second.message += " (after a restart with a looser height consistency: the first solve stopped where the "
                        "anchors were unobservable)";
      return second;
    }
    why += "; after a looser height consistency: " + second.message;
  } else {
    why += "; with a looser height consistency: " + coarse.message;
  }
  // Straight cables have no sag to start and converge from farther away: a
  // rigid fit's anchors as the start.
  CalibrationOptions rigid = options;
  rigid.cable_model = CableModelKind::kRigid;
  rigid.effects.clear();
  const CalibrationResult straight = calibrate_once(robot, samples, rigid);
  if (!straight.calibration.winches.empty()) {
    CalibrationResult third = restart_from(straight);
    if (usable(third)) {
      third.message += " (started from a rigid fit's anchors: " + why + ")";
      return third;
    }
    why += "; from a rigid fit's anchors: " + third.message;
  } else {
    why += "; the rigid fit for a start failed too: " + straight.message;
  }
  if (first.gross_errors.empty()) first.message = "no start converged (" + why + ")";
  return first;
}

std::string rows_text(const std::vector<SensorReading>& readings) {
  std::string text;
  for (const SensorReading& r : readings) {
    char line[128];
    std::snprintf(line, sizeof line, "%srow %d %s%s %+.1f sigma", text.empty() ? "" : ", ", r.row,
                  sensor_name(r.sensor),
                  r.sensor == SensorKind::kEncoder ? (" " + std::to_string(r.cable)).c_str() : "", r.value);
    text += line;
  }
  return text;
}

// The gross errors left out, the fit redone by least squares from the
// robust fit's anchors.
CalibrationResult refit_without(const Robot& robot, const std::vector<Sample>& samples,
                                const CalibrationOptions& options, const CalibrationResult& robust) {
  // Refused when the readings flagged (a hypothesis row's readings are not
  // flagged, only tentative: the final test below decides them) or, after
  // the final test, those confirmed lie on more rows than allowed.
  auto refusal = [&](const std::vector<SensorReading>& readings) -> std::optional<CalibrationResult> {
    CalibrationResult refused = robust;
    refused.gross_errors = readings;
    const double fraction = gross_error_row_fraction(refused, samples.size());
    if (fraction <= options.max_rejected_fraction) return std::nullopt;
    refused.ok = false;
    refused.calibration.rejected.clear();
    char text[256];
    std::snprintf(text, sizeof text,
                  "%.0f of %zu rows (%.0f %%) have gross errors, more than the %.0f %% allowed: the robot or its "
                  "sensors need attention (or the model does not fit; see cdpr-calib diagnose). ",
                  std::round(fraction * static_cast<double>(samples.size())), samples.size(), 100.0 * fraction,
                  100.0 * options.max_rejected_fraction);
    refused.message = text + rows_text(readings);
    return refused;
  };
  std::vector<SensorReading> flagged;
  for (const SensorReading& r : robust.gross_errors) {
    if (std::isfinite(r.value)) flagged.push_back(r);
  }
  if (auto refused = refusal(flagged)) return *refused;
  const std::vector<Sample> kept = leave_out(samples, robust.gross_errors, options.cable_model);
  Robot restart = robot;
  for (int i = 0; i < kCableCount; ++i) restart.winches[i].anchor_world = robust.calibration.winches[i].anchor_world;
  CalibrationOptions plain = options;
  plain.robust = false;
  CalibrationResult refit = calibrate_with_restart(restart, kept, plain);
  // The final test: a left-out reading that the refit predicts within the
  // threshold was no gross error (a robust fit from far off can end where
  // good readings look bad); it goes back in and the fit is redone once.
  // Where the model misfits everywhere (chi2 / dof above 1) the bar rises
  // with the misfit: a reading then off by a few times the noise is the
  // missing effect's signature, which diagnose needs, not a gross error.
  const double misfit_scale =
      refit.degrees_of_freedom > 0 ? std::max(1.0, std::sqrt(refit.chi_square / refit.degrees_of_freedom)) : 1.0;
  const std::vector<SensorReading> confirmed = confirm_left_out(
      robust.gross_errors, refit.left_out_residuals, refit.ok, options.rejection_threshold_sigma * misfit_scale);
  if (confirmed.size() < robust.gross_errors.size()) {
    // A failed refit has no anchors: the robust fit's stay the start.
    if (has_anchors(refit)) {
      for (int i = 0; i < kCableCount; ++i) restart.winches[i].anchor_world = refit.calibration.winches[i].anchor_world;
    }
    refit = calibrate_with_restart(restart, leave_out(samples, confirmed, options.cable_model), plain);
  }
  if (auto refused = refusal(confirmed)) return *refused;
  refit.gross_errors = confirmed;
  refit.calibration.rejected = confirmed;
  if (refit.ok) note_left_out(refit);
  return refit;
}

// When the robust fit flags more rows than allowed on a small set, one
// high-leverage gross error may have pulled the fit into a basin where good
// rows look bad. Each row is left out in turn and the robust fit redone; the
// hypothesis that flags the fewest rows wins. Its flagged readings and every
// reading of the row it left out become the candidates to leave out: the
// final test in refit_without puts back those the refit predicts within the
// threshold. Nothing when the set is large or no hypothesis brings the
// flagged rows within the allowed fraction.
std::optional<CalibrationResult> consensus_start(const Robot& robot, const std::vector<Sample>& samples,
                                                 const CalibrationOptions& options) {
  if (samples.size() > kSmallSetRows || samples.size() < 3) return std::nullopt;
  std::optional<CalibrationResult> best;
  std::size_t best_row = 0;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    std::vector<Sample> rest = samples;
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(k));
    CalibrationResult fit = calibrate_with_restart(robot, rest, options);
    if (fit.calibration.winches.empty() || (!fit.ok && fit.gross_errors.empty())) continue;
    if (gross_error_row_fraction(fit, rest.size()) > options.max_rejected_fraction) continue;
    if (!best || fit.gross_errors.size() < best->gross_errors.size()) {
      best = std::move(fit);
      best_row = k;
    }
  }
  if (!best) return std::nullopt;
  CalibrationResult candidate = *best;
  candidate.ok = false;
  const int id = samples[best_row].id;
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  for (int i = 0; i < kCableCount; ++i) candidate.gross_errors.push_back({id, SensorKind::kEncoder, i, unknown});
  if (options.cable_model == CableModelKind::kCatenary) {
    candidate.gross_errors.push_back({id, SensorKind::kForce, robot.reference_cable, unknown});
  }
  return candidate;
}

// On a small set, a gross error can be absorbed and stay in while a good
// reading is left out in its place: by its row's pose and reference force
// once another reading of the row is left out (above all the load cell,
// whose absence frees both force components), or by its cable's anchor and
// offset, which then make the same cable's reading of another row look bad.
// A row may also hold two gross errors of which one was found. So for each
// reading left out, every other reading of its row is tried in its place
// and beside it, the same sensor of every other row in its place, and the
// reading itself back in; the fit is redone by least squares each time. The best
// change is kept when a reading it newly leaves out is predicted beyond the
// threshold and the fit explains the readings better (start_score) without
// starting to misfit; then the search starts over, a bounded number of times.
CalibrationResult swap_within_rows(const Robot& robot, const std::vector<Sample>& samples,
                                   const CalibrationOptions& options, CalibrationResult result) {
  if (samples.size() > kSmallSetRows || options.cable_model != CableModelKind::kCatenary || !result.ok) return result;
  CalibrationOptions plain = options;
  plain.robust = false;
  auto same = [](const SensorReading& a, const SensorReading& b) {
    return a.row == b.row && a.sensor == b.sensor && a.cable == b.cable;
  };
  auto left_out = [&](const SensorReading& in) {
    return std::any_of(result.gross_errors.begin(), result.gross_errors.end(),
                       [&](const SensorReading& r) { return same(r, in); });
  };
  // Each change of the set left out: the fit, or nothing when it is not kept.
  auto try_change = [&](std::vector<SensorReading> changed, const SensorReading* in) -> std::optional<CalibrationResult> {
    CalibrationResult refit =
        calibrate_with_restart(started_at(robot, result), leave_out(samples, changed, options.cable_model), plain);
    if (!refit.ok) return std::nullopt;
    if (in) {
      const auto predicted = std::find_if(refit.left_out_residuals.begin(), refit.left_out_residuals.end(),
                                          [&](const SensorReading& p) { return same(p, *in); });
      if (predicted == refit.left_out_residuals.end() ||
          !(std::abs(predicted->value) > options.rejection_threshold_sigma)) {
        return std::nullopt;
      }
      for (SensorReading& r : changed) {
        if (same(r, *in)) r.value = predicted->value;
      }
    }
    refit.gross_errors = changed;
    refit.calibration.rejected = changed;
    note_left_out(refit);
    assess_model_fit(refit, options);
    if (refit.misfit && !result.misfit) return std::nullopt;
    return refit;
  };
  const int max_changes = 2 * static_cast<int>(result.gross_errors.size()) + 2;
  for (int change = 0; change < max_changes; ++change) {
    std::optional<CalibrationResult> best;
    auto consider = [&](std::optional<CalibrationResult> fit) {
      if (fit && better_fit(*fit, best ? *best : result, options.rejection_threshold_sigma)) best = std::move(fit);
    };
    for (std::size_t g = 0; g < result.gross_errors.size(); ++g) {
      const SensorReading out = result.gross_errors[g];
      std::vector<SensorReading> peers;
      for (const Sample& sample : samples) {
        if (sample.id == out.row) {
          for (int i = 0; i < kCableCount; ++i) peers.push_back({out.row, SensorKind::kEncoder, i, 0.0});
          peers.push_back({out.row, SensorKind::kForce, robot.reference_cable, 0.0});
        } else {
          peers.push_back({sample.id, out.sensor, out.cable, 0.0});
        }
      }
      for (const SensorReading& in : peers) {
        if (left_out(in)) continue;
        std::vector<SensorReading> swapped = result.gross_errors;
        swapped[g] = in;
        consider(try_change(swapped, &in));
        if (in.row != out.row) continue;
        std::vector<SensorReading> beside = result.gross_errors;
        beside.push_back(in);
        consider(try_change(beside, &in));
      }
      std::vector<SensorReading> back = result.gross_errors;
      back.erase(back.begin() + static_cast<std::ptrdiff_t>(g));
      consider(try_change(back, nullptr));
    }
    if (!best) break;
    result = std::move(*best);
  }
  return result;
}

}  // namespace

std::vector<Sample> leave_out(const std::vector<Sample>& samples, const std::vector<SensorReading>& gross_errors,
                              CableModelKind cable_model) {
  std::vector<Sample> kept;
  for (Sample s : samples) {
    bool any = false;
    for (const SensorReading& r : gross_errors) {
      if (r.row != s.id) continue;
      any = true;
      if (r.sensor == SensorKind::kForce) s.force_left_out = true;
      else if (r.cable >= 0 && r.cable < kCableCount) s.encoder_left_out[r.cable] = true;
    }
    if (!any || cable_model == CableModelKind::kCatenary) kept.push_back(s);
  }
  return kept;
}

namespace {

// calibrate() from one start: the robust fit, the gross errors left out and
// the fit redone, the leave-one-row-out hypotheses on small sets.
CalibrationResult calibrate_from(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options) {
  CalibrationResult result = calibrate_with_restart(robot, samples, options);
  bool hypothesis = false;
  if (!result.ok && !result.gross_errors.empty() &&
      gross_error_row_fraction(result, samples.size()) > options.max_rejected_fraction) {
    if (auto candidate = consensus_start(robot, samples, options)) {
      result = std::move(*candidate);
      hypothesis = true;
    }
  }
  if (result.ok || result.gross_errors.empty()) {
    if (result.ok) assess_model_fit(result, options);
    return result;
  }
  const CalibrationResult robust = result;
  result = refit_without(robot, samples, options, robust);
  if (!result.ok) return result;
  assess_model_fit(result, options);
  if (hypothesis) return result;
  // On a small set, one gross error can be absorbed by its cable's anchor
  // and offset and stay in, while good readings are left out in its place,
  // and the fit may still pass the model-fit test. The leave-one-row-out
  // hypotheses get a chance: a fit that passes is replaced by the
  // hypothesis' fit when that explains the readings better (start_score,
  // solver/calibration/start_selection.h); a fit that misfits, by the one
  // with the smaller chi-square per degree of freedom (a genuine model
  // misfit stays flagged).
  if (auto candidate = consensus_start(robot, samples, options)) {
    CalibrationResult other = refit_without(robot, samples, options, *candidate);
    if (other.ok) {
      assess_model_fit(other, options);
      auto per_dof = [](const CalibrationResult& r) {
        return r.degrees_of_freedom > 0 ? r.chi_square / r.degrees_of_freedom
                                        : std::numeric_limits<double>::infinity();
      };
      const bool take = result.misfit ? per_dof(other) < per_dof(result)
                                      : !other.misfit && better_fit(other, result, options.rejection_threshold_sigma);
      if (take) result = std::move(other);
    }
  }
  return result;
}

// The anchors of a least-squares rigid fit from the nominal ones, as a start:
// straight cables have no sag to start and reach their minimum from farther
// away, and least squares keeps every reading in, so a start that a robust
// fit would have bent around one good reading cannot form here.
std::optional<Robot> rigid_start(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options) {
  CalibrationOptions rigid = options;
  rigid.cable_model = CableModelKind::kRigid;
  rigid.robust = false;
  rigid.huber_width = 0.0;
  rigid.effects.clear();
  rigid.progress = nullptr;
  const CalibrationResult fit = calibrate_once(robot, samples, rigid);
  if (!fit.ok || !has_anchors(fit)) return std::nullopt;
  return started_at(robot, fit);
}


// Multi-start (solver/calibration/start_selection.h): the fit's own anchors
// when its start could not take every row, then a rigid fit's, each of those
// again from its own anchors when it left rows out; the best fit is kept.
CalibrationResult best_of_starts(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options, CalibrationResult best) {
  const double threshold = options.rejection_threshold_sigma;
  auto consider = [&](CalibrationResult other, const char* why) {
    if (!better_fit(other, best, threshold)) return;
    other.message += std::string(" (kept from ") + why + ": it fits the readings better than the fit from the "
                     "nominal anchors)";
    best = std::move(other);
  };
  auto with_every_row = [&](const CalibrationResult& fit, const char* why) {
    if (fit.ok && !fit.rejected_samples.empty() && has_anchors(fit)) {
      consider(calibrate_from(started_at(robot, fit), samples, options), why);
    }
  };
  with_every_row(best, "a restart from the fit's own anchors, where every row could be started");
  if (const std::optional<Robot> start = rigid_start(robot, samples, options)) {
    CalibrationResult from_rigid = calibrate_from(*start, samples, options);
    const CalibrationResult kept = from_rigid;
    consider(std::move(from_rigid), "a start at a rigid fit's anchors");
    with_every_row(kept, "a start at a rigid fit's anchors, then its own");
  }
  return best;
}

}  // namespace

CalibrationResult calibrate(const Robot& robot, const std::vector<Sample>& samples, const CalibrationOptions& options) {
  CalibrationResult first = calibrate_from(robot, samples, options);
  if (!options.robust || options.cable_model != CableModelKind::kCatenary || !worth_other_starts(first)) return first;
  // The set the kept fit left out gets its swap test once, at the end.
  return swap_within_rows(robot, samples, options, best_of_starts(robot, samples, options, std::move(first)));
}

}  // namespace cdpr

