#include "src/calibration/equilibrium_detector.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>

#include <Eigen/Cholesky>

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
    case EquilibriumVerdict::kSwaying: return "platform swaying";
    case EquilibriumVerdict::kSettled: return "settled";
    case EquilibriumVerdict::kSwayEstimated: return "rest estimated from the sway";
  }
  return "unknown";
}

EquilibriumDetector::EquilibriumDetector(const EquilibriumThresholds& thresholds, std::size_t capacity)
    : thresholds_(thresholds),
      ring_(std::max<std::size_t>(capacity, 2)),
      scratch_(ring_.size()),
      bins_(kSwayBins),
      values_(ring_.size()),
      basis_(ring_.size()) {}

void EquilibriumDetector::reset() {
  first_ = 0;
  count_ = 0;
  added_ = 0;
  sway_ = SwayFit{};
  last_check_sway_ = false;
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
  ++added_;
  // Keep exactly one observation at or before the start of the longer of
  // the rest and the sway window, so a full window is recognisable by its
  // span, and at least twice the rest window's observations (the return
  // test's history when poses are sparse in source time).
  const hal::TimeUs window_start_us = observation.time_us - std::max(thresholds_.window_us, thresholds_.sway_window_us);
  const std::size_t keep = 2 * static_cast<std::size_t>(std::max({2, thresholds_.min_samples, kRateBins}));
  while (count_ > keep && at(1).time_us <= window_start_us) {
    first_ = (first_ + 1) % ring_.size();
    --count_;
  }
}

std::size_t EquilibriumDetector::window_begin() const {
  if (count_ == 0) return 0;
  const hal::TimeUs start_us = at(count_ - 1).time_us - thresholds_.window_us;
  std::size_t begin = 0;
  while (begin + 1 < count_ && at(begin + 1).time_us <= start_us) ++begin;
  const std::size_t keep = static_cast<std::size_t>(std::max({2, thresholds_.min_samples, kRateBins}));
  return count_ > keep ? std::min(begin, count_ - keep) : 0;
}

Eigen::Quaterniond EquilibriumDetector::mean_orientation(std::size_t begin) const {
  // Sign-aligned mean of the coefficients: q and -q are the same rotation,
  // and for the small spread of a resting platform the normalized mean is the
  // rotation average to first order.
  const Eigen::Vector4d reference = at(begin).world_R_platform.coeffs();
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (std::size_t k = begin; k < count_; ++k) {
    const Eigen::Vector4d q = at(k).world_R_platform.coeffs();
    sum += q.dot(reference) < 0.0 ? Eigen::Vector4d(-q) : q;
  }
  Eigen::Quaterniond mean(sum(3), sum(0), sum(1), sum(2));
  mean.normalize();
  return mean;
}

EquilibriumCheck EquilibriumDetector::check() const {
  EquilibriumCheck result;
  last_check_sway_ = false;
  const std::size_t begin = window_begin();
  const std::size_t n = count_ - begin;
  result.samples = static_cast<int>(n);
  if (n < 2) return result;
  const hal::TimeUs start_us = at(begin).time_us;
  result.span_us = at(count_ - 1).time_us - start_us;

  // Tension mean and standard deviation; stable bits.
  double tension_sum = 0.0;
  bool all_stable = true;
  for (std::size_t k = begin; k < count_; ++k) {
    tension_sum += at(k).tension_n;
    all_stable = all_stable && at(k).tension_stable;
  }
  const double tension_mean = tension_sum / static_cast<double>(n);
  double square_sum = 0.0;
  for (std::size_t k = begin; k < count_; ++k) square_sum += std::pow(at(k).tension_n - tension_mean, 2);
  result.tension_std_n = std::sqrt(square_sum / static_cast<double>(n - 1));

  // Bin means of position (relative to the oldest, against cancellation) and
  // of the rotation relative to the mean orientation; the noise of one
  // observation from successive differences, which a slow motion hardly
  // enters (half their mean square is the noise variance of white noise).
  const Eigen::Quaterniond mean_q = mean_orientation(begin);
  const Eigen::Vector3d origin = at(begin).position_world;
  std::array<Eigen::Vector3d, kRateBins> position_sum, rotation_sum;
  std::array<double, kRateBins> time_sum{};
  std::array<int, kRateBins> bin_count{};
  position_sum.fill(Eigen::Vector3d::Zero());
  rotation_sum.fill(Eigen::Vector3d::Zero());
  Eigen::Vector3d position_step_square = Eigen::Vector3d::Zero(), rotation_step_square = Eigen::Vector3d::Zero();
  Eigen::Vector3d previous_p = Eigen::Vector3d::Zero(), previous_r = Eigen::Vector3d::Zero();
  const double span = std::max<double>(static_cast<double>(result.span_us), 1.0);
  for (std::size_t k = begin; k < count_; ++k) {
    const EquilibriumObservation& o = at(k);
    const int bin = std::min(kRateBins - 1, static_cast<int>(kRateBins * (o.time_us - start_us) / span));
    const Eigen::Vector3d p = o.position_world - origin;
    const Eigen::Vector3d r = so3_log(mean_q.conjugate() * o.world_R_platform);
    position_sum[bin] += p;
    rotation_sum[bin] += r;
    if (k > begin) {
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
    const double steps = 2.0 * static_cast<double>(n - 1);
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
  const bool slow = result.speed_mps <= thresholds_.max_speed_mps &&
                    result.angular_rate_radps <= thresholds_.max_angular_rate_radps;
  result.covered = covered;
  ReturnTest returned;
  if (covered && slow) returned = return_beyond_noise(begin, std::min(span / kRateBins, 1e6 * kMaxReturnBinS));
  result.return_m = returned.excess_m;
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
  } else if (!returned.covered) {
    result.verdict = EquilibriumVerdict::kNotEnoughData;
  } else if (result.return_m > 0.0) {
    result.verdict = EquilibriumVerdict::kSwaying;
  } else {
    result.verdict = EquilibriumVerdict::kSettled;
  }
  // Only a platform seen moving is tried as a sway: one at rest whose load
  // cell is not stable or whose tension varies stays refused.
  // A slow window whose return window is not covered yet may be a sway's
  // turning point: the fit decides.
  const bool moving = !slow || !returned.covered || result.return_m > 0.0;
  if (result.verdict != EquilibriumVerdict::kSettled && result.verdict != EquilibriumVerdict::kNotEnoughData &&
      moving && thresholds_.estimate_sway) {
    fit_sway();
    result.sway_period_s = sway_.omega_radps > 0.0 ? 2.0 * std::numbers::pi / sway_.omega_radps : 0.0;
    result.sway_misfit = sway_.misfit;
    if (sway_.accepted) {
      result.verdict = EquilibriumVerdict::kSwayEstimated;
      last_check_sway_ = true;
    }
  }
  return result;
}

EquilibriumDetector::ReturnTest EquilibriumDetector::return_beyond_noise(std::size_t rest_begin, double bin_us) const {
  // The return window: the last sway_window_us, at least twice the rest
  // window, cut into bins as long as the rate bins.
  ReturnTest out;
  const hal::TimeUs newest_us = at(count_ - 1).time_us;
  const hal::TimeUs length_us = std::max(thresholds_.sway_window_us, 2 * (newest_us - at(rest_begin).time_us));
  std::size_t begin = 0;
  while (begin + 1 < count_ && at(begin + 1).time_us <= newest_us - length_us) ++begin;
  const hal::TimeUs t0_us = at(begin).time_us;
  out.covered = newest_us - t0_us >= length_us;
  if (!out.covered) return out;
  const std::size_t rest_count = count_ - rest_begin;
  const int bin_count = std::clamp(static_cast<int>(static_cast<double>(newest_us - t0_us) / std::max(bin_us, 1.0)) + 1,
                                   1, static_cast<int>(bins_.size()));
  const double width_us = std::max(static_cast<double>(newest_us - t0_us) / bin_count, 1.0);
  const Eigen::Vector3d origin = at(begin).position_world;
  bins_.assign(bins_.size(), {0.0, 0.0, 0.0, 0.0, 0.0});
  Eigen::Vector3d rest_sum = Eigen::Vector3d::Zero(), step_square = Eigen::Vector3d::Zero();
  for (std::size_t k = begin; k < count_; ++k) {
    const Eigen::Vector3d p = at(k).position_world - origin;
    const int b = std::min(bin_count - 1, static_cast<int>(static_cast<double>(at(k).time_us - t0_us) / width_us));
    for (int axis = 0; axis < 3; ++axis) bins_[b][1 + axis] += p(axis);
    bins_[b][4] += 1.0;
    if (k >= rest_begin) rest_sum += p;
    if (k > begin) step_square += (p - (at(k - 1).position_world - origin)).cwiseAbs2();
  }
  const Eigen::Vector3d rest = rest_sum / static_cast<double>(rest_count);
  // Noise variance of one observation, summed over the axes.
  const double noise_var = step_square.sum() / (2.0 * static_cast<double>(count_ - begin - 1));
  // Each bin's distance from the rest window's mean, once per bin (in the
  // slot the sway fit keeps its time in); a later bin farther than an
  // earlier one, beyond the noise of the two bin means, is a return.
  for (int k = 0; k < bin_count; ++k) {
    if (bins_[k][4] == 0.0) continue;
    bins_[k][0] = (Eigen::Vector3d(bins_[k][1], bins_[k][2], bins_[k][3]) / bins_[k][4] - rest).norm();
  }
  for (int k = 0; k < bin_count; ++k) {
    if (bins_[k][4] == 0.0) continue;
    for (int j = 0; j < k; ++j) {
      if (bins_[j][4] == 0.0) continue;
      const double noise = kNoiseAllowance * std::sqrt(noise_var * (1.0 / bins_[j][4] + 1.0 / bins_[k][4]));
      out.excess_m = std::max(out.excess_m, bins_[k][0] - bins_[j][0] - noise);
    }
  }
  return out;
}

double EquilibriumDetector::coordinate(const EquilibriumObservation& o, int c, const Eigen::Quaterniond& mean_q) const {
  if (c < 3) return o.position_world(c);
  if (c < 6) return so3_log(mean_q.conjugate() * o.world_R_platform)(c - 3);
  if (c < 6 + kCableCount) return o.encoder_m[c - 6];
  return o.tension_n;
}

double EquilibriumDetector::sway_residual_sum(double omega, double decay) const {
  // Least squares of the bin means (weighted by their counts) on
  // 1, exp(-decay t) cos(omega t), exp(-decay t) sin(omega t), per axis.
  Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d rhs = Eigen::Matrix3d::Zero();  // column per axis
  double square_sum = 0.0;
  for (const std::array<double, 5>& bin : bins_) {
    const double w = bin[4];
    if (w == 0.0) continue;
    const double envelope = std::exp(-decay * bin[0]);
    const Eigen::Vector3d phi(1.0, envelope * std::cos(omega * bin[0]), envelope * std::sin(omega * bin[0]));
    gram += w * phi * phi.transpose();
    for (int axis = 0; axis < 3; ++axis) {
      rhs.col(axis) += w * bin[1 + axis] * phi;
      square_sum += w * bin[1 + axis] * bin[1 + axis];
    }
  }
  const Eigen::LDLT<Eigen::Matrix3d> solve(gram);
  if (solve.info() != Eigen::Success) return square_sum;
  double explained = 0.0;
  for (int axis = 0; axis < 3; ++axis) explained += rhs.col(axis).dot(solve.solve(rhs.col(axis)));
  return square_sum - explained;
}

void EquilibriumDetector::fit_sway() const {
  if (sway_.newest_us >= 0 && added_ - sway_.added_at < static_cast<std::size_t>(kSwayRefitObservations)) return;
  sway_ = SwayFit{};
  const hal::TimeUs newest_us = at(count_ - 1).time_us;
  sway_.newest_us = newest_us;
  sway_.added_at = added_;

  // The sway window: the last sway_window_us, at least min_samples.
  std::size_t begin = 0;
  while (begin + 1 < count_ && at(begin + 1).time_us <= newest_us - thresholds_.sway_window_us) ++begin;
  const std::size_t keep = static_cast<std::size_t>(std::max({3 * kMinSamplesPerPeriod, thresholds_.min_samples}));
  if (count_ < keep) return;
  begin = std::min(begin, count_ - keep);
  const std::size_t n = count_ - begin;
  const hal::TimeUs t0_us = at(begin).time_us;
  const double span_s = 1e-6 * static_cast<double>(newest_us - t0_us);
  if (newest_us - t0_us < thresholds_.sway_window_us || !(span_s > 0.0)) return;
  const double omega_min = 2.0 * std::numbers::pi * kMinSwayPeriods / span_s;
  const double omega_max = 2.0 * std::numbers::pi * static_cast<double>(n - 1) / (kMinSamplesPerPeriod * span_s);
  if (!(omega_max > 1.5 * omega_min)) return;

  // Bin means of the position (relative to the oldest) for the search.
  const Eigen::Vector3d origin = at(begin).position_world;
  const int bin_count = static_cast<int>(std::min<std::size_t>(n, kSwayBins));
  bins_.assign(bins_.size(), {0.0, 0.0, 0.0, 0.0, 0.0});
  for (std::size_t k = begin; k < count_; ++k) {
    const double t = 1e-6 * static_cast<double>(at(k).time_us - t0_us);
    const int b = std::min(bin_count - 1, static_cast<int>(bin_count * t / span_s));
    const Eigen::Vector3d p = at(k).position_world - origin;
    bins_[b][0] += t;
    for (int axis = 0; axis < 3; ++axis) bins_[b][1 + axis] += p(axis);
    bins_[b][4] += 1.0;
  }
  for (std::array<double, 5>& bin : bins_) {
    if (bin[4] > 0.0) {
      for (int j = 0; j < 4; ++j) bin[j] /= bin[4];
    }
  }

  // Grid over omega (log-spaced) and the decay (up to e^-4 over the window),
  // then golden-section refinement of each in turn.
  constexpr int kOmegaGrid = 48;
  const double ratio = std::pow(omega_max / omega_min, 1.0 / (kOmegaGrid - 1));
  const std::array<double, 6> decays{0.0, 0.25 / span_s, 0.5 / span_s, 1.0 / span_s, 2.0 / span_s, 4.0 / span_s};
  double best = std::numeric_limits<double>::infinity(), omega = omega_min, decay = 0.0;
  for (int i = 0; i < kOmegaGrid; ++i) {
    const double w = omega_min * std::pow(ratio, i);
    for (const double d : decays) {
      const double r = sway_residual_sum(w, d);
      if (r < best) {
        best = r;
        omega = w;
        decay = d;
      }
    }
  }
  const auto golden = [](auto&& f, double lo, double hi) {
    constexpr double kInv = 0.6180339887498949;
    double a = hi - kInv * (hi - lo), b = lo + kInv * (hi - lo);
    double fa = f(a), fb = f(b);
    for (int iteration = 0; iteration < 40; ++iteration) {
      if (fa < fb) {
        hi = b;
        b = a;
        fb = fa;
        a = hi - kInv * (hi - lo);
        fa = f(a);
      } else {
        lo = a;
        a = b;
        fa = fb;
        b = lo + kInv * (hi - lo);
        fb = f(b);
      }
    }
    return 0.5 * (lo + hi);
  };
  for (int round = 0; round < 3; ++round) {
    omega = golden([&](double w) { return sway_residual_sum(w, decay); }, omega / ratio, omega * ratio);
    decay = golden([&](double d) { return sway_residual_sum(omega, d); }, std::max(0.0, decay - 1.0 / span_s),
                   decay + 1.0 / span_s);
  }
  sway_.omega_radps = omega;
  sway_.decay_per_s = decay;
  if (!(omega > omega_min * ratio && omega < omega_max / ratio)) return;  // at the edge: no oscillation found

  // Every coordinate on the full window: rest values, residuals, misfit.
  sway_.mean_q = mean_orientation(begin);
  Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();
  for (std::size_t k = begin; k < count_; ++k) {
    const double t = 1e-6 * static_cast<double>(at(k).time_us - t0_us);
    const double envelope = std::exp(-decay * t);
    Eigen::Vector3d& phi = basis_[k - begin];
    phi = Eigen::Vector3d(1.0, envelope * std::cos(omega * t), envelope * std::sin(omega * t));
    gram += phi * phi.transpose();
  }
  const Eigen::LDLT<Eigen::Matrix3d> solve(gram);
  if (solve.info() != Eigen::Success) return;
  const double rest_factor = std::sqrt(std::max(solve.solve(Eigen::Vector3d::UnitX())(0), 0.0));
  // Residual differences at a lag of 1/20 period: readings repeated between
  // sensor updates are not counted as noiseless.
  const double samples_per_period = static_cast<double>(n - 1) / span_s * 2.0 * std::numbers::pi / omega;
  const std::size_t lag = std::max<std::size_t>(1, static_cast<std::size_t>(samples_per_period / 20.0));
  const std::span<const double> residuals(scratch_.data(), n);
  bool consistent = true;
  double significance = 0.0;
  for (int c = 0; c < kSwayCoordinates; ++c) {
    const double y0 = coordinate(at(begin), c, sway_.mean_q);
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t k = begin; k < count_; ++k) {
      values_[k - begin] = coordinate(at(k), c, sway_.mean_q) - y0;
      rhs += values_[k - begin] * basis_[k - begin];
    }
    const Eigen::Vector3d beta = solve.solve(rhs);
    double square_sum = 0.0, lag_square_sum = 0.0, constant_sum = 0.0, constant_square_sum = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      const double y = values_[j];
      const double r = y - beta.dot(basis_[j]);
      scratch_[j] = r;
      square_sum += r * r;
      constant_sum += y;
      constant_square_sum += y * y;
      if (j >= lag) lag_square_sum += std::pow(r - scratch_[j - lag], 2);
    }
    const double variance = square_sum / static_cast<double>(n - 3);
    const double noise = lag_square_sum / (2.0 * static_cast<double>(n - lag));
    const double misfit =
        noise > 0.0 ? variance / noise : (variance > 0.0 ? std::numeric_limits<double>::infinity() : 1.0);
    sway_.misfit = std::max(sway_.misfit, misfit);
    if (c < 6 && variance > 0.0) {
      const double constant_residual = constant_square_sum - constant_sum * constant_sum / static_cast<double>(n);
      significance = std::max(significance, 0.5 * (constant_residual - square_sum) / variance);
    }
    consistent = consistent && misfit <= thresholds_.max_sway_misfit;
    sway_.rest[c] = y0 + beta(0);
    sway_.scatter[c] = std::sqrt(variance);
    // The residuals' correlation: n / n_eff (window_statistics.h).
    const WindowStatistics statistics = window_statistics(residuals, std::max(sway_.scatter[c], 1e-300));
    sway_.factor[c] = rest_factor * std::sqrt(static_cast<double>(n) / statistics.effective_count);
  }
  sway_.accepted = consistent && significance >= kMinSwaySignificance;
}

Sample EquilibriumDetector::average() const {
  assert(count_ > 0);
  Sample sample;
  if (last_check_sway_) {
    sample.position_world = Eigen::Vector3d(sway_.rest[0], sway_.rest[1], sway_.rest[2]);
    sample.world_R_platform =
        (sway_.mean_q * so3_exp(Eigen::Vector3d(sway_.rest[3], sway_.rest[4], sway_.rest[5]))).normalized();
    for (int i = 0; i < kCableCount; ++i) sample.encoder_m[i] = sway_.rest[6 + i];
    sample.force_n = sway_.rest[6 + kCableCount];
    return sample;
  }
  const std::size_t begin = window_begin();
  Eigen::Vector3d position_sum = Eigen::Vector3d::Zero();
  double tension_sum = 0.0;
  for (std::size_t k = begin; k < count_; ++k) {
    const EquilibriumObservation& o = at(k);
    position_sum += o.position_world;
    tension_sum += o.tension_n;
    for (int i = 0; i < kCableCount; ++i) sample.encoder_m[i] += o.encoder_m[i];
  }
  const double n = static_cast<double>(count_ - begin);
  sample.position_world = position_sum / n;
  sample.world_R_platform = mean_orientation(begin);
  for (double& encoder_m : sample.encoder_m) encoder_m /= n;
  sample.force_n = tension_sum / n;
  return sample;
}

SampleSigmas EquilibriumDetector::average_sigmas(const NoiseSigmas& per_reading) const {
  assert(count_ > 0);
  const std::size_t begin = window_begin();
  const std::span<const double> series(scratch_.data(), count_ - begin);
  const Eigen::Quaterniond mean_q = mean_orientation(begin);
  // The standard error of coordinate c's value in average().
  const auto sigma_of = [&](int c, double floor) {
    if (last_check_sway_) return std::max(sway_.scatter[c], floor) * sway_.factor[c];
    for (std::size_t k = begin; k < count_; ++k) scratch_[k - begin] = coordinate(at(k), c, mean_q);
    return window_statistics(series, floor).sigma_of_mean;
  };
  SampleSigmas sigma;
  for (int i = 0; i < kCableCount; ++i) sigma.encoder_m[i] = sigma_of(6 + i, per_reading.encoder_m);
  sigma.force_n = sigma_of(6 + kCableCount, per_reading.force_n);
  double position_square = 0.0, rotation_square = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    position_square += std::pow(sigma_of(axis, per_reading.position_m), 2);
    rotation_square += std::pow(sigma_of(3 + axis, per_reading.orientation_rad), 2);
  }
  sigma.position_m = std::sqrt(position_square / 3.0);
  sigma.orientation_rad = std::sqrt(rotation_square / 3.0);
  return sigma;
}

}  // namespace cdpr::calibration
