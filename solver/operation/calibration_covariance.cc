#include "solver/operation/calibration_covariance.h"

#include <algorithm>
#include <cmath>

#include "solver/nls/levenberg_marquardt.h"
#include "solver/nls/problem.h"
#include "solver/operation/calibration_variables.h"
#include "solver/operation/rest_problem.h"

namespace cdpr {
namespace {

std::optional<CalibrationCovariance> no_covariance(std::string* why, const std::string& what) {
  if (why) *why = what;
  return std::nullopt;
}

}  // namespace

std::optional<CalibrationCovariance> calibration_covariance(const Robot& robot, const Calibration& calibration,
                                                            const std::vector<Sample>& samples,
                                                            double height_sigma_m, std::string* why) {
  if (samples.empty()) return no_covariance(why, "no calibration samples");
  std::string problem_why;
  const std::optional<std::vector<Effect>> effects = calibration_effects(calibration, &problem_why);
  if (!effects) return no_covariance(why, problem_why);
  Problem problem;
  if (!add_calibration_variables(problem, calibration, *effects, CalibrationUncertainty::kHeldConstant,
                                 &problem_why)) {
    return no_covariance(why, problem_why);
  }
  std::vector<Key> keys;
  for (int i = 0; i < kCableCount; ++i) keys.push_back(AnchorKey(i));
  for (int i = 0; i < kCableCount; ++i) keys.push_back(OffsetKey(i));
  for (const Key& key : keys) problem.set_constant(key, false);
  int index = 0;
  for (const Sample& sample : samples) {
    if (!has_measured_pose(sample)) continue;
    const Pose measured{sample.position_world, sample.world_R_platform};
    const std::optional<RestStart> start = rest_start(robot, calibration, sample, measured, &problem_why);
    if (!start) continue;  // a row the committed values cannot hold: left out, as a gross error was
    problem.add_pose(PoseKey(index), Pose{measured.position_world, start->world_T_platform.world_R_platform});
    problem.add_vector(ReferenceForceKey(index), start->reference_force);
    problem.add_factor(make_rest_factor(robot, index, sample, *effects, height_sigma_m));
    problem.add_factor(make_measured_pose_factor(robot, index, sample));
    ++index;
  }
  if (index == 0) return no_covariance(why, "no calibration sample with a measured pose and an equilibrium");

  SolverOptions options;
  options.max_iterations = 50;
  LevenbergMarquardt lm(problem, options);
  const SolverSummary summary = lm.solve();
  if (!summary.usable()) return no_covariance(why, "the calibration's fit failed: " + summary.message);
  const Eigen::MatrixXd covariance = lm.covariance(keys);
  if (covariance.rows() != kCalibrationDimension || !covariance.allFinite()) {
    return no_covariance(why, "the calibration's anchors and offsets are not observable from its samples");
  }
  // The committed sigmas may be scaled up for a misfit (calibration.h): keep
  // the larger scale, never shrink them.
  double scale = 1.0;
  for (int i = 0; i < kCableCount; ++i) {
    const WinchCalibration& w = calibration.winches[i];
    const double fitted = covariance(kCalibrationDimension - kCableCount + i, kCalibrationDimension - kCableCount + i);
    if (fitted > 0.0 && w.offset_sigma_m > 0.0) scale = std::max(scale, w.offset_sigma_m * w.offset_sigma_m / fitted);
  }
  return CalibrationCovariance(covariance * std::min(scale, 100.0));
}

}  // namespace cdpr
