// The encoder offsets of a robot's first run (no previous calibration) are
// estimated at the start pose before the plan: every payout target carries
// their error, so the estimate must average the localization's noise down
// rather than take one reading.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "calibration_rig.h"
#include "../../text_contains.h"

namespace cdpr::calibration {
namespace {

using test::CalibrationRig;

// The first waypoint's payout targets of a first run whose pose source adds
// white noise of `sigma_m` per axis, drawn from `seed`.
std::array<double, kCableCount> first_targets(double sigma_m, unsigned seed) {
  CalibrationRig rig(test::rig_options(), false);
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  rig.pose.set_generator([&](hal::TimeUs now_us) {
    hal::PoseSample sample = rig.platform(now_us);
    sample.platform_world.x += noise(random);
    sample.platform_world.y += noise(random);
    sample.platform_world.z += noise(random);
    return sample;
  });
  EXPECT_TRUE(rig.machine->request_start(rig.clock.now_us()));
  EXPECT_TRUE(rig.run_to(CalibrationState::kMove, 1)) << rig.status().reason;
  EXPECT_FALSE(rig.machine->plan().waypoints.empty());
  if (rig.machine->plan().waypoints.empty()) return {};
  return rig.machine->plan().waypoints.front().payout_m;
}

TEST(StartOffsets, AFirstRunsTargetsAverageThePoseNoiseOfTheStartPose) {
  // GIVEN a first run (nothing stored) and its targets with a noiseless pose
  const std::array<double, kCableCount> exact = first_targets(0.0, 0);
  // WHEN the pose source has the small robot's 5 mm of noise per axis
  constexpr double kSigmaM = 0.005;
  constexpr int kRuns = 10;
  double square_sum = 0.0;
  for (int run = 0; run < kRuns; ++run) {
    const std::array<double, kCableCount> targets = first_targets(kSigmaM, 1000 + run);
    for (int i = 0; i < kCableCount; ++i) square_sum += std::pow(targets[i] - exact[i], 2);
  }
  const double rms_m = std::sqrt(square_sum / (kRuns * kCableCount));
  // THEN the targets' error is that of the mean of the rest window (the rig's
  // 1 s at 50 Hz: 50 poses, sigma / 7), not of one pose (about sigma: a
  // cable's length error is the pose error along it)
  EXPECT_LT(rms_m, kSigmaM / 3.0) << "rms target error " << rms_m << " m";
  EXPECT_GT(rms_m, 0.0);
}

TEST(StartOffsets, APlatformStillSwingingAtTheStartIsWaitedFor) {
  // GIVEN a first run whose platform swings (a run stopped mid-move)
  CalibrationRig rig(test::rig_options(), false);
  rig.swinging = true;
  ASSERT_TRUE(rig.machine->request_start(rig.clock.now_us()));
  // WHEN it has run for less than the settle timeout
  rig.run_until([] { return false; }, 5'000'000);
  // THEN it is still measuring the start pose, drives off
  EXPECT_EQ(rig.status().state, CalibrationState::kPlan);
  EXPECT_TRUE(cdpr::test::contains(rig.status().detail, "measuring the start pose")) << rig.status().detail;
  // AND once the platform is still, the run goes on to the first move
  rig.swinging = false;
  EXPECT_TRUE(rig.run_to(CalibrationState::kMove, 1)) << rig.status().reason;
}

}  // namespace
}  // namespace cdpr::calibration
