#include "src/calibration/equilibrium_detector.h"

#include <cmath>
#include <optional>
#include <random>

#include <gtest/gtest.h>

namespace cdpr::calibration {
namespace {

constexpr hal::TimeUs kPeriodUs = 20'000;  // 50 Hz observations

// A platform approaching rest exponentially with white sensor noise:
// x(t) = x_rest + x0 * exp(-t / tau) + noise.
struct SettlingSignal {
  Eigen::Vector3d rest_world{10.0, 20.0, 5.0};
  Eigen::Vector3d initial_offset{0.3, -0.2, 0.1};  // [m] at t = 0
  double initial_yaw_rad = 0.05;  // at t = 0
  double tau_s = 2.0;
  double position_noise_m = 0.003;
  double tension_rest_n = 700.0;
  double tension_initial_offset_n = 150.0;
  double tension_noise_n = 3.0;
  std::array<double, kCableCount> encoder_rest_m{50.0, 51.0, 52.0, 53.0};
  std::mt19937 random{42};

  EquilibriumObservation at(hal::TimeUs time_us) {
    std::normal_distribution<double> normal(0.0, 1.0);
    const double decay = std::exp(-1e-6 * static_cast<double>(time_us) / tau_s);
    EquilibriumObservation o;
    o.time_us = time_us;
    o.position_world = rest_world + initial_offset * decay +
                       position_noise_m * Eigen::Vector3d(normal(random), normal(random), normal(random));
    o.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(initial_yaw_rad * decay, Eigen::Vector3d::UnitZ()));
    o.tension_n = tension_rest_n + tension_initial_offset_n * decay + tension_noise_n * normal(random);
    o.tension_stable = true;
    for (int i = 0; i < kCableCount; ++i) o.encoder_m[i] = encoder_rest_m[i] + 0.5 * decay;
    return o;
  }
  // Time at which the true speed falls below `speed_mps`.
  double time_speed_below_s(double speed_mps) const {
    return tau_s * std::log(initial_offset.norm() / (tau_s * speed_mps));
  }
};

EquilibriumThresholds thresholds() {
  EquilibriumThresholds t;
  t.window_us = 2'000'000;
  t.min_samples = 50;
  t.max_speed_mps = 0.005;
  t.max_angular_rate_radps = 0.01;
  t.max_tension_std_n = 8.0;
  return t;
}

// Feeds the signal until settled; returns the time, or nullopt by `limit_us`.
std::optional<hal::TimeUs> first_settled(EquilibriumDetector& detector, SettlingSignal& signal,
                                         hal::TimeUs limit_us) {
  for (hal::TimeUs t = 0; t <= limit_us; t += kPeriodUs) {
    detector.add(signal.at(t));
    if (detector.check().settled()) return t;
  }
  return std::nullopt;
}

TEST(EquilibriumDetector, SettlesOnlyAfterTheTransientHasDecayed) {
  // GIVEN an exponentially settling platform with noise
  SettlingSignal signal;
  EquilibriumDetector detector(thresholds(), 200);
  // WHEN observations arrive at 50 Hz
  const auto settled_us = first_settled(detector, signal, 60'000'000);
  // THEN it settles, not before the true speed fell below the limit, and
  // within two windows after that
  ASSERT_TRUE(settled_us.has_value());
  const double settled_s = 1e-6 * static_cast<double>(*settled_us);
  const double slow_s = signal.time_speed_below_s(thresholds().max_speed_mps);
  EXPECT_GT(settled_s, slow_s);
  EXPECT_LT(settled_s, slow_s + 2.0 * 1e-6 * static_cast<double>(thresholds().window_us) + 1.0);
}

TEST(EquilibriumDetector, AverageIsTheRestPoseWithinTheNoise) {
  // GIVEN a settled platform
  SettlingSignal signal;
  EquilibriumDetector detector(thresholds(), 200);
  ASSERT_TRUE(first_settled(detector, signal, 60'000'000).has_value());
  // WHEN the window is averaged
  const Sample sample = detector.average();
  // THEN the averages match the rest values within a few standard errors plus the remaining transient
  const double standard_error_m = signal.position_noise_m / std::sqrt(detector.size());
  EXPECT_LT((sample.position_world - signal.rest_world).norm(), 5.0 * standard_error_m + 0.01);
  EXPECT_NEAR(sample.force_n, signal.tension_rest_n, 5.0);
  for (int i = 0; i < kCableCount; ++i) EXPECT_NEAR(sample.encoder_m[i], signal.encoder_rest_m[i], 0.02);
  EXPECT_NEAR(sample.world_R_platform.norm(), 1.0, 1e-12);
}

TEST(EquilibriumDetector, NeedsACoveredWindow) {
  // GIVEN a platform perfectly at rest
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  signal.tension_initial_offset_n = 0.0;
  EquilibriumDetector detector(thresholds(), 200);
  // WHEN observations cover less than the window
  for (hal::TimeUs t = 0; t < thresholds().window_us; t += kPeriodUs) detector.add(signal.at(t));
  // THEN it is not settled yet; one more observation covering the window settles it
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kNotEnoughData);
  detector.add(signal.at(thresholds().window_us));
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kSettled);
}

TEST(EquilibriumDetector, AClearedStableBitPreventsSettling) {
  // GIVEN a platform at rest whose load cell once says "not stable" inside the window
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  EquilibriumDetector detector(thresholds(), 200);
  for (hal::TimeUs t = 0; t <= 3 * thresholds().window_us; t += kPeriodUs) {
    EquilibriumObservation o = signal.at(t);
    o.tension_stable = t != 2 * thresholds().window_us + 500'000;
    detector.add(o);
  }
  // WHEN checked
  // THEN the verdict names the load cell
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kTensionUnstable);
}

TEST(EquilibriumDetector, NoisyTensionIsRefused) {
  // GIVEN a platform at rest with a tension noise above the threshold
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  signal.tension_initial_offset_n = 0.0;
  signal.tension_noise_n = 3.0 * thresholds().max_tension_std_n;
  EquilibriumDetector detector(thresholds(), 200);
  for (hal::TimeUs t = 0; t <= 2 * thresholds().window_us; t += kPeriodUs) detector.add(signal.at(t));
  // WHEN checked THEN the tension spread is named and measured about right
  const EquilibriumCheck check = detector.check();
  EXPECT_EQ(check.verdict, EquilibriumVerdict::kTensionSpread);
  EXPECT_NEAR(check.tension_std_n, signal.tension_noise_n, 0.3 * signal.tension_noise_n);
}

TEST(EquilibriumDetector, SlowSteadyRotationIsDetected) {
  // GIVEN a platform still in position but turning at 3x the angular-rate limit
  const double rate_radps = 3.0 * thresholds().max_angular_rate_radps;
  EquilibriumDetector detector(thresholds(), 200);
  for (hal::TimeUs t = 0; t <= 2 * thresholds().window_us; t += kPeriodUs) {
    EquilibriumObservation o;
    o.time_us = t;
    o.world_R_platform = Eigen::AngleAxisd(rate_radps * 1e-6 * static_cast<double>(t), Eigen::Vector3d::UnitX());
    o.tension_n = 500.0;
    o.tension_stable = true;
    detector.add(o);
  }
  // WHEN checked THEN rotation is refused and the rate is measured
  const EquilibriumCheck check = detector.check();
  EXPECT_EQ(check.verdict, EquilibriumVerdict::kRotating);
  EXPECT_NEAR(check.angular_rate_radps, rate_radps, 0.05 * rate_radps);
}

TEST(EquilibriumDetector, TooSmallARingNeverCoversTheWindow) {
  // GIVEN a ring holding one second at 50 Hz and a two-second window
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  EquilibriumDetector detector(thresholds(), 50);
  // WHEN ten seconds of rest are observed
  for (hal::TimeUs t = 0; t <= 10'000'000; t += kPeriodUs) detector.add(signal.at(t));
  // THEN the ring stays at its capacity and never claims a settled window
  EXPECT_EQ(detector.size(), 50);
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kNotEnoughData);
}

TEST(EquilibriumDetector, TimeGoingBackwardsStartsAgain) {
  // GIVEN a settled window
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  EquilibriumDetector detector(thresholds(), 200);
  for (hal::TimeUs t = 0; t <= 3 * thresholds().window_us; t += kPeriodUs) detector.add(signal.at(t));
  ASSERT_TRUE(detector.check().settled());
  // WHEN an observation older than the newest arrives
  detector.add(signal.at(1'000));
  // THEN the window restarts from it
  EXPECT_EQ(detector.size(), 1);
  EXPECT_FALSE(detector.check().settled());
}

TEST(EquilibriumDetector, QuaternionSignFlipsAverageToTheSameRotation) {
  // GIVEN one rotation reported alternately as q and -q
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  EquilibriumDetector detector(thresholds(), 200);
  for (int k = 0; k < 20; ++k) {
    EquilibriumObservation o;
    o.time_us = k * kPeriodUs;
    o.world_R_platform = k % 2 ? q : Eigen::Quaterniond(-q.coeffs());
    detector.add(o);
  }
  // WHEN averaged THEN the mean is that rotation
  EXPECT_LT(detector.average().world_R_platform.angularDistance(q), 1e-12);
}

}  // namespace
}  // namespace cdpr::calibration
