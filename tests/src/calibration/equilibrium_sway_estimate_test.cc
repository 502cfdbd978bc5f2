#include "src/calibration/equilibrium_detector.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "equilibrium_test_rate.h"

namespace cdpr::calibration {
namespace {

using test::kPeriodUs;

// A platform swaying about its rest after a move: one decaying oscillation
// (period 10 s, damping ratio 0.05) of position, yaw and tension, with white
// sensor noise; the load cell's stable bit clear throughout, as a cell
// clears it for a swinging load. `drift_mps` moves the rest itself;
// `second_mode_m` adds a y sway of another period.
struct SwaySignal {
  Eigen::Vector3d rest_world{120.0, 110.0, 17.0};
  Eigen::Vector3d amplitude_m{0.8, -0.5, 0.05};
  double period_s = 10.0, damping_ratio = 0.05;
  double yaw_amplitude_rad = 0.02;
  double tension_rest_n = 900.0, tension_amplitude_n = 60.0;
  double position_noise_m = 0.005, tension_noise_n = 5.0, orientation_noise_rad = 0.002;
  double drift_mps = 0.0;
  double second_mode_m = 0.0, second_period_s = 6.3;
  std::mt19937 random{7};

  EquilibriumObservation at(hal::TimeUs time_us) {
    std::normal_distribution<double> normal(0.0, 1.0);
    const double t = 1e-6 * static_cast<double>(time_us);
    const double omega = 2.0 * M_PI / period_s;
    const double sway = std::exp(-damping_ratio * omega * t) * std::cos(omega * t + 0.4);
    EquilibriumObservation o;
    o.time_us = time_us;
    o.position_world = rest_world + amplitude_m * sway + Eigen::Vector3d(drift_mps * t, 0.0, 0.0) +
                       Eigen::Vector3d(0.0, second_mode_m * std::sin(2.0 * M_PI * t / second_period_s), 0.0) +
                       position_noise_m * Eigen::Vector3d(normal(random), normal(random), normal(random));
    o.world_R_platform = Eigen::Quaterniond(
        Eigen::AngleAxisd(yaw_amplitude_rad * sway + orientation_noise_rad * normal(random), Eigen::Vector3d::UnitZ()));
    o.tension_n = tension_rest_n + tension_amplitude_n * sway + tension_noise_n * normal(random);
    o.tension_stable = false;
    for (int i = 0; i < kCableCount; ++i) o.encoder_m[i] = 50.0 + i + 0.01 * normal(random);
    return o;
  }
};

// Feeds `signal` at 50 Hz until settled or `limit_s`; the check of the last observation.
EquilibriumCheck run_until_settled(EquilibriumDetector& detector, SwaySignal& signal, double limit_s) {
  EquilibriumCheck check;
  for (hal::TimeUs t = 0; t <= static_cast<hal::TimeUs>(limit_s * 1e6) && !check.settled(); t += kPeriodUs) {
    detector.add(signal.at(t));
    check = detector.check();
  }
  return check;
}

TEST(EquilibriumDetector, SwayAboutRestIsEstimatedInsteadOfWaitedOut) {
  // GIVEN a platform swaying by almost 1 m about its rest, and the shipped thresholds
  const EquilibriumThresholds shipped;
  EquilibriumDetector detector(shipped, 4096);
  SwaySignal signal;
  // WHEN observed at 50 Hz
  const EquilibriumCheck check = run_until_settled(detector, signal, 120.0);
  // THEN the rest is estimated from the sway once the sway window is covered, long before the sway dies out
  ASSERT_EQ(check.verdict, EquilibriumVerdict::kSwayEstimated) << to_string(check.verdict);
  EXPECT_NEAR(check.sway_period_s, signal.period_s, 0.05);
  // AND the sample is the rest state within its sigmas
  const Sample sample = detector.average();
  const SampleSigmas sigma = detector.average_sigmas(NoiseSigmas{});
  EXPECT_LT(sigma.position_m, 0.002);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(sample.position_world(axis), signal.rest_world(axis), 4.0 * sigma.position_m) << axis;
  }
  EXPECT_NEAR(sample.force_n, signal.tension_rest_n, 4.0 * sigma.force_n);
  EXPECT_LT(sample.world_R_platform.angularDistance(Eigen::Quaterniond::Identity()), 4.0 * sigma.orientation_rad);
  EXPECT_NEAR(sample.encoder_m[2], 52.0, 4.0 * sigma.encoder_m[2]);
}

TEST(EquilibriumDetector, SwayIsWaitedOutWhenEstimatingIsOff) {
  // GIVEN the same sway and estimate_sway off
  EquilibriumThresholds thresholds;
  thresholds.estimate_sway = false;
  EquilibriumDetector detector(thresholds, 4096);
  SwaySignal signal;
  // WHEN observed for two minutes THEN it is still moving
  EXPECT_FALSE(run_until_settled(detector, signal, 120.0).settled());
}

TEST(EquilibriumDetector, ASwayWhoseRestDriftsIsNotEstimated) {
  // GIVEN a sway about a rest that still creeps at 1 mm/s
  EquilibriumDetector detector(EquilibriumThresholds{}, 4096);
  SwaySignal signal;
  signal.drift_mps = 0.001;
  // WHEN observed THEN no window is accepted as a sway about rest
  EXPECT_FALSE(run_until_settled(detector, signal, 120.0).settled());
}

TEST(EquilibriumDetector, TwoSwayModesAreNotTakenForOne) {
  // GIVEN a second sway in y with another period, as large as the first
  EquilibriumDetector detector(EquilibriumThresholds{}, 4096);
  SwaySignal signal;
  signal.damping_ratio = 0.01;
  signal.second_mode_m = 0.5;
  // WHEN observed THEN it is waited out, not fitted with one oscillation
  EXPECT_FALSE(run_until_settled(detector, signal, 120.0).settled());
}

TEST(EquilibriumDetector, AtRestWithAnUnstableLoadCellIsNotASway) {
  // GIVEN a platform at rest whose load cell keeps its stable bit clear
  EquilibriumDetector detector(EquilibriumThresholds{}, 4096);
  SwaySignal signal;
  signal.amplitude_m.setZero();
  signal.yaw_amplitude_rad = 0.0;
  signal.tension_amplitude_n = 0.0;
  // WHEN observed THEN the clear bit still refuses it
  const EquilibriumCheck check = run_until_settled(detector, signal, 120.0);
  EXPECT_EQ(check.verdict, EquilibriumVerdict::kTensionUnstable);
}

}  // namespace
}  // namespace cdpr::calibration
