#include "src/calibration/equilibrium_detector.h"

#include <cmath>
#include <optional>
#include <random>

#include <gtest/gtest.h>

#include "equilibrium_test_rate.h"

namespace cdpr::calibration {
namespace {

using test::kPeriodUs;

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
  // The shortest return window (twice the rest window): these tests are
  // about the rest window.
  t.sway_window_us = 2 * t.window_us;
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
  EquilibriumDetector detector(thresholds(), 400);
  // WHEN observations arrive at 50 Hz
  const auto settled_us = first_settled(detector, signal, 60'000'000);
  // THEN it settles, not before the true speed fell below the limit plus
  // the noise allowance of a bin-mean change (2 standard errors of a 3-D
  // difference of two 25-observation means, over the 0.5 s between bins), and
  // within two windows and the return window after the speed fell below the limit
  ASSERT_TRUE(settled_us.has_value());
  const double settled_s = 1e-6 * static_cast<double>(*settled_us);
  const double allowance_mps =
      EquilibriumDetector::kNoiseAllowance * signal.position_noise_m * std::sqrt(3.0 * 2.0 / 25.0) / 0.5;
  const double slow_s = signal.time_speed_below_s(thresholds().max_speed_mps);
  EXPECT_GT(settled_s, signal.time_speed_below_s(thresholds().max_speed_mps + allowance_mps));
  EXPECT_LT(settled_s, slow_s + 1e-6 * static_cast<double>(2 * thresholds().window_us + thresholds().sway_window_us) + 1.0);
}

TEST(EquilibriumDetector, AverageIsTheRestPoseWithinTheNoise) {
  // GIVEN a settled platform
  SettlingSignal signal;
  EquilibriumDetector detector(thresholds(), 400);
  ASSERT_TRUE(first_settled(detector, signal, 60'000'000).has_value());
  // WHEN the window is averaged
  const Sample sample = detector.average();
  // THEN the averages match the rest values within a few standard errors
  // plus the transient left at the fastest speed the detector may call rest
  // (the limit plus its noise allowance)
  const double standard_error_m = signal.position_noise_m / std::sqrt(detector.size());
  const double allowance_mps =
      EquilibriumDetector::kNoiseAllowance * signal.position_noise_m * std::sqrt(3.0 * 2.0 / 25.0) / 0.5;
  const double decay = signal.tau_s * (thresholds().max_speed_mps + allowance_mps) / signal.initial_offset.norm();
  EXPECT_LT((sample.position_world - signal.rest_world).norm(),
            5.0 * standard_error_m + signal.initial_offset.norm() * decay);
  EXPECT_NEAR(sample.force_n, signal.tension_rest_n, 5.0 + signal.tension_initial_offset_n * decay);
  for (int i = 0; i < kCableCount; ++i) EXPECT_NEAR(sample.encoder_m[i], signal.encoder_rest_m[i], 0.5 * decay + 0.005);
  EXPECT_NEAR(sample.world_R_platform.norm(), 1.0, 1e-12);
}

TEST(EquilibriumDetector, NeedsACoveredWindow) {
  // GIVEN a platform perfectly at rest
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  signal.tension_initial_offset_n = 0.0;
  EquilibriumDetector detector(thresholds(), 400);
  // WHEN observations cover less than the window, then less than the return window
  for (hal::TimeUs t = 0; t < thresholds().window_us; t += kPeriodUs) detector.add(signal.at(t));
  // THEN it is not settled yet; one more observation covering the return window settles it
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kNotEnoughData);
  for (hal::TimeUs t = thresholds().window_us; t < thresholds().sway_window_us; t += kPeriodUs) detector.add(signal.at(t));
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kNotEnoughData);
  detector.add(signal.at(thresholds().sway_window_us));
  EXPECT_EQ(detector.check().verdict, EquilibriumVerdict::kSettled);
}

TEST(EquilibriumDetector, AClearedStableBitPreventsSettling) {
  // GIVEN a platform at rest whose load cell once says "not stable" inside the window
  SettlingSignal signal;
  signal.initial_offset.setZero();
  signal.initial_yaw_rad = 0.0;
  EquilibriumDetector detector(thresholds(), 400);
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
  EquilibriumDetector detector(thresholds(), 400);
  for (hal::TimeUs t = 0; t <= 2 * thresholds().window_us; t += kPeriodUs) detector.add(signal.at(t));
  // WHEN checked THEN the tension spread is named and measured about right
  const EquilibriumCheck check = detector.check();
  EXPECT_EQ(check.verdict, EquilibriumVerdict::kTensionSpread);
  EXPECT_NEAR(check.tension_std_n, signal.tension_noise_n, 0.3 * signal.tension_noise_n);
}

TEST(EquilibriumDetector, SlowSteadyRotationIsDetected) {
  // GIVEN a platform still in position but turning at 3x the angular-rate limit
  const double rate_radps = 3.0 * thresholds().max_angular_rate_radps;
  EquilibriumDetector detector(thresholds(), 400);
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
  EquilibriumDetector detector(thresholds(), 400);
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
  EquilibriumDetector detector(thresholds(), 400);
  for (int k = 0; k < 20; ++k) {
    EquilibriumObservation o;
    o.time_us = k * kPeriodUs;
    o.world_R_platform = k % 2 ? q : Eigen::Quaterniond(-q.coeffs());
    detector.add(o);
  }
  // WHEN averaged THEN the mean is that rotation
  EXPECT_LT(detector.average().world_R_platform.angularDistance(q), 1e-12);
}

// The shipped thresholds (daemon defaults) against a pose source whose
// physics runs `time_scale` times faster than the daemon's 50 Hz loop: the
// observations are stamped with the source's own time.
std::optional<hal::TimeUs> settled_at_time_scale(double time_scale, double noise_m, double drift_mps) {
  const EquilibriumThresholds shipped;
  EquilibriumDetector detector(shipped, 4096);
  std::mt19937 random(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (hal::TimeUs loop_us = 0; loop_us <= 60'000'000; loop_us += kPeriodUs) {
    const hal::TimeUs source_us = static_cast<hal::TimeUs>(time_scale * static_cast<double>(loop_us));
    EquilibriumObservation o;
    o.time_us = source_us;
    o.position_world = Eigen::Vector3d(100.0 + drift_mps * 1e-6 * static_cast<double>(source_us), 50.0, 10.0) +
                       noise_m * Eigen::Vector3d(normal(random), normal(random), normal(random));
    o.world_R_platform = Eigen::AngleAxisd(0.002 * normal(random), Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(0.002 * normal(random), Eigen::Vector3d::UnitX());
    o.tension_n = 700.0 + 3.0 * normal(random);
    o.tension_stable = true;
    detector.add(o);
    if (detector.check().settled()) return source_us;
  }
  return std::nullopt;
}

TEST(EquilibriumDetector, ShippedThresholdsSeeRestAtAnyTimeScale) {
  for (const double time_scale : {1.0, 5.0, 20.0, 50.0}) {
    SCOPED_TRACE(time_scale);
    // GIVEN a platform at rest seen through a 5 mm pose noise, at this time scale
    // WHEN observed at 50 Hz of the daemon's clock
    const auto settled_us = settled_at_time_scale(time_scale, 0.005, 0.0);
    // THEN the shipped thresholds see rest once the return window is
    // covered in source time: the sway window, at least twice the rest
    // window of min_samples observations
    ASSERT_TRUE(settled_us.has_value());
    const EquilibriumThresholds shipped;
    const hal::TimeUs min_samples_us =
        static_cast<hal::TimeUs>(time_scale * static_cast<double>((shipped.min_samples - 1) * kPeriodUs));
    EXPECT_LE(*settled_us, std::max(shipped.sway_window_us, 2 * std::max(shipped.window_us, min_samples_us)) +
                               static_cast<hal::TimeUs>(time_scale * 1e6));
  }
}

TEST(EquilibriumDetector, ShippedThresholdsSeeMotionAtAnyTimeScale) {
  for (const double time_scale : {1.0, 20.0}) {
    SCOPED_TRACE(time_scale);
    // GIVEN a quiet platform still drifting at 20x the speed limit in its own time
    const EquilibriumThresholds shipped;
    // WHEN observed at 50 Hz of the daemon's clock, however fast its time runs
    // THEN it is never called settled
    EXPECT_FALSE(settled_at_time_scale(time_scale, 0.0005, 20.0 * shipped.max_speed_mps).has_value());
  }
}

TEST(EquilibriumDetector, WindowHoldsMinSamplesWhenPosesAreSparseInSourceTime) {
  // GIVEN observations 0.4 s apart in source time (the daemon's 50 Hz loop
  // on a source 20x faster) and the shipped 2 s window of min_samples
  const EquilibriumThresholds shipped;
  EquilibriumDetector detector(shipped, 1024);
  for (int k = 0; k < 2 * shipped.min_samples; ++k) {
    EquilibriumObservation o;
    o.time_us = k * 400'000;
    o.tension_n = 500.0;
    o.tension_stable = true;
    detector.add(o);
  }
  // WHEN checked THEN the window keeps min_samples observations and settles
  EXPECT_EQ(detector.size(), shipped.min_samples);
  EXPECT_TRUE(detector.check().settled());
}

TEST(EquilibriumDetector, AverageSigmasAreTheStandardErrorsOfTheWindow) {
  // GIVEN 400 observations at rest with white noise larger than the floors
  std::mt19937 random(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  EquilibriumThresholds t = thresholds();
  t.window_us = 400 * kPeriodUs;
  EquilibriumDetector detector(t, 1024);
  const double encoder_noise_m = 0.01, position_noise_m = 0.004, tension_noise_n = 4.0;
  for (int k = 0; k < 400; ++k) {
    EquilibriumObservation o;
    o.time_us = k * kPeriodUs;
    o.position_world = Eigen::Vector3d(1.0, 2.0, 3.0) +
                       position_noise_m * Eigen::Vector3d(normal(random), normal(random), normal(random));
    for (double& e : o.encoder_m) e = 40.0 + encoder_noise_m * normal(random);
    // Cable 3's encoder is held for 8 observations between its updates.
    o.encoder_m[3] = 40.0 + encoder_noise_m * std::sin(static_cast<double>(k / 8) * 12.9898) * 1.7;
    o.tension_n = 600.0 + tension_noise_n * normal(random);
    detector.add(o);
  }
  // WHEN the sigmas are taken with floors below the noise (the rotation's above it)
  NoiseSigmas floor;
  floor.encoder_m = 0.001;
  floor.force_n = 1.0;
  floor.position_m = 0.001;
  floor.orientation_rad = 0.01;
  const SampleSigmas sigma = detector.average_sigmas(floor);
  // THEN white readings give scatter / sqrt(n), the held one about sqrt(8) more,
  // the noiseless rotation the floor over sqrt(1)
  const double n = detector.size();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(sigma.encoder_m[i], encoder_noise_m / std::sqrt(n), 0.2 * encoder_noise_m / std::sqrt(n));
  EXPECT_GT(sigma.encoder_m[3], 2.0 * sigma.encoder_m[0]);
  EXPECT_NEAR(sigma.force_n, tension_noise_n / std::sqrt(n), 0.2 * tension_noise_n / std::sqrt(n));
  EXPECT_NEAR(sigma.position_m, position_noise_m / std::sqrt(n), 0.2 * position_noise_m / std::sqrt(n));
  EXPECT_DOUBLE_EQ(sigma.orientation_rad, floor.orientation_rad);
}

}  // namespace
}  // namespace cdpr::calibration
