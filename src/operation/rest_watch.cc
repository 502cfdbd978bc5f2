#include "src/operation/rest_watch.h"

namespace cdpr::operation {

using calibration::EquilibriumVerdict;

RestWatch::RestWatch(const calibration::EquilibriumThresholds& thresholds, std::size_t capacity,
                     const NoiseSigmas& noise)
    : detector_(thresholds, capacity), noise_(noise) {}

std::optional<WatchedRest> RestWatch::step(const WatchReadings& r, hal::TimeUs now_us) {
  bool complete = r.pose && r.pose->valid && r.tension;
  for (const std::optional<double>& payout : r.payout_m) complete = complete && payout.has_value();
  if (!complete) {
    detector_.reset();
    last_pose_us_ = -1;
    settled_since_us_ = -1;
    check_ = {};
    return std::nullopt;
  }
  if (r.pose->source_time_us == last_pose_us_) return std::nullopt;  // one observation per pose
  last_pose_us_ = r.pose->source_time_us;
  calibration::EquilibriumObservation o;
  o.time_us = r.pose->source_time_us;
  o.position_world = {r.pose->platform_world.x, r.pose->platform_world.y, r.pose->platform_world.z};
  const hal::Quaternion& q = r.pose->world_R_platform;
  o.world_R_platform = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
  for (int i = 0; i < kCableCount; ++i) o.encoder_m[i] = *r.payout_m[i];
  o.tension_n = r.tension->tension_n;
  o.tension_stable = r.tension->stable;
  detector_.add(o);
  check_ = detector_.check();
  if (check_.verdict == EquilibriumVerdict::kMoving || check_.verdict == EquilibriumVerdict::kRotating) {
    // A verdict of motion from the noise of a resting platform (the rate
    // test's allowance is exceeded now and then) is not a move: the same
    // rest would count twice. Moved: the window's mean left the last rest.
    if (!armed_ && moved_beyond_noise(rest_position_, rest_sigma_m_)) armed_ = true;
    settled_since_us_ = -1;
    return std::nullopt;
  }
  if (!check_.settled()) settled_since_us_ = -1;
  if (!armed_ || !check_.settled()) return std::nullopt;
  if (settled_since_us_ < 0) {
    begin_hold(o.time_us);
    return std::nullopt;
  }
  if (o.time_us - settled_since_us_ < 2 * detector_.thresholds().window_us) return std::nullopt;
  if (moved_beyond_noise(held_position_, held_sigma_m_)) {
    begin_hold(o.time_us);  // still creeping towards its rest: hold again from here
    return std::nullopt;
  }
  armed_ = false;
  settled_since_us_ = -1;
  WatchedRest rest;
  rest.index = ++rests_;
  rest.seen_us = now_us;
  rest.source_time_us = last_pose_us_;
  rest.sample = detector_.average();
  rest.sample.sigma = detector_.average_sigmas(noise_);
  rest.sample.id = rest.index;
  rest.verdict = check_.verdict;
  rest_position_ = rest.sample.position_world;
  rest_sigma_m_ = rest.sample.sigma.position_m;
  return rest;
}

bool RestWatch::moved_beyond_noise(const Eigen::Vector3d& position, double sigma_m) const {
  const double window_sigma_m = detector_.average_sigmas(noise_).position_m;
  const double variance = sigma_m * sigma_m + window_sigma_m * window_sigma_m;
  return (detector_.average().position_world - position).squaredNorm() > kMaxMoveChiSquare * variance;
}

void RestWatch::begin_hold(hal::TimeUs time_us) {
  settled_since_us_ = time_us;
  held_position_ = detector_.average().position_world;
  held_sigma_m_ = detector_.average_sigmas(noise_).position_m;
}

}  // namespace cdpr::operation
