// CalibrationResult::stages: the recorder alone, then what calibrate()
// records on clean data, with gross errors, and when it falls back.
#include "solver/calibration/calibration_stages.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"

namespace cdpr {
namespace {

TEST(CalibrationStages, ScopesNestTheirStagesAndSumTheirIterations) {
  // GIVEN a recorder, a stage, a scope holding two stages, and a stage after it
  std::vector<CalibrationStage> stages;
  {
    const StageRecorder recorder(stages);
    record_stage("first", "done", 3, 1.5);
    {
      StageScope scope("restart", true);
      record_stage("inner one", "ok", 4, 2.0);
      record_stage("inner two", "ok", 5, 1.0);
      scope.finish("kept");
    }
    record_stage("last", "checked");
  }
  // THEN they are in order, the scope's own line before its stages, one
  // level deeper, and the scope carries their iterations
  ASSERT_EQ(stages.size(), 5u);
  EXPECT_EQ(stages[0].name, "first");
  EXPECT_EQ(stages[0].depth, 0);
  EXPECT_EQ(stages[1].name, "restart");
  EXPECT_TRUE(stages[1].fallback);
  EXPECT_EQ(stages[1].outcome, "kept");
  EXPECT_EQ(stages[1].iterations, 9);
  EXPECT_TRUE(std::isnan(stages[1].cost));
  EXPECT_EQ(stages[2].depth, 1);
  EXPECT_EQ(stages[3].depth, 1);
  EXPECT_EQ(stages[4].name, "last");
  EXPECT_EQ(stages[4].depth, 0);
  EXPECT_FALSE(stages[4].fallback);
}

TEST(CalibrationStages, ASearchKeepsOnlyItsSummaryAndAnUnfinishedScopeSaysSo) {
  std::vector<CalibrationStage> stages;
  {
    const StageRecorder recorder(stages);
    {
      StageScope search("other starts", true, StageScope::Inner::kSummaryOnly);
      record_stage("a fit inside", "ok", 7, 1.0);
      StageScope nested("a restart inside", true);
      record_stage("another", "ok", 2, 1.0);
      search.finish("2 fits; kept the first");
    }
    StageScope left("left early", false);
  }
  ASSERT_EQ(stages.size(), 2u);
  EXPECT_EQ(stages[0].outcome, "2 fits; kept the first");
  EXPECT_EQ(stages[0].iterations, 9);
  EXPECT_EQ(stages[1].outcome, "abandoned");
}

TEST(CalibrationStages, NothingIsRecordedWithoutARecorder) {
  // A stage outside calibrate() (calibrate_once called alone) goes nowhere.
  record_stage("alone", "ok", 1, 1.0);
  StageScope scope("alone too", false);
  scope.finish("ok");
  std::vector<CalibrationStage> stages;
  { const StageRecorder recorder(stages); }
  EXPECT_TRUE(stages.empty());
}

sim::SimulatedDataset simulate_for_stages(sim::DatasetConfig config) {
  config.segments = 400;
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  return data ? std::move(*data) : sim::SimulatedDataset{};
}

sim::DatasetConfig large_for_stages(int poses, std::uint64_t seed) {
  sim::DatasetConfig c;
  c.pose_count = poses;
  c.seed = seed;
  c.anchor_perturbation_m = 10.0;
  return c;
}

const CalibrationStage* find_stage(const CalibrationResult& result, const std::string& prefix) {
  const auto it = std::find_if(result.stages.begin(), result.stages.end(),
                               [&](const CalibrationStage& s) { return s.name.rfind(prefix, 0) == 0; });
  return it == result.stages.end() ? nullptr : &*it;
}

std::string listed(const CalibrationResult& result) {
  std::string text;
  for (const CalibrationStage& s : result.stages) {
    text += std::string(2 * s.depth, ' ') + s.name + (s.fallback ? " [fallback]" : "") + ": " +
            std::to_string(s.iterations) + " it, " + s.outcome + "\n";
  }
  return text;
}

TEST(CalibrationStages, ACleanFitRecordsItsRobustAndFinalFitsWhoseIterationsAreTheSolvers) {
  // GIVEN clean data of 35 poses, nominal anchors 10 m off
  const sim::SimulatedDataset data = simulate_for_stages(large_for_stages(35, 5));
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // THEN the Huber fit and the final fit are recorded at the top level, no
  // fallback was taken, and their iterations are the summary's
  const CalibrationStage* huber = find_stage(result, "robust fit, Huber");
  ASSERT_NE(huber, nullptr) << listed(result);
  EXPECT_GT(huber->iterations, 0);
  EXPECT_TRUE(std::isfinite(huber->cost));
  ASSERT_NE(find_stage(result, "final fit, least squares"), nullptr) << listed(result);
  int iterations = 0;
  for (const CalibrationStage& s : result.stages) {
    EXPECT_EQ(s.depth, 0) << listed(result);
    EXPECT_FALSE(s.fallback) << listed(result);
    iterations += s.iterations;
  }
  EXPECT_EQ(iterations, result.solver.iterations) << listed(result);
}

TEST(CalibrationStages, GrossErrorsShowTheTestTheRefitAndTheOtherStartsAsAFallback) {
  // GIVEN 35 poses with 10 % rows with an encoder error and 5 % with a load-cell spike
  sim::DatasetConfig config = large_for_stages(35, 3);
  config.gross_errors.encoder_fraction = 0.1;
  config.gross_errors.force_fraction = 0.05;
  const sim::SimulatedDataset data = simulate_for_stages(config);
  // WHEN calibrated
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // THEN the gross-error test names readings, the refit without them holds
  // its own fits one level deeper, and the other starts it called for are
  // marked as a fallback
  const CalibrationStage* test = find_stage(result, "gross-error test");
  ASSERT_NE(test, nullptr) << listed(result);
  EXPECT_NE(test->outcome.find("leave-one-out names"), std::string::npos) << listed(result);
  const auto refit = std::find_if(result.stages.begin(), result.stages.end(), [](const CalibrationStage& s) {
    return s.name == "refit without the gross errors";
  });
  ASSERT_NE(refit, result.stages.end()) << listed(result);
  EXPECT_FALSE(refit->fallback);
  ASSERT_NE(refit + 1, result.stages.end());
  EXPECT_EQ((refit + 1)->depth, refit->depth + 1) << listed(result);
  EXPECT_GT(refit->iterations, 0);
  const CalibrationStage* starts = find_stage(result, "other starts");
  ASSERT_NE(starts, nullptr) << listed(result);
  EXPECT_TRUE(starts->fallback);
  EXPECT_NE(starts->outcome.find("kept"), std::string::npos) << listed(result);
}

TEST(CalibrationStages, RowsThatCannotBeStartedShowAndTheStartThatTakesThemIsAFallback) {
  // GIVEN 9 clean poses with nominal anchors 20 m off, from which 3 rows
  // cannot be started
  sim::DatasetConfig config = large_for_stages(9, 22);
  config.anchor_perturbation_m = 20.0;
  const sim::SimulatedDataset data = simulate_for_stages(config);
  // WHEN calibrated
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  ASSERT_TRUE(result.ok) << result.message;
  // THEN the first stage says which rows could not be started, and the
  // other starts, a fallback, say they kept a fit of another start
  ASSERT_FALSE(result.stages.empty());
  EXPECT_EQ(result.stages.front().name, "start") << listed(result);
  EXPECT_NE(result.stages.front().outcome.find("cannot be started"), std::string::npos) << listed(result);
  const CalibrationStage* starts = find_stage(result, "other starts");
  ASSERT_NE(starts, nullptr) << listed(result);
  EXPECT_TRUE(starts->fallback);
  EXPECT_EQ(starts->outcome.find("kept the fit from the nominal anchors"), std::string::npos) << listed(result);
}

}  // namespace
}  // namespace cdpr
