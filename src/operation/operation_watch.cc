#include "src/operation/operation_watch.h"

#include <cmath>

namespace cdpr::operation {

OperationWatch::OperationWatch(const Robot& robot, const calibration::EquilibriumThresholds& thresholds,
                               std::size_t capacity, const HealthWatchOptions& health)
    : robot_(robot), health_options_(health), rests_(thresholds, capacity, robot.noise) {}

void OperationWatch::set_calibration(int seq, std::optional<Calibration> calibration) {
  calibration_ = std::move(calibration);
  health_.reset();
  if (calibration_) health_ = std::make_unique<HealthWatch>(robot_, *calibration_, health_options_);
  refit_due_ = false;
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
  if (!health_) {
    outcome.why = "no calibration committed";
    status_.last_problem = outcome.why;
    return outcome;
  }
  const Sample& sample = outcome.rest.sample;
  const bool was_stale = health_->stale();
  RestCheck check = health_->add_rest(sample);
  outcome.pose = std::move(check.pose);
  outcome.why = check.why;
  if (health_->stale()) {
    note_finding(*health_->finding(), now_us);
    if (!was_stale) refit_due_ = true;
  }
  if (!outcome.pose) {
    status_.last_problem = outcome.why;
    return outcome;
  }
  ++status_.localized;
  status_.last_problem.clear();
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

void OperationWatch::note_finding(const StaleFinding& f, hal::TimeUs now_us) {
  const bool first = !status_.finding;
  FindingSummary s;
  s.term = fault_term_name(f.term.term, f.term.cable);
  s.meaning = fault_term_meaning(f.term.term, f.term.cable);
  s.cable = f.term.cable;
  s.value.assign(f.term.value.data(), f.term.value.data() + f.term.value.size());
  s.sigma.assign(f.term.sigma.data(), f.term.sigma.data() + f.term.sigma.size());
  s.since_rest = f.since_rest;
  s.fired_at_rest = f.fired_at_rest;
  s.fired_us = first ? now_us : status_.finding->fired_us;
  s.rests_fitted = f.rests_fitted;
  s.calibration_fault = f.calibration_fault();
  for (const TermEstimate& alike : f.alike) s.alike.push_back(fault_term_name(alike.term, alike.cable));
  status_.finding = std::move(s);
  status_.state = "calibration stale";
}

std::optional<Calibration> OperationWatch::take_refit(std::vector<Sample>& rests, std::string* why) {
  refit_due_ = false;
  if (!health_ || !health_->finding()) {
    if (why) *why = "nothing found";
    return std::nullopt;
  }
  rests = health_->rests_since_onset();
  return refit_from_rests(robot_, *calibration_, rests, refit_request_for(*health_->finding()), RefitOptions{}, why);
}

}  // namespace cdpr::operation
