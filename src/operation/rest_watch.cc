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
    armed_ = true;
    return std::nullopt;
  }
  if (!check_.settled()) settled_since_us_ = -1;
  if (!armed_ || !check_.settled()) return std::nullopt;
  if (settled_since_us_ < 0) settled_since_us_ = o.time_us;
  if (o.time_us - settled_since_us_ < 2 * detector_.thresholds().window_us) return std::nullopt;
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
  return rest;
}

}  // namespace cdpr::operation
