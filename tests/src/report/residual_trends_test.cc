#include "src/report/residual_trends.h"

#include <gtest/gtest.h>

namespace cdpr::report {
namespace {

// Held-out poses whose encoder residuals alternate around zero (no trend),
// with `drift` [m] added over the run on the cables given.
HeldOutEvaluation poses_with_drift(const std::vector<std::pair<int, double>>& drift) {
  HeldOutEvaluation h;
  h.ok = true;
  const int n = 40;
  for (int k = 0; k < n; ++k) {
    HeldOutPose pose;
    pose.sample.id = k;
    // Lengths, tensions and heights unrelated to the order.
    pose.world_T_platform.position_world = Eigen::Vector3d(0, 0, 10.0 + (k * 7) % 11);
    for (int i = 0; i < kCableCount; ++i) {
      pose.prediction.payout_m[i] = 100.0 + (k * 13 + 5 * i) % 17;
      pose.prediction.tension_n[i] = 500.0 + 10.0 * ((k * 5 + i) % 19);
      pose.prediction.encoder_residual_m[i] = (k % 2 ? 0.01 : -0.01);
      pose.prediction.height_residual_m[i] = (k % 3 ? 0.001 : -0.002);
    }
    for (auto [cable, metres] : drift) pose.prediction.encoder_residual_m[cable] += metres * k / (n - 1);
    pose.prediction.force_residual_n = (k % 2 ? 1.0 : -1.0);
    pose.sample.force_n = 600.0 + (k * 3) % 7;
    h.poses.push_back(pose);
  }
  return h;
}

TEST(ResidualTrends, DriftOverTheRunIsNamedAsSampleOrderOnItsCables) {
  // GIVEN encoders 0 and 3 drifting by 60 mm over the run
  const std::vector<Trend> trends = residual_trends(poses_with_drift({{0, 0.06}, {3, 0.05}}));
  // THEN the strongest trend is against the sample order, and the words name both cables
  ASSERT_FALSE(trends.empty());
  EXPECT_EQ(trends.front().against, kSampleOrder);
  EXPECT_LT(trends.front().p_value, 1e-6);
  const std::string text = strongest_trend_text(trends);
  EXPECT_NE(text.find("encoder residuals grow with sample order on cables 0 and 3"), std::string::npos) << text;
  EXPECT_NE(text.find("mm over the run"), std::string::npos) << text;
}

TEST(ResidualTrends, OppositeDriftsChangeRatherThanGrow) {
  const std::string text = strongest_trend_text(residual_trends(poses_with_drift({{1, 0.06}, {2, -0.06}})));
  EXPECT_NE(text.find("encoder residuals change with sample order on cables 1 and 2"), std::string::npos) << text;
}

TEST(ResidualTrends, AReadingLeftOutAsAGrossErrorMakesNoTrend) {
  // GIVEN no drift, but the last pose's encoder 3 and load cell wrong by 1.4 m and 300 N and left out
  HeldOutEvaluation h = poses_with_drift({});
  HeldOutPose& last = h.poses.back();
  last.prediction.encoder_residual_m[3] += 1.4;
  last.prediction.force_residual_n += 300.0;
  last.sample.encoder_left_out[3] = true;
  last.sample.force_left_out = true;
  // THEN no trend is significant, and the series leave those readings out
  for (const Trend& t : residual_trends(h)) EXPECT_GT(t.p_value, 1e-3) << t.sensor << " vs " << t.against;
  for (const ResidualSeries& s : residual_series(h)) {
    const bool left_out = s.sensor == "encoder 3" || s.sensor == "load cell";
    EXPECT_EQ(s.x.size(), h.poses.size() - (left_out ? 1 : 0)) << s.sensor << " vs " << s.against;
  }
}

TEST(ResidualTrends, NoTrendsNoWords) { EXPECT_EQ(strongest_trend_text({}), ""); }

}  // namespace
}  // namespace cdpr::report
