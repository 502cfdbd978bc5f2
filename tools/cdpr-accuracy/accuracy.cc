#include "cdpr-accuracy/accuracy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "sim/dataset.h"
#include "solver/calibration/pose_design.h"

namespace cdpr::accuracy {

namespace {

// "row 12 encoder 2 (+0.83): <why>" for a planted reading not reported:
// put on other readings of its row (named), or its row kept whole.
std::string miss_text(const SensorReading& p, const std::vector<SensorReading>& rejected,
                      const std::vector<SensorReading>& planted) {
  std::string others;
  for (const SensorReading& r : rejected) {
    if (r.row != p.row) continue;
    const bool bad = std::any_of(planted.begin(), planted.end(), [&](const SensorReading& q) {
      return q.row == r.row && q.sensor == r.sensor && (q.sensor == SensorKind::kForce || q.cable == r.cable);
    });
    others += std::string(others.empty() ? "" : ", ") + sensor_name(r.sensor) +
              (r.sensor == SensorKind::kEncoder ? " " + std::to_string(r.cable) : "") + (bad ? " (planted)" : "");
  }
  char text[160];
  std::snprintf(text, sizeof text, "row %d %s%s (%+.2f): ", p.row, sensor_name(p.sensor),
                p.sensor == SensorKind::kEncoder ? (" " + std::to_string(p.cable)).c_str() : "", p.value);
  return text + (others.empty() ? std::string("its row kept whole") : "its row's " + others + " left out");
}

void score_gross_errors(const std::vector<SensorReading>& planted, const std::vector<SensorReading>& rejected, int rows,
                        RunResult& run) {
  constexpr double kRecallFloorM = 0.3;  // encoder errors this large must all be found
  auto found = [&](const SensorReading& p) {
    return std::any_of(rejected.begin(), rejected.end(), [&](const SensorReading& r) {
      return r.row == p.row && r.sensor == p.sensor && (p.sensor == SensorKind::kForce || r.cable == p.cable);
    });
  };
  std::vector<bool> planted_row(rows, false), rejected_row(rows, false);
  for (const SensorReading& p : planted) {
    if (p.row >= 0 && p.row < rows) planted_row[p.row] = true;
    if (p.sensor == SensorKind::kEncoder && std::abs(p.value) >= kRecallFloorM) {
      ++run.planted_encoder;
      run.recalled_encoder += found(p);
    } else if (p.sensor == SensorKind::kForce) {
      ++run.planted_force;
      run.recalled_force += found(p);
    } else {
      continue;
    }
    if (!found(p)) run.missed.push_back(miss_text(p, rejected, planted));
  }
  for (const SensorReading& r : rejected) {
    if (r.row >= 0 && r.row < rows) rejected_row[r.row] = true;
  }
  for (int k = 0; k < rows; ++k) {
    if (planted_row[k]) continue;
    ++run.clean_rows;
    run.clean_rows_rejected += rejected_row[k];
  }
}

}  // namespace

RunResult run_case(const Case& c, std::uint64_t seed) {
  RunResult run;
  run.seed = seed;
  sim::DatasetConfig config;
  config.preset = c.preset;
  config.pose_count = c.poses;
  config.seed = seed;
  config.anchor_perturbation_m = c.anchor_perturbation_m;
  config.noise_scale = c.noise_scale;
  config.workspace_min = c.workspace_min;
  config.workspace_max = c.workspace_max;
  config.design_candidates = c.design_candidates;
  config.gross_errors = c.gross_errors;
  config.effects = c.effects;
  const auto data = sim::simulate_dataset(config);
  if (!data) {
    run.message = "simulation failed: " + data.error();
    return run;
  }
  CalibrationOptions options;
  options.cable_model = c.model;
  options.max_iterations = c.max_iterations;
  const CalibrationResult result = calibrate(data->nominal, data->samples, options);
  run.ok = result.ok;
  run.message = result.message;
  run.iterations = result.solver.iterations;
  run.misfit = result.misfit;
  run.refused = !result.ok && !result.gross_errors.empty();
  run.chi_square_ratio = result.degrees_of_freedom > 0 ? result.chi_square / result.degrees_of_freedom : 0.0;
  run.cost_final = result.solver.final_cost;
  score_gross_errors(data->truth.outliers, result.gross_errors, static_cast<int>(data->samples.size()), run);
  if (c.compare_truth_start) {
    Robot at_truth = data->nominal;
    for (std::size_t i = 0; i < at_truth.winches.size(); ++i) {
      at_truth.winches[i].anchor_world = data->truth.winches[i].anchor_world;
    }
    const CalibrationResult reference = calibrate(at_truth, data->samples, options);
    run.truth_start_ok = result.ok && reference.ok;
    if (run.truth_start_ok) {
      run.truth_start_cost_gap = (result.solver.final_cost - reference.solver.final_cost) /
                                 std::max(reference.solver.final_cost, 1e-300);
    }
  }
  const std::vector<WinchTruth>& truth = data->truth.winches;
  const int n = static_cast<int>(truth.size());
  std::vector<Pose> true_poses;
  for (const sim::Equilibrium& state : data->states) true_poses.push_back(state.world_T_platform);
  const DesignInformation bound = design_covariance(data->true_robot.robot, true_poses);
  for (int i = 0; i < n; ++i) run.straight_bound_m += std::sqrt(bound.block<3, 3>(3 * i, 3 * i).trace()) / n;
  for (int i = 0; i < n; ++i) {
    if (!result.ok) {
      // Scored as no calibration at all: the nominal guess stays in force.
      run.anchor_error_m += (data->nominal.winches[i].anchor_world - truth[i].anchor_world).norm() / n;
      run.offset_error_m += std::abs(truth[i].offset_m) / n;
      continue;
    }
    const WinchCalibration& w = result.calibration.winches[i];
    const Eigen::Vector3d error = w.anchor_world - truth[i].anchor_world;
    const double offset_error = w.offset_m - truth[i].offset_m;
    run.anchor_error_m += error.norm() / n;
    run.offset_error_m += std::abs(offset_error) / n;
    run.reported_sigma_m += w.anchor_sigma.norm() / n;
    run.normalised_sq_sum += error.cwiseQuotient(w.anchor_sigma).squaredNorm() + std::pow(offset_error / w.offset_sigma_m, 2);
    run.normalised_count += 4;
  }
  return run;
}

Distribution distribution(std::vector<double> values) {
  Distribution d;
  if (values.empty()) return d;
  std::sort(values.begin(), values.end());
  for (double v : values) d.mean += v / static_cast<double>(values.size());
  const auto at = [&](double q) { return values[std::min(values.size() - 1, static_cast<std::size_t>(q * (values.size() - 1) + 0.5))]; };
  d.median = at(0.5);
  d.p90 = at(0.9);
  d.worst = values.back();
  return d;
}

Summary summarise(const std::vector<RunResult>& runs) {
  Summary s;
  s.runs = static_cast<int>(runs.size());
  std::vector<double> anchors, offsets;
  double sq = 0.0, iterations = 0.0;
  int count = 0;
  for (const RunResult& r : runs) {
    if (r.ok) s.mean_reported_sigma_m += r.reported_sigma_m;
    s.mean_straight_bound_m += r.straight_bound_m / static_cast<double>(runs.size());
    anchors.push_back(r.anchor_error_m);
    offsets.push_back(r.offset_error_m);
    if (!r.ok) ++s.failures;
    sq += r.normalised_sq_sum;
    count += r.normalised_count;
    iterations += r.iterations;
    s.planted_encoder += r.planted_encoder;
    s.recalled_encoder += r.recalled_encoder;
    s.planted_force += r.planted_force;
    s.recalled_force += r.recalled_force;
    s.clean_rows += r.clean_rows;
    s.clean_rows_rejected += r.clean_rows_rejected;
    s.misfits += r.misfit;
    s.refusals += r.refused;
    if (!r.truth_start_ok || std::abs(r.truth_start_cost_gap) > 1e-6) ++s.truth_start_mismatches;
    s.worst_truth_start_gap = std::max(s.worst_truth_start_gap, std::abs(r.truth_start_cost_gap));
  }
  s.anchor = distribution(anchors);
  s.offset = distribution(offsets);
  s.normalised_rms = count ? std::sqrt(sq / count) : 0.0;
  const int successes = s.runs - s.failures;
  s.mean_reported_sigma_m = successes ? s.mean_reported_sigma_m / successes : 0.0;
  s.mean_iterations = runs.empty() ? 0.0 : iterations / runs.size();
  return s;
}

}  // namespace cdpr::accuracy
