// Watch mode's rest finder (src/operation/rest_watch.h) and the pose
// output's lines (src/operation/pose_output_line.h).
#include <cmath>

#include <gtest/gtest.h>

#include "src/operation/pose_output_line.h"
#include "src/operation/rest_watch.h"

namespace cdpr::operation {
namespace {

calibration::EquilibriumThresholds watch_thresholds() {
  calibration::EquilibriumThresholds t;
  t.window_us = 2'000'000;
  t.sway_window_us = 6'000'000;
  t.min_samples = 20;
  t.estimate_sway = false;
  return t;
}

// One 50 Hz step at source time t_us with the platform at x [m] (a little noise, as a sensor).
WatchReadings at(hal::TimeUs t_us, double x, int k) {
  WatchReadings r;
  hal::PoseSample pose;
  const double noise = 1e-4 * std::sin(1.7 * k);
  pose.platform_world = {x + noise, 2.0, 3.0};
  pose.world_R_platform = {1.0, 0.0, 0.0, 0.0};
  pose.valid = true;
  pose.source_time_us = t_us;
  r.pose = pose;
  for (int i = 0; i < kCableCount; ++i) r.payout_m[i] = 10.0 + i + x + noise;
  r.tension = hal::TensionSample{500.0 + 0.5 * std::cos(2.3 * k), true, t_us};
  return r;
}

TEST(RestWatch, OneRestPerStopOnceItHeldThenAnotherAfterAMove) {
  // GIVEN the watch with a 2 s rest window and a 6 s return window
  NoiseSigmas noise;
  noise.encoder_m = 1e-3;
  noise.force_n = 1.0;
  noise.position_m = 1e-3;
  noise.orientation_rad = 1e-3;
  RestWatch watch(watch_thresholds(), 4096, noise);
  std::vector<int> rests_at_k;
  double x = 0.0;
  // WHEN the platform rests 20 s, moves 1 m in 10 s, rests 20 s (50 Hz)
  for (int k = 0; k < 2500; ++k) {
    if (k >= 1000 && k < 1500) x += 1.0 / 500.0;
    const hal::TimeUs t_us = 20'000LL * k;
    if (const std::optional<WatchedRest> rest = watch.step(at(t_us, x, k), t_us)) {
      rests_at_k.push_back(k);
      EXPECT_EQ(rest->index, static_cast<int>(rests_at_k.size()));
      EXPECT_EQ(rest->source_time_us, t_us);
      EXPECT_NEAR(rest->sample.position_world.x(), x, 1e-3);
      EXPECT_GT(rest->sample.sigma.force_n, 0.0);
    }
  }
  // THEN exactly two rests: the first once the return window is covered
  // and the verdict held two rest windows, the second a rest window after
  // the stop plus that hold (50 Hz)
  ASSERT_EQ(rests_at_k.size(), 2u);
  EXPECT_GE(rests_at_k[0], 300 + 200);
  EXPECT_GE(rests_at_k[1], 1500 + 200);  // at least the hold after the stop
  EXPECT_LT(rests_at_k[1], 1500 + 100 + 200 + 100);
  EXPECT_EQ(watch.rests(), 2);
}

TEST(RestWatch, AMissingReadingStartsTheWindowOver) {
  NoiseSigmas noise;
  noise.encoder_m = noise.position_m = noise.orientation_rad = 1e-3;
  noise.force_n = 1.0;
  RestWatch watch(watch_thresholds(), 4096, noise);
  int rests = 0;
  for (int k = 0; k < 1000; ++k) {
    WatchReadings r = at(20'000LL * k, 0.0, k);
    if (k % 200 == 199) r.tension.reset();  // the load cell misses a reading every 4 s
    rests += watch.step(r, 0).has_value() ? 1 : 0;
  }
  EXPECT_EQ(rests, 0);  // never 10 s in a row
}

TEST(PoseOutputLine, PoseAndCovarianceReadBackExactly) {
  Pose pose;
  pose.position_world = {120.25, 110.125, 17.0625};
  pose.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()));
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Identity() * 4e-6;
  c(0, 5) = c(5, 0) = 1.0 / 3.0 * 1e-7;
  const std::string text = format_pose_output(1234567, pose, c);
  const std::size_t newline = text.find('\n');
  ASSERT_NE(newline, std::string::npos);
  EXPECT_EQ(text.substr(0, 13), "POSE 1234567 ");
  const auto parsed = parse_covariance_line(text.substr(newline + 1, text.size() - newline - 2));
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed->source_time_us, 1234567);
  EXPECT_EQ(parsed->covariance, c);
  EXPECT_FALSE(parse_covariance_line("COV 12 1 2 3"));
  EXPECT_FALSE(parse_covariance_line("POSE 1 2 3"));
}

}  // namespace
}  // namespace cdpr::operation
