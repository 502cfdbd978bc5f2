// The paired held-out comparison of two models (solver/diagnosis/held_out_comparison.h):
// poses are matched by sample id, and a pose only one model could evaluate
// is left out of both sides.
#include "solver/diagnosis/held_out_comparison.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cdpr {
namespace {

HeldOutEvaluation evaluation(const std::vector<std::pair<int, double>>& id_chi2) {
  HeldOutEvaluation e;
  e.ok = true;
  for (const auto& [id, chi2] : id_chi2) {
    HeldOutPose pose;
    pose.sample.id = id;
    pose.chi2 = chi2;
    e.poses.push_back(pose);
    e.chi2 += chi2;
  }
  return e;
}

TEST(HeldOutComparison, PairsPosesBySampleIdAndSkipsThoseOnlyOneModelEvaluates) {
  // GIVEN a current model evaluating poses 1-5 and a candidate that could not
  // evaluate pose 3 (listed in another order)
  const HeldOutEvaluation current = evaluation({{1, 10.0}, {2, 12.0}, {3, 500.0}, {4, 9.0}, {5, 11.0}});
  const HeldOutEvaluation candidate = evaluation({{5, 8.0}, {4, 8.0}, {2, 9.0}, {1, 7.0}});
  // WHEN they are compared
  const HeldOutComparison c = compare_held_out(current, candidate);
  // THEN only the four common poses count: drops 3, 3, 1, 3 (not pose 3's 500)
  EXPECT_EQ(c.paired_poses, 4);
  EXPECT_DOUBLE_EQ(c.drop, 10.0);
  // mean 2.5, sample sd 1, standard error 0.5
  EXPECT_NEAR(c.t_statistic, 5.0, 1e-12);
}

TEST(HeldOutComparison, HasNoTStatisticBelowThreePairsOrWithoutSpread) {
  const HeldOutEvaluation current = evaluation({{1, 10.0}, {2, 12.0}, {3, 14.0}});
  EXPECT_EQ(compare_held_out(current, evaluation({{1, 9.0}, {2, 8.0}})).t_statistic, 0.0);
  EXPECT_EQ(compare_held_out(current, evaluation({{1, 9.0}, {2, 11.0}, {3, 13.0}})).t_statistic, 0.0);
  EXPECT_EQ(compare_held_out(current, evaluation({{7, 9.0}})).paired_poses, 0);
}

}  // namespace
}  // namespace cdpr
