#include "src/calibration/equilibrium_detector.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "solver/nls/pose.h"
#include "src/calibration/window_statistics.h"

namespace cdpr::calibration {

const char* to_string(EquilibriumVerdict verdict) {
  switch (verdict) {
    case EquilibriumVerdict::kNotEnoughData: return "collecting";
    case EquilibriumVerdict::kTensionUnstable: return "load cell not stable";
    case EquilibriumVerdict::kTensionSpread: return "tension varies";
    case EquilibriumVerdict::kMoving: return "platform moving";
    case EquilibriumVerdict::kRotating: return "platform rotating";
    case EquilibriumVerdict::kSettled: return "settled";
  }
  return "unknown";
}

EquilibriumDetector::EquilibriumDetector(const EquilibriumThresholds& thresholds, std::size_t capacity)
    : thresholds_(thresholds), ring_(std::max<std::size_t>(capacity, 2)), scratch_(ring_.size()) {}

void EquilibriumDetector::reset() {
  first_ = 0;
  count_ = 0;
}

const EquilibriumObservation& EquilibriumDetector::at(std::size_t k) const {
  return ring_[(first_ + k) % ring_.size()];
}

void EquilibriumDetector::add(const EquilibriumObservation& observation) {
  if (count_ > 0 && observation.time_us < at(count_ - 1).time_us) reset();
  if (count_ == ring_.size()) {
    first_ = (first_ + 1) % ring_.size();
    --count_;
  }
  ring_[(first_ + count_) % ring_.size()] = observation;
  ++count_;
  // Keep exactly one observation at or before the window's start, so a full
  // window is recognisable by its span, and at least min_samples.
  const hal::TimeUs window_start_us = observation.time_us - thresholds_.window_us;
  const std::size_t keep = static_cast<std::size_t>(std::max({2, thresholds_.min_samples, kRateBins}));
  while (count_ > keep && at(1).time_us <= window_start_us) {
    first_ = (first_ + 1) % ring_.size();
    --count_;
  }
}

Eigen::Quaterniond EquilibriumDetector::mean_orientation() const {
  // Sign-aligned mean of the coefficients: q and -q are the same rotation,
  // and for the small spread of a resting platform the normalized mean is the
  // rotation average to first order.
  const Eigen::Vector4d reference = at(0).world_R_platform.coeffs();
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (std::size_t k = 0; k < count_; ++k) {
    const Eigen::Vector4d q = at(k).world_R_platform.coeffs();
    sum += q.dot(reference) < 0.0 ? Eigen::Vector4d(-q) : q;
  }
  Eigen::Quaterniond mean(sum(3), sum(0), sum(1), sum(2));
  mean.normalize();
  return mean;
}

EquilibriumCheck EquilibriumDetector::check() const {
  EquilibriumCheck result;
  result.samples = static_cast<int>(count_);
  if (count_ < 2) return result;
  const hal::TimeUs start_us = at(0).time_us;
  result.span_us = at(count_ - 1).time_us - start_us;

  // Tension mean and standard deviation; stable bits.
  double tension_sum = 0.0;
  bool all_stable = true;
  for (std::size_t k = 0; k < count_; ++k) {
    tension_sum += at(k).tension_n;
    all_stable = all_stable && at(k).tension_stable;
  }
  const double tension_mean = tension_sum / static_cast<double>(count_);
  double square_sum = 0.0;
  for (std::size_t k = 0; k < count_; ++k) square_sum += std::pow(at(k).tension_n - tension_mean, 2);
  result.tension_std_n = std::sqrt(square_sum / static_cast<double>(count_ - 1));

  // Bin means of position (relative to the oldest, against cancellation) and
  // of the rotation relative to the mean orientation; the noise of one
  // observation from successive differences, which a slow motion hardly
  // enters (half their mean square is the noise variance of white noise).
  const Eigen::Quaterniond mean_q = mean_orientation();
  const Eigen::Vector3d origin = at(0).position_world;
  std::array<Eigen::Vector3d, kRateBins> position_sum, rotation_sum;
  std::array<double, kRateBins> time_sum{};
  std::array<int, kRateBins> bin_count{};
  position_sum.fill(Eigen::Vector3d::Zero());
  rotation_sum.fill(Eigen::Vector3d::Zero());
  Eigen::Vector3d position_step_square = Eigen::Vector3d::Zero(), rotation_step_square = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_p = Eigen::Vector3d::Zero(), previous_r = Eigen::Vector3d::Zero();
  const double span = std::max<double>(static_cast<double>(result.span_us), 1.0);
  for (std::size_t k = 0; k < count_; ++k) {
    const EquilibriumObservation& o = at(k);
    const int bin = std::min(kRateBins - 1, static_cast<int>(kRateBins * (o.time_us - start_us) / span));
    const Eigen::Vector3d p = o.position_world - origin;
    const Eigen::Vector3d r = so3_log(mean_q.conjugate() * o.world_R_platform);
    position_sum[bin] += p;
    rotation_sum[bin] += r;
    if (k > 0) {
      position_step_square += (p - previous_p).cwiseAbs2();
      rotation_step_square += (r - previous_r).cwiseAbs2();
    }
    previous_p = p;
    previous_r = r;
    time_sum[bin] += 1e-6 * static_cast<double>(o.time_us - start_us);
    ++bin_count[bin];
  }
  bool bins_filled = true;
  for (int b = 0; b < kRateBins; ++b) bins_filled = bins_filled && bin_count[b] > 0;
  if (bins_filled) {
    // Per-axis noise variance of one observation.
    const double steps = 2.0 * static_cast<double>(count_ - 1);
    const Eigen::Vector3d position_var = position_step_square / steps;
    const Eigen::Vector3d rotation_var = rotation_step_square / steps;
    for (int b = 0; b + 1 < kRateBins; ++b) {
      const double dt_s = time_sum[b + 1] / bin_count[b + 1] - time_sum[b] / bin_count[b];
      if (!(dt_s > 0.0)) continue;
      const double per_pair = 1.0 / bin_count[b] + 1.0 / bin_count[b + 1];
      const double dp = (position_sum[b + 1] / bin_count[b + 1] - position_sum[b] / bin_count[b]).norm();
      const double dr = (rotation_sum[b + 1] / bin_count[b + 1] - rotation_sum[b] / bin_count[b]).norm();
      const double dp_noise = kNoiseAllowance * std::sqrt(position_var.sum() * per_pair);
      const double dr_noise = kNoiseAllowance * std::sqrt(rotation_var.sum() * per_pair);
      result.speed_mps = std::max(result.speed_mps, std::max(dp - dp_noise, 0.0) / dt_s);
      result.angular_rate_radps = std::max(result.angular_rate_radps, std::max(dr - dr_noise, 0.0) / dt_s);
    }
  }

  const bool covered = result.span_us >= thresholds_.window_us &&
                       result.samples >= std::max(thresholds_.min_samples, kRateBins) && bins_filled;
  if (!covered) {
    result.verdict = EquilibriumVerdict::kNotEnoughData;
  } else if (!all_stable) {
    result.verdict = EquilibriumVerdict::kTensionUnstable;
  } else if (!(result.tension_std_n <= thresholds_.max_tension_std_n)) {
    result.verdict = EquilibriumVerdict::kTensionSpread;
  } else if (!(result.speed_mps <= thresholds_.max_speed_mps)) {
    result.verdict = EquilibriumVerdict::kMoving;
  } else if (!(result.angular_rate_radps <= thresholds_.max_angular_rate_radps)) {
    result.verdict = EquilibriumVerdict::kRotating;
  } else {
    result.verdict = EquilibriumVerdict::kSettled;
  }
  return result;
}

Sample EquilibriumDetector::average() const {
  assert(count_ > 0);
  Sample sample;
  Eigen::Vector3d position_sum = Eigen::Vector3d::Zero();
  double tension_sum = 0.0;
  for (std::size_t k = 0; k < count_; ++k) {
    const EquilibriumObservation& o = at(k);
    position_sum += o.position_world;
    tension_sum += o.tension_n;
    for (int i = 0; i < kCableCount; ++i) sample.encoder_m[i] += o.encoder_m[i];
  }
  const double n = static_cast<double>(count_);
  sample.position_world = position_sum / n;
  sample.world_R_platform = mean_orientation();
  for (double& encoder_m : sample.encoder_m) encoder_m /= n;
  sample.force_n = tension_sum / n;
  return sample;
}

SampleSigmas EquilibriumDetector::average_sigmas(const NoiseSigmas& per_reading) const {
  assert(count_ > 0);
  const std::span<const double> series(scratch_.data(), count_);
  const auto sigma_of_mean = [&](auto&& reading, double floor) {
    for (std::size_t k = 0; k < count_; ++k) scratch_[k] = reading(at(k));
    return window_statistics(series, floor).sigma_of_mean;
  };
  SampleSigmas sigma;
  for (int i = 0; i < kCableCount; ++i) {
    sigma.encoder_m[i] =
        sigma_of_mean([i](const EquilibriumObservation& o) { return o.encoder_m[i]; }, per_reading.encoder_m);
  }
  sigma.force_n = sigma_of_mean([](const EquilibriumObservation& o) { return o.tension_n; }, per_reading.force_n);
  const Eigen::Quaterniond mean_q = mean_orientation();
  double position_square = 0.0, rotation_square = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    position_square += std::pow(
        sigma_of_mean([axis](const EquilibriumObservation& o) { return o.position_world(axis); }, per_reading.position_m),
        2);
    rotation_square += std::pow(sigma_of_mean(
                                    [&, axis](const EquilibriumObservation& o) {
                                      return so3_log(mean_q.conjugate() * o.world_R_platform)(axis);
                                    },
                                    per_reading.orientation_rad),
                                2);
  }
  sigma.position_m = std::sqrt(position_square / 3.0);
  sigma.orientation_rad = std::sqrt(rotation_square / 3.0);
  return sigma;
}

}  // namespace cdpr::calibration
