#include "src/calibration/window_statistics.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace cdpr::calibration {
namespace {

std::vector<double> white_noise(int n, double sigma, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, sigma);
  std::vector<double> values(static_cast<std::size_t>(n));
  for (double& v : values) v = 3.0 + normal(random);
  return values;
}

TEST(WindowStatistics, WhiteNoiseGivesSigmaOverSqrtN) {
  // GIVEN white noise of sigma 2 above a floor of 0.1, averaged over many windows
  double ratio_sum = 0.0;
  const int windows = 200, n = 100;
  for (int w = 0; w < windows; ++w) {
    // WHEN each window's standard error is taken
    const WindowStatistics s = window_statistics(white_noise(n, 2.0, static_cast<unsigned>(w)), 0.1);
    ratio_sum += s.sigma_of_mean / (2.0 / std::sqrt(n));
    EXPECT_GT(s.effective_count, 0.3 * n);
  }
  // THEN it is sigma / sqrt(n) within a few percent on average (the positive
  // lags of pure noise make it slightly conservative)
  EXPECT_NEAR(ratio_sum / windows, 1.0, 0.12);
}

TEST(WindowStatistics, CorrelatedNoiseGivesFewerEffectiveReadings) {
  // GIVEN an AR(1) series with coefficient 0.9 (integrated time 19 readings)
  std::mt19937 random(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> values(2000);
  double x = 0.0;
  for (double& v : values) v = x = 0.9 * x + normal(random);
  // WHEN the standard error is taken
  const WindowStatistics s = window_statistics(values, 1e-3);
  // THEN n_eff is about n / 19 and the error about sqrt(19) times the naive one
  EXPECT_NEAR(s.effective_count, 2000.0 / 19.0, 0.4 * 2000.0 / 19.0);
  EXPECT_GT(s.sigma_of_mean, 3.0 * s.scatter / std::sqrt(2000.0));
}

TEST(WindowStatistics, RepeatedReadingsCountOnce) {
  // GIVEN 40 independent readings each held for 5 observations
  const std::vector<double> distinct = white_noise(40, 1.0, 5);
  std::vector<double> held;
  for (const double v : distinct) held.insert(held.end(), 5, v);
  // WHEN the standard error is taken THEN about 40 readings count, not 200
  const WindowStatistics s = window_statistics(held, 1e-3);
  EXPECT_NEAR(s.effective_count, 40.0, 15.0);
}

TEST(WindowStatistics, QuietWindowIsFlooredAtTheSensorSigma) {
  // GIVEN white noise 100 times quieter than the sensor's per-reading sigma
  const std::vector<double> values = white_noise(100, 0.01, 9);
  // WHEN the standard error is taken with that sigma as the floor
  const WindowStatistics s = window_statistics(values, 1.0);
  // THEN the scatter is the floor's: floor / sqrt(n_eff)
  EXPECT_NEAR(s.scatter, 0.01, 0.003);
  EXPECT_DOUBLE_EQ(s.sigma_of_mean, 1.0 / std::sqrt(s.effective_count));
  EXPECT_GT(s.sigma_of_mean, 0.08);
}

TEST(WindowStatistics, ConstantWindowIsTheFloorItself) {
  // GIVEN a reading that never changes WHEN the standard error is taken
  const WindowStatistics s = window_statistics(std::vector<double>(50, 7.0), 0.5);
  // THEN nothing shows the readings independent: one reading's sigma
  EXPECT_EQ(s.mean, 7.0);
  EXPECT_EQ(s.effective_count, 1.0);
  EXPECT_EQ(s.sigma_of_mean, 0.5);
}

TEST(WindowStatistics, OneReadingIsTheFloor) {
  const WindowStatistics s = window_statistics(std::vector<double>{2.0}, 0.3);
  EXPECT_EQ(s.sigma_of_mean, 0.3);
}

}  // namespace
}  // namespace cdpr::calibration
