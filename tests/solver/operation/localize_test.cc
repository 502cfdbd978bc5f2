#include "solver/operation/localize.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "simulated_rests.h"

namespace cdpr {
namespace {

// Error of the pose from the cables against the true pose, in sigmas of its
// own covariance, over `rests`: the RMS of the normalised components.
struct Normalised {
  double rms = 0.0;
  double worst = 0.0;
};

Normalised localize_all(const test::SimulatedRests& r, int count) {
  double sum = 0.0, worst = 0.0;
  int n = 0;
  Pose start = nominal_start(r.calibration, r.data.samples[0]);
  for (int k = 0; k < count; ++k) {
    std::string why;
    const auto pose = localize_rest(r.data.nominal, r.calibration, r.data.samples[k], start, {}, &why);
    EXPECT_TRUE(pose) << "rest " << k << ": " << why;
    if (!pose) continue;
    EXPECT_TRUE(pose->converged);
    const Eigen::Matrix<double, 6, 1> error = pose_difference(r.data.states[k].world_T_platform, pose->world_T_platform);
    for (int j = 0; j < 6; ++j) {
      const double z = error(j) / std::sqrt(pose->covariance(j, j));
      sum += z * z;
      worst = std::max(worst, std::abs(z));
      ++n;
    }
    start = pose->world_T_platform;
  }
  return {std::sqrt(sum / std::max(n, 1)), worst};
}

TEST(Localize, SimulatedRestsOfTheLargeRobotLieWithinTheirSigmas) {
  // GIVEN rests of the large robot and a calibration good to 2 mm
  const test::SimulatedRests r = test::simulated_rests(sim::Preset::kLarge, 12, 3);
  // WHEN each is localized from the cables alone, each from the last
  const Normalised z = localize_all(r, 12);
  // THEN the errors against the truth are of the size the covariance says
  EXPECT_LT(z.worst, 4.5);
  EXPECT_GT(z.rms, 0.4);
  EXPECT_LT(z.rms, 1.6);
}

TEST(Localize, SimulatedRestsOfTheSmallRobotLieWithinTheirSigmas) {
  const test::SimulatedRests r = test::simulated_rests(sim::Preset::kSmall, 12, 4, 1e-3, 1e-3);
  const Normalised z = localize_all(r, 12);
  EXPECT_LT(z.worst, 4.5);
  EXPECT_GT(z.rms, 0.4);
  EXPECT_LT(z.rms, 1.6);
}

TEST(Localize, TheMeasuredPoseSharpensThePoseFromTheCables) {
  const test::SimulatedRests r = test::simulated_rests(sim::Preset::kLarge, 2, 5);
  const Sample& rest = r.data.samples[0];
  LocalizeOptions with_pose;
  with_pose.use_measured_pose = true;
  const auto cables = localize_rest(r.data.nominal, r.calibration, rest, nominal_start(r.calibration, rest), {}, nullptr);
  const auto both = localize_rest(r.data.nominal, r.calibration, rest, nominal_start(r.calibration, rest), with_pose, nullptr);
  ASSERT_TRUE(cables && both);
  EXPECT_LT(both->position_sigma().maxCoeff(), cables->position_sigma().maxCoeff());
  EXPECT_LE(both->position_sigma().maxCoeff(), r.data.nominal.noise.position_m);
}

TEST(Localize, ARestTheCablesCannotHoldSaysWhy) {
  // GIVEN a rest whose cable 1 reads 3 m shorter than it can be
  const test::SimulatedRests r = test::simulated_rests(sim::Preset::kLarge, 1, 6);
  Sample rest = r.data.samples[0];
  rest.encoder_m[1] -= 3.0;
  // WHEN localized
  std::string why;
  const auto pose = localize_rest(r.data.nominal, r.calibration, rest, nominal_start(r.calibration, rest), {}, &why);
  // THEN there is no pose, and the reason names the equilibrium
  EXPECT_FALSE(pose);
  EXPECT_NE(why.find("equilibrium"), std::string::npos) << why;
}

TEST(Localize, ARigidCableCalibrationIsRefused) {
  const test::SimulatedRests r = test::simulated_rests(sim::Preset::kSmall, 1, 7);
  Calibration rigid = r.calibration;
  rigid.model = {"rigid"};
  std::string why;
  EXPECT_FALSE(localize_rest(r.data.nominal, rigid, r.data.samples[0], Pose{}, {}, &why));
  EXPECT_NE(why.find("rigid"), std::string::npos) << why;
}

TEST(PoseDifference, IsWorldFrameAndMatchesTheCovarianceConvention) {
  Pose a, b;
  b.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  a.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ())) * b.world_R_platform;
  a.position_world = Eigen::Vector3d(0.1, 0, 0);
  const Eigen::Matrix<double, 6, 1> d = pose_difference(a, b);
  EXPECT_NEAR(d(0), 0.1, 1e-12);
  EXPECT_NEAR(d(5), 0.01, 1e-12);
  EXPECT_NEAR(d(3), 0.0, 1e-12);
  Eigen::Matrix<double, 6, 6> cov = Eigen::Matrix<double, 6, 6>::Identity() * 1e-4;
  EXPECT_NEAR(mahalanobis_squared(d, cov), (0.01 + 1e-4) / 1e-4, 1e-6);
}

}  // namespace
}  // namespace cdpr
