// Held-out evaluation (solver/diagnosis/held_out.h) on samples with readings
// left out as gross errors: those readings are predicted but are no evidence
// of misfit, so neither the chi-square nor the rms may count them.
#include <cmath>

#include <gtest/gtest.h>

#include "diagnosis_configs.h"
#include "sim/dataset.h"
#include "solver/diagnosis/model_search.h"

namespace cdpr {
namespace {

TEST(HeldOut, ReadingsLeftOutAsGrossErrorsAreNotInTheRms) {
  // GIVEN a data set without effects, and the same with one encoder reading 1.5 m and one
  // load-cell reading 400 N wrong, both marked left out (as diagnose does with the robust fit's gross errors)
  auto data = sim::simulate_dataset(test::large_robot_45_poses(211));
  ASSERT_TRUE(data) << data.error();
  std::vector<Sample> marked = data->samples;
  marked[17].encoder_m[2] += 1.5;
  marked[17].encoder_left_out[2] = true;
  marked[30].force_n += 400.0;
  marked[30].force_left_out = true;
  // WHEN both are cross-validated
  const HeldOutEvaluation clean = cross_validate(data->nominal, data->samples, DiagnosisOptions{}, {});
  const HeldOutEvaluation left_out = cross_validate(data->nominal, marked, DiagnosisOptions{}, {});
  ASSERT_TRUE(clean.ok && left_out.ok) << clean.message << left_out.message;
  // THEN the rms stay at the clean data's (one reading of 180 at 1.5 m would add 0.11 m; one of 45 at 400 N, 60 N)
  EXPECT_LT(left_out.rms_encoder_m, 1.5 * clean.rms_encoder_m);
  EXPECT_LT(left_out.rms_force_n, 1.5 * clean.rms_force_n);
  // AND the chi-square has fewer, not larger, terms
  EXPECT_LT(left_out.chi2, clean.chi2 + 3.0 * std::sqrt(clean.chi2_variance));
}

}  // namespace
}  // namespace cdpr
