#include "solver/platform_statics.h"

#include <gtest/gtest.h>

#include "test_robots.h"

namespace cdpr {
namespace {

StaticsInput input_at(const Robot& robot, const Eigen::Vector3d& position) {
  StaticsInput in;
  in.world_T_platform = test::tilted_pose(position);
  in.reference_force = Eigen::Vector2d(420.0, 160.0);
  in.anchor_world = test::anchors_of(robot);
  in.com_offset_platform = Eigen::Vector3d(0.01, 0.02, -0.03);
  return in;
}

TEST(PlatformStatics, ForcesBalanceTheWeight) {
  // GIVEN the large robot at a tilted pose and a reference force
  const Robot robot = test::large_robot();
  const StaticsInput in = input_at(robot, {110.0, 95.0, 15.0});
  std::array<CableStatics, kCableCount> cables;
  // WHEN the statics of Eq. (11) are solved
  ASSERT_EQ(solve_platform_statics(robot, in, false, cables), StaticsStatus::kOk);
  // THEN the cable forces and moments cancel the weight at the centre of mass
  const Eigen::Matrix3d R = in.world_T_platform.world_R_platform.toRotationMatrix();
  Eigen::Vector3d force = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d b = in.world_T_platform.transform(robot.winches[i].attachment_platform);
    Eigen::Vector3d towards_anchor = in.anchor_world[i] - b;
    towards_anchor.z() = 0.0;
    const Eigen::Vector3d f = cables[i].f_h * towards_anchor.normalized() + cables[i].f_v * Eigen::Vector3d::UnitZ();
    force += f;
    moment += (R * robot.winches[i].attachment_platform).cross(f);
  }
  const Eigen::Vector3d gravity(0, 0, -robot.platform_mass_kg * robot.gravity_mps2);
  const Eigen::Vector3d com = R * (robot.center_of_mass_platform + in.com_offset_platform);
  EXPECT_LT((force + gravity).norm(), 1e-8);
  EXPECT_LT((moment + com.cross(gravity)).norm(), 1e-8);
}

TEST(PlatformStatics, JacobianMatchesCentralDifferences) {
  const Robot robot = test::large_robot();
  const StaticsInput in = input_at(robot, {150.0, 60.0, 22.0});
  std::array<CableStatics, kCableCount> exact;
  ASSERT_EQ(solve_platform_statics(robot, in, true, exact), StaticsStatus::kOk);

  auto perturb = [&](int j, double h) {
    StaticsInput p = in;
    if (j < 3) {
      p.world_T_platform.position_world(j) += h;
    } else if (j < 6) {
      p.world_T_platform.world_R_platform =
          p.world_T_platform.world_R_platform * Eigen::Quaterniond(Eigen::AngleAxisd(h, Eigen::Vector3d::Unit(j - 3)));
    } else if (j < 8) {
      p.reference_force(j - 6) += h;
    } else if (j < kStaticsCom) {
      p.anchor_world[(j - kStaticsAnchor) / 3]((j - kStaticsAnchor) % 3) += h;
    } else {
      p.com_offset_platform(j - kStaticsCom) += h;
    }
    std::array<CableStatics, kCableCount> out;
    EXPECT_EQ(solve_platform_statics(robot, p, false, out), StaticsStatus::kOk);
    return out;
  };
  for (int j = 0; j < kStaticsParamDim; ++j) {
    const double h = (j >= 3 && j < 6) ? 1e-7 : 1e-5;
    const auto plus = perturb(j, h), minus = perturb(j, -h);
    for (int i = 0; i < kCableCount; ++i) {
      auto check = [&](const char* what, double analytic, double up, double down, double scale) {
        EXPECT_NEAR(analytic, (up - down) / (2 * h), 1e-6 * scale) << what << " cable " << i << " column " << j;
      };
      check("f_h", exact[i].d_f_h(j), plus[i].f_h, minus[i].f_h, 1e3);
      check("f_v", exact[i].d_f_v(j), plus[i].f_v, minus[i].f_v, 1e3);
      check("span", exact[i].d_span(j), plus[i].span, minus[i].span, 1.0);
      check("anchor_z", exact[i].d_anchor_z(j), plus[i].anchor_z, minus[i].anchor_z, 1.0);
      check("attachment_z", exact[i].d_attachment_z(j), plus[i].attachment_z, minus[i].attachment_z, 1.0);
    }
  }
}

TEST(PlatformStatics, VerticalCableIsReportedNotComputed) {
  // GIVEN a platform whose attachment sits exactly below its anchor
  Robot robot = test::large_robot();
  StaticsInput in = input_at(robot, {0.5, 0.5, 10.0});
  in.world_T_platform.world_R_platform = Eigen::Quaterniond::Identity();
  std::array<CableStatics, kCableCount> cables;
  // THEN the statics refuse instead of dividing by a zero span
  EXPECT_EQ(solve_platform_statics(robot, in, true, cables), StaticsStatus::kVerticalCable);
}

}  // namespace
}  // namespace cdpr
