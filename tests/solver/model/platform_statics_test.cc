#include "solver/model/platform_statics.h"

#include <cmath>

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

TEST(PlatformStatics, ReferenceForceMapReproducesTheStaticsAndTheirTurn) {
  // GIVEN the statics at a tilted pose as an affine map of the reference force
  const Robot robot = test::large_robot();
  const StaticsInput in = input_at(robot, {150.0, 60.0, 22.0});
  ReferenceForceMap map;
  ASSERT_EQ(reference_force_map(robot, in, map), StaticsStatus::kOk);
  // THEN at any reference force it gives the forces of the full solve
  auto solve_at = [&](const StaticsInput& at) {
    std::array<CableStatics, kCableCount> cables;
    EXPECT_EQ(solve_platform_statics(robot, at, false, cables), StaticsStatus::kOk);
    return cables;
  };
  for (const Eigen::Vector2d& f : {Eigen::Vector2d(420.0, 160.0), Eigen::Vector2d(900.0, -50.0)}) {
    StaticsInput at = in;
    at.reference_force = f;
    const auto cables = solve_at(at);
    for (int i = 0; i < kCableCount; ++i) {
      const Eigen::Vector2d mapped = map.offset[i] + map.gain[i] * f;
      EXPECT_NEAR(mapped.x(), cables[i].f_h, 1e-9 * std::abs(cables[i].f_h) + 1e-9) << i;
      EXPECT_NEAR(mapped.y(), cables[i].f_v, 1e-9 * std::abs(cables[i].f_v) + 1e-9) << i;
      EXPECT_DOUBLE_EQ(map.span[i], cables[i].span);
      EXPECT_DOUBLE_EQ(map.attachment_z[i], cables[i].attachment_z);
    }
  }
  // AND its yaw derivatives match central differences of a turn about the world vertical
  const double h = 1e-6;
  auto turned = [&](double yaw) {
    StaticsInput at = in;
    at.world_T_platform.world_R_platform =
        Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) * in.world_T_platform.world_R_platform;
    return solve_at(at);
  };
  const auto up = turned(h), down = turned(-h);
  const std::array<Eigen::Vector2d, kCableCount> d_force = map.d_force_d_yaw(in.reference_force);
  for (int i = 0; i < kCableCount; ++i) {
    const double d_f_h = (up[i].f_h - down[i].f_h) / (2 * h), d_f_v = (up[i].f_v - down[i].f_v) / (2 * h);
    EXPECT_NEAR(d_force[i].x(), d_f_h, 1e-5 * (1.0 + std::abs(d_f_h))) << i;
    EXPECT_NEAR(d_force[i].y(), d_f_v, 1e-5 * (1.0 + std::abs(d_f_v))) << i;
    EXPECT_NEAR(map.d_span_d_yaw[i], (up[i].span - down[i].span) / (2 * h), 1e-6) << i;
    EXPECT_NEAR(up[i].attachment_z, down[i].attachment_z, 1e-9) << i;
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
