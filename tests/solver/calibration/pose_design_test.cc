#include "solver/calibration/pose_design.h"

#include <cmath>
#include <set>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "../model/test_robots.h"

namespace cdpr {
namespace {

// Straight-cable encoder readings for anchors+offsets `parameters` at `pose`.
Eigen::Vector4d readings(const Robot& robot, const Eigen::Matrix<double, kDesignParameters, 1>& parameters,
                         const Pose& pose) {
  Eigen::Vector4d l;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d anchor = parameters.segment<3>(3 * i);
    l(i) = (anchor - pose.transform(robot.winches[i].attachment_platform)).norm() + parameters(3 * kCableCount + i);
  }
  return l;
}

// The same information built from central differences, for comparison.
DesignInformation numeric_information(const Robot& robot, const Pose& pose) {
  Eigen::Matrix<double, kDesignParameters, 1> parameters = Eigen::Matrix<double, kDesignParameters, 1>::Zero();
  for (int i = 0; i < kCableCount; ++i) parameters.segment<3>(3 * i) = robot.winches[i].anchor_world;
  const double h = 1e-6;
  Eigen::Matrix<double, kCableCount, kDesignParameters> j_parameters;
  for (int k = 0; k < kDesignParameters; ++k) {
    auto plus = parameters, minus = parameters;
    plus(k) += h;
    minus(k) -= h;
    j_parameters.col(k) = (readings(robot, plus, pose) - readings(robot, minus, pose)) / (2 * h);
  }
  Eigen::Matrix<double, kCableCount, 6> j_pose;
  for (int k = 0; k < 6; ++k) {
    double step[6] = {0, 0, 0, 0, 0, 0};
    step[k] = h;
    Pose plus = pose;
    retract(plus, step);
    step[k] = -h;
    Pose minus = pose;
    retract(minus, step);
    j_pose.col(k) = (readings(robot, parameters, plus) - readings(robot, parameters, minus)) / (2 * h);
  }
  const double w = 1.0 / (robot.noise.encoder_m * robot.noise.encoder_m);
  Eigen::Matrix<double, 6, 6> prior = Eigen::Matrix<double, 6, 6>::Zero();
  prior.diagonal().head<3>().setConstant(1.0 / (robot.noise.position_m * robot.noise.position_m));
  prior.diagonal().tail<3>().setConstant(1.0 / (robot.noise.orientation_rad * robot.noise.orientation_rad));
  // Products first, then scaled (GCC 12 -O1 with sanitizers: see pose_design.cc).
  const Eigen::Matrix<double, 6, kCableCount> j_pose_t = j_pose.transpose();
  const Eigen::Matrix<double, 6, 6> i_pose = Eigen::Matrix<double, 6, 6>(j_pose_t * j_pose) * w + prior;
  const Eigen::Matrix<double, 6, kDesignParameters> i_cross =
      Eigen::Matrix<double, 6, kDesignParameters>(j_pose_t * j_parameters) * w;
  const DesignInformation i_parameters = DesignInformation(j_parameters.transpose() * j_parameters) * w;
  return i_parameters - i_cross.transpose() * i_pose.inverse() * i_cross;
}

Pose tilted_pose(const Eigen::Vector3d& position) {
  Pose pose;
  pose.position_world = position;
  pose.world_R_platform = so3_exp(Eigen::Vector3d(0.05, -0.08, 0.4));
  return pose;
}

TEST(PoseDesign, InformationOfAPoseMatchesCentralDifferences) {
  // GIVEN the small robot at a tilted, turned pose off-centre
  const Robot robot = test::small_robot();
  const Pose pose = tilted_pose(Eigen::Vector3d(3.0, 1.2, 14.0));
  // WHEN its information is computed analytically and numerically THEN they agree
  const DesignInformation analytic = pose_information(robot, pose);
  const DesignInformation numeric = numeric_information(robot, pose);
  EXPECT_LT((analytic - numeric).norm(), 1e-5 * numeric.norm()) << (analytic - numeric);
  // AND one pose of four readings informs at most four directions
  const Eigen::SelfAdjointEigenSolver<DesignInformation> eigen(analytic);
  EXPECT_LT(eigen.eigenvalues()(kDesignParameters - 5), 1e-6 * eigen.eigenvalues().maxCoeff());
}

TEST(PoseDesign, ChoosesDistinctCandidatesAndNeverMoreThanThereAre) {
  const Robot robot = test::small_robot();
  std::vector<Pose> candidates;
  for (double z : {4.0, 12.0, 20.0}) candidates.push_back(tilted_pose(Eigen::Vector3d(6.0, 2.0, z)));
  const std::vector<int> chosen = choose_informative_poses(robot, candidates, 5);
  ASSERT_EQ(chosen.size(), 3u);
  EXPECT_EQ(std::set<int>(chosen.begin(), chosen.end()).size(), 3u);
}

TEST(PoseDesign, InformativePosesBeatAnEvenSpreadOnTheSmallRobot) {
  // GIVEN the small robot and a grid of candidates over its whole box, high and low
  const Robot robot = test::small_robot();
  std::vector<Pose> candidates;
  for (double x = 1.0; x <= 11.5; x += 1.5) {
    for (double y = 0.6; y <= 3.9; y += 1.1) {
      for (double z = 2.0; z <= 24.0; z += 2.75) candidates.push_back(tilted_pose(Eigen::Vector3d(x, y, z)));
    }
  }
  // WHEN 8 are chosen for information, and 8 are taken evenly through the list
  const std::vector<int> chosen = choose_informative_poses(robot, candidates, 8);
  std::vector<Pose> informative, even;
  for (int k : chosen) informative.push_back(candidates[k]);
  for (int k = 0; k < 8; ++k) even.push_back(candidates[k * candidates.size() / 8]);
  // THEN the chosen design allows the smaller variances, and its anchor sigma (Cramer-Rao) is smaller
  EXPECT_LT(design_variance_sum(robot, informative), design_variance_sum(robot, even));
  const auto anchor_sigma = [&](const std::vector<Pose>& poses) {
    const DesignInformation covariance = design_covariance(robot, poses);
    return std::sqrt(covariance.diagonal().head<3 * kCableCount>().sum() / kCableCount);
  };
  EXPECT_LT(anchor_sigma(informative), 0.5 * anchor_sigma(even));
}

TEST(PoseDesign, CovarianceIsTheInverseOfTheSummedInformation) {
  const Robot robot = test::small_robot();
  std::vector<Pose> poses;
  for (double x : {2.0, 10.0}) {
    for (double y : {1.0, 3.5}) {
      for (double z : {4.0, 20.0}) poses.push_back(tilted_pose(Eigen::Vector3d(x, y, z)));
    }
  }
  DesignInformation information = DesignInformation::Zero();
  for (const Pose& pose : poses) information += pose_information(robot, pose);
  const DesignInformation covariance = design_covariance(robot, poses);
  // Up to the design's tiny ridge, which only matters in unseen directions.
  EXPECT_LT((covariance * information - DesignInformation::Identity()).norm(), 1e-4);
  EXPECT_NEAR(covariance.trace(), design_variance_sum(robot, poses), 1e-12 * covariance.trace());
}

}  // namespace
}  // namespace cdpr
