#include "src/calibration/equilibrium_detector.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include <gtest/gtest.h>

#include "equilibrium_test_rate.h"

namespace cdpr::calibration {
namespace {

using test::kPeriodUs;

// A platform swaying slowly about its rest in x and y, as a heavy platform
// on long cables does after a move (the load cell steady: the sway is in
// the pose alone), with the virtual robot's pose noise (5 mm per axis).
struct SlowSway {
  double period_s = 15.0, damping_ratio = 0.05;
  Eigen::Vector2d amplitude_m{0.08, -0.05};
  double noise_m = 0.005;
  Eigen::Vector3d rest_world{120.0, 110.0, 17.0};
  std::mt19937 random{3};

  // The noiseless position [m] at source time t [s].
  Eigen::Vector3d truth(double t) const {
    const double omega = 2.0 * M_PI / period_s;
    const double sway = std::exp(-damping_ratio * omega * t) * std::cos(omega * t + 0.3);
    return rest_world + Eigen::Vector3d(amplitude_m.x(), amplitude_m.y(), 0.0) * sway;
  }
  EquilibriumObservation at(hal::TimeUs time_us) {
    std::normal_distribution<double> normal(0.0, 1.0);
    EquilibriumObservation o;
    o.time_us = time_us;
    o.position_world =
        truth(1e-6 * static_cast<double>(time_us)) + noise_m * Eigen::Vector3d(normal(random), normal(random), normal(random));
    o.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(0.002 * normal(random), Eigen::Vector3d::UnitZ()));
    o.tension_n = 900.0 + 3.0 * normal(random);
    o.tension_stable = true;
    for (int i = 0; i < kCableCount; ++i) o.encoder_m[i] = 50.0 + i;
    return o;
  }
};

// The largest distance [m] of the noiseless platform from its rest over the
// detector's rest window ending at t_us.
double rest_window_distance(const SlowSway& sway, const EquilibriumThresholds& t, hal::TimeUs t_us) {
  double largest = 0.0;
  for (hal::TimeUs s = std::max<hal::TimeUs>(0, t_us - t.window_us); s <= t_us; s += kPeriodUs) {
    largest = std::max(largest, (sway.truth(1e-6 * static_cast<double>(s)) - sway.rest_world).norm());
  }
  return largest;
}

TEST(EquilibriumDetector, ASlowSwayIsNotRestAtItsTurningPoints) {
  for (const double period_s : {5.0, 10.0, 20.0, 30.0}) {
    SCOPED_TRACE(period_s);
    // GIVEN a slowly decaying sway of this period and waiting for rest (the
    // shipped thresholds with estimate_sway off), 50 Hz poses with their
    // source's stamps
    EquilibriumThresholds thresholds;
    thresholds.estimate_sway = false;
    EquilibriumDetector detector(thresholds, 4096);
    SlowSway sway;
    sway.period_s = period_s;
    // WHEN observed until the first settled verdict
    std::optional<hal::TimeUs> settled_us;
    for (hal::TimeUs t = 0; t <= 1'200'000'000 && !settled_us; t += kPeriodUs) {
      detector.add(sway.at(t));
      if (detector.check().settled()) settled_us = t;
    }
    // THEN it settles, and only with the platform within 3 mm of its rest
    // over the whole rest window (the 2 s mean's standard error is 0.5 mm
    // per axis; the turning points of a 5 cm sway pass the rate limits)
    ASSERT_TRUE(settled_us.has_value());
    EXPECT_LT(rest_window_distance(sway, thresholds, *settled_us), 0.003) << 1e-6 * static_cast<double>(*settled_us);
  }
}

TEST(EquilibriumDetector, ASlowSwayIsSeenBeforeTheSwayFitIsTried) {
  // GIVEN the shipped thresholds (sway estimate on) and a 20 s sway of 3 cm
  const EquilibriumThresholds shipped;
  EquilibriumDetector detector(shipped, 4096);
  SlowSway sway;
  sway.period_s = 20.0;
  sway.amplitude_m = Eigen::Vector2d(0.03, 0.0);
  // WHEN observed for one sway window
  // THEN no window is called rest while the platform is more than 3 mm from it
  for (hal::TimeUs t = 0; t < shipped.sway_window_us; t += kPeriodUs) {
    detector.add(sway.at(t));
    const EquilibriumCheck check = detector.check();
    if (check.verdict == EquilibriumVerdict::kSettled) {
      ASSERT_LT(rest_window_distance(sway, shipped, t), 0.003) << 1e-6 * static_cast<double>(t);
    }
  }
}

TEST(EquilibriumDetector, AtRestSettlesOnceTheReturnWindowIsCovered) {
  // GIVEN a platform truly at rest, seen with the virtual robot's pose noise
  EquilibriumThresholds thresholds;
  thresholds.estimate_sway = false;
  EquilibriumDetector detector(thresholds, 4096);
  SlowSway sway;
  sway.amplitude_m.setZero();
  // WHEN observed at 50 Hz
  std::optional<hal::TimeUs> settled_us;
  for (hal::TimeUs t = 0; t <= 60'000'000 && !settled_us; t += kPeriodUs) {
    detector.add(sway.at(t));
    if (detector.check().settled()) settled_us = t;
  }
  // THEN it settles as soon as the return window (the sway window) is covered
  ASSERT_TRUE(settled_us.has_value());
  EXPECT_LE(*settled_us, thresholds.sway_window_us + 10 * kPeriodUs);
}

}  // namespace
}  // namespace cdpr::calibration
