#include "src/operation/operation_watch.h"

#include <cmath>

namespace cdpr::operation {

OperationWatch::OperationWatch(const Robot& robot, const calibration::EquilibriumThresholds& thresholds,
                               std::size_t capacity, const LocalizeOptions& localize)
    : robot_(robot), localize_(localize), rests_(thresholds, capacity, robot.noise) {}

void OperationWatch::set_calibration(int seq, std::optional<Calibration> calibration) {
  calibration_ = std::move(calibration);
  previous_.reset();
  status_ = OperationStatus{};
  status_.calibration_seq = seq;
  status_.state = calibration_ ? "waiting for a rest" : "no calibration";
}

std::optional<RestOutcome> OperationWatch::step(const WatchReadings& readings, hal::TimeUs now_us) {
  std::optional<WatchedRest> rest = rests_.step(readings, now_us);
  status_.detail = rests_.resting() ? "at rest" : calibration::to_string(rests_.last_check().verdict);
  if (!rest) return std::nullopt;
  ++status_.rests;
  RestOutcome outcome{std::move(*rest), std::nullopt, {}};
  if (!calibration_) {
    outcome.why = "no calibration committed";
    status_.last_problem = outcome.why;
    return outcome;
  }
  const Sample& sample = outcome.rest.sample;
  const Pose start = previous_ ? *previous_ : nominal_start(*calibration_, sample);
  outcome.pose = localize_rest(robot_, *calibration_, sample, start, localize_, &outcome.why);
  if (!outcome.pose) {
    status_.last_problem = outcome.why;
    return outcome;
  }
  ++status_.localized;
  status_.last_problem.clear();
  previous_ = outcome.pose->world_T_platform;
  if (status_.state == "waiting for a rest") status_.state = "watching";
  LocalizedRestSummary last;
  last.rest = outcome.rest.index;
  last.seen_us = now_us;
  last.position_world = outcome.pose->world_T_platform.position_world;
  last.position_sigma_m = outcome.pose->position_sigma();
  last.orientation_sigma_rad = outcome.pose->orientation_sigma();
  // The onboard pose's own sigma (the window mean's) adds to the cables' covariance.
  Eigen::Matrix<double, 6, 6> covariance = outcome.pose->covariance;
  const SampleSigmas onboard = reading_sigmas(robot_, sample);
  for (int k = 0; k < 3; ++k) {
    covariance(k, k) += onboard.position_m * onboard.position_m;
    covariance(k + 3, k + 3) += onboard.orientation_rad * onboard.orientation_rad;
  }
  const Pose measured{sample.position_world, sample.world_R_platform};
  last.onboard_sigmas =
      std::sqrt(mahalanobis_squared(pose_difference(measured, outcome.pose->world_T_platform), covariance));
  status_.last = last;
  return outcome;
}

}  // namespace cdpr::operation
