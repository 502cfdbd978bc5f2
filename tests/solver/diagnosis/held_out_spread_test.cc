// The held-out chi-square's mean and variance under a right model
// (solver/diagnosis/held_out.h), which the model-discrepancy workflow's "structure
// remains" test stands on: on data the catenary model describes, the
// standardized excess (chi2 - expected) / sqrt(variance) must look like a
// standard normal. Taken as a chi-square's (variance 2 expected), the spread
// was understated: the training fit's error is shared by a fold's poses.
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "diagnosis_configs.h"
#include "sim/dataset.h"
#include "solver/diagnosis/model_search.h"

namespace cdpr {
namespace {

TEST(HeldOutChi2, SpreadsAsItsMeanAndVarianceSayWhenTheModelIsRight) {
  // GIVEN 24 data sets of the large robot without hidden effects
  std::vector<double> z;
  for (std::uint64_t seed = 201; seed < 225; ++seed) {
    auto data = sim::simulate_dataset(test::large_robot_45_poses(seed));
    ASSERT_TRUE(data) << data.error();
    // WHEN the catenary model is cross-validated on each
    const HeldOutEvaluation h = cross_validate(data->nominal, data->samples, DiagnosisOptions{}, {});
    ASSERT_TRUE(h.ok) << h.message;
    ASSERT_GT(h.chi2_variance, 2.0 * h.expected_chi2);
    z.push_back((h.chi2 - h.expected_chi2) / std::sqrt(h.chi2_variance));
  }
  // THEN the standardized excess has mean 0 and variance 1 within what 24
  // draws allow (standard errors about 0.2 and 0.3)
  double mean = 0.0, square = 0.0;
  for (double v : z) mean += v / static_cast<double>(z.size());
  for (double v : z) square += (v - mean) * (v - mean) / static_cast<double>(z.size() - 1);
  EXPECT_LT(std::abs(mean), 0.6);
  EXPECT_LT(square, 1.6);
  EXPECT_GT(square, 0.4);
}

}  // namespace
}  // namespace cdpr
