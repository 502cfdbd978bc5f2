#include "solver/operation/calibration_covariance.h"

#include <cmath>
#include <random>

#include <Eigen/Cholesky>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "sim/rest_sequence.h"
#include "solver/operation/localize.h"

namespace cdpr {
namespace {

// RMS over the rests of the pose-from-the-cables error in its own sigmas.
double normalised_rms(const sim::RestSequence& rests, const Calibration& calibration, const LocalizeOptions& options) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < rests.rests.size(); ++k) {
    const Sample& rest = rests.rests[k];
    const auto pose = localize_rest(rests.nominal, calibration, rest, nominal_start(calibration, rest), options, nullptr);
    EXPECT_TRUE(pose);
    if (!pose) continue;
    const auto error = pose_difference(rests.states[k].world_T_platform, pose->world_T_platform);
    sum += error.cwiseQuotient(pose->covariance.diagonal().cwiseSqrt()).squaredNorm();
    n += 6;
  }
  return std::sqrt(sum / std::max(n, 1));
}

TEST(CalibrationCovariance, MakesThePoseFromTheCablesHonestWhereSigmasAloneOverstateIt) {
  // GIVEN 35 calibration poses spread over the large robot's reach
  sim::DatasetConfig config;
  config.seed = 2;
  config.workspace_min = Eigen::Vector3d(40, 40, 5);
  config.workspace_max = Eigen::Vector3d(200, 180, 35);
  config.segments = 200;  // the true cables coarser: the test is about sigmas, not the model's accuracy
  const auto data = sim::simulate_dataset(config);
  ASSERT_TRUE(data);
  Calibration truth;
  for (int i = 0; i < kCableCount; ++i) {
    truth.winches.push_back({data->truth.winches[i].anchor_world, Eigen::Vector3d::Zero(),
                             data->truth.winches[i].offset_m, 0.0});
  }
  sim::RestSequenceConfig rc;
  rc.robot = config;
  rc.rest_count = 12;
  const auto rests = sim::simulate_rest_sequence(rc);
  ASSERT_TRUE(rests);

  // WHEN the joint covariance of a fit on them is recovered, and a
  // calibration drawn from it (the truth plus an error of that covariance)
  std::string why;
  const auto covariance = calibration_covariance(data->nominal, truth, data->samples, 1e-2, &why);
  ASSERT_TRUE(covariance) << why;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, kCalibrationDimension, 1> draw;
  for (int j = 0; j < kCalibrationDimension; ++j) draw(j) = normal(rng);
  const Eigen::Matrix<double, kCalibrationDimension, 1> error = covariance->llt().matrixL() * draw;
  Calibration fitted = truth;
  for (int i = 0; i < kCableCount; ++i) {
    fitted.winches[i].anchor_world += error.segment<3>(3 * i);
    fitted.winches[i].anchor_sigma = covariance->diagonal().segment<3>(3 * i).cwiseSqrt();
    fitted.winches[i].offset_m += error(12 + i);
    fitted.winches[i].offset_sigma_m = std::sqrt((*covariance)(12 + i, 12 + i));
  }

  // THEN anchor and offset errors of a cable are strongly anti-correlated
  // (they cancel in the length), and the rests' errors match their sigmas
  // with it, while per-axis sigmas make them look several times too small
  const double correlation = (*covariance)(0, 12) / std::sqrt((*covariance)(0, 0) * (*covariance)(12, 12));
  EXPECT_GT(std::abs(correlation), 0.5);
  LocalizeOptions joint;
  joint.calibration_covariance = *covariance;
  const double with_joint = normalised_rms(*rests, fitted, joint);
  const double per_axis = normalised_rms(*rests, fitted, LocalizeOptions{});
  EXPECT_GT(with_joint, 0.6);
  EXPECT_LT(with_joint, 1.4);
  EXPECT_LT(per_axis, 0.7 * with_joint);
}

}  // namespace
}  // namespace cdpr
