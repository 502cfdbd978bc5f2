// Why a fit with too many rows of gross errors is refused
// (solver/calibration/refusal_cause.h): a model that does not fit is told
// apart from a sensor fault by a model term or a noise scale that explains
// the rows.
#include <string>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "solver/calibration/calibrate.h"

namespace cdpr {
namespace {

sim::SimulatedDataset refusal_data(sim::DatasetConfig config) {
  config.segments = 200;
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  return data ? std::move(*data) : sim::SimulatedDataset{};
}

sim::DatasetConfig large_robot(int poses, std::uint64_t seed) {
  sim::DatasetConfig c;
  c.pose_count = poses;
  c.seed = seed;
  c.anchor_perturbation_m = 2.0;
  return c;
}

TEST(RefusalCause, WeightlessCablesSolvedAsCatenariesAreAModelMisfit) {
  // GIVEN straight weightless cables in truth, fitted with the catenary
  sim::DatasetConfig config = large_robot(30, 1);
  config.effects.density_error = -1.0;
  const sim::SimulatedDataset data = refusal_data(config);
  // WHEN calibrated with default options
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  // THEN it is refused as a model misfit, not a sensor fault, naming what explains the rows
  ASSERT_FALSE(result.ok);
  EXPECT_EQ(result.refusal, Refusal::kModelMisfit) << result.message;
  EXPECT_EQ(result.message.rfind("the model does not fit: ", 0), 0u) << result.message;
  EXPECT_EQ(result.message.find("need attention"), std::string::npos) << result.message;
}

TEST(RefusalCause, GrossErrorsNoTermExplainsAreASensorFault) {
  // GIVEN 50 % rows with a 0.5-2 m encoder error, and at most 40 % allowed
  sim::DatasetConfig config = large_robot(30, 3);
  config.gross_errors.encoder_fraction = 0.5;
  const sim::SimulatedDataset data = refusal_data(config);
  // WHEN calibrated
  const CalibrationResult result = calibrate(data.nominal, data.samples, CalibrationOptions{});
  // THEN it is refused as a sensor fault, naming a few of the worst readings only
  ASSERT_FALSE(result.ok);
  EXPECT_EQ(result.refusal, Refusal::kSensorFault) << result.message;
  EXPECT_NE(result.message.find("need attention"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("no model term or pose-noise scale"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find(" more (the gross-error list)"), std::string::npos) << result.message;
  EXPECT_LT(result.message.size(), 1200u) << result.message;
}

}  // namespace
}  // namespace cdpr
