// The virtual robot in operation (--operate): its own controller moves the
// platform by itself with rests between, the nodes publish as on a
// production bus, and the faults of operation_faults.h happen on time.

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "robot_time.h"
#include "virtual-robot/operation_faults.h"
#include "virtual-robot/virtual_robot.h"

namespace cdpr::integration {
namespace {

using virtual_robot::OperationFault;
using virtual_robot::parse_operation_fault;

TEST(OperationFaults, ParsesEachKindAndRefusesNonsense) {
  std::string why;
  const auto slip = parse_operation_fault("slip@300:cable=2,size=0.02", why);
  ASSERT_TRUE(slip) << why;
  EXPECT_EQ(slip->kind, OperationFault::Kind::kEncoderSlip);
  EXPECT_DOUBLE_EQ(slip->at_s, 300.0);
  EXPECT_EQ(slip->cable, 2);
  EXPECT_DOUBLE_EQ(slip->size_m, 0.02);
  const auto anchor = parse_operation_fault("anchor@10:cable=0,dx=0.05,dz=-0.01", why);
  ASSERT_TRUE(anchor) << why;
  EXPECT_TRUE(anchor->anchor_shift_m.isApprox(Eigen::Vector3d(0.05, 0.0, -0.01)));
  const auto payload = parse_operation_fault("payload@5:mass=3", why);
  ASSERT_TRUE(payload) << why;
  EXPECT_DOUBLE_EQ(payload->mass_kg, 3.0);
  EXPECT_TRUE(parse_operation_fault("creep@0:cable=3,rate=1e-4", why));

  for (const char* bad : {"slip:cable=1", "slide@3:cable=1", "slip@x:cable=1", "slip@3:cable=4,size=1",
                          "slip@3:size=1", "payload@3:mass=2,cable=1", "anchor@3:cable=1,dx=abc"}) {
    EXPECT_FALSE(parse_operation_fault(bad, why)) << bad;
    EXPECT_FALSE(why.empty()) << bad;
  }
}

TEST(VirtualRobotOperation, MovesByItselfRestsAndSlipsOneEncoderOnTime) {
  // GIVEN the large robot in operation, rests of 2-3 s, an encoder slip of
  // cable 1 by 2 cm 5 s into the run, and nobody on the bus
  char pattern[] = "/tmp/cdpr-operation-XXXXXX";
  const std::string dir = mkdtemp(pattern);
  virtual_robot::VirtualRobotOptions options;
  options.dir = dir;
  options.time_scale = 20.0;
  options.noise_scale = 0.0;
  options.operation.enabled = true;
  options.operation.rest_min_s = 2.0;
  options.operation.rest_max_s = 3.0;
  std::string why;
  options.faults.push_back(*parse_operation_fault("slip@5:cable=1,size=0.02", why));
  auto created = virtual_robot::VirtualRobot::create(options);
  ASSERT_TRUE(created) << created.error();
  virtual_robot::VirtualRobot& robot = **created;
  const double start_payout_m = robot.physics().payout_m(0);

  // WHEN it runs for three rests
  const RobotDeadline deadline(robot.clock(), std::chrono::seconds(120));
  while (robot.controller()->rests() < 3 && !deadline.passed()) robot.run_once(1'000);

  // THEN the controller moved the winches itself, every drive enabled, and
  // the slipped encoder reads 2 cm more than its cable's payout
  EXPECT_GE(robot.controller()->rests(), 3);
  EXPECT_GE(robot.controller()->moves(), 3);
  EXPECT_NE(robot.physics().payout_m(0), start_payout_m);
  for (int i = 0; i < kCableCount; ++i) EXPECT_TRUE(robot.nodes().drive(i).operation_enabled()) << i;
  EXPECT_EQ(robot.nodes().encoder(0).state(), virtual_robot::NodeState::kOperational);
  const double m_per_count = robot.options().nodes.encoder_m_per_count;
  robot.run_once(0);
  for (int i = 0; i < kCableCount; ++i) {
    const double reading_m = robot.nodes().encoder(i).position_value() * m_per_count;
    const double expected_m = robot.physics().payout_m(i) + (i == 1 ? 0.02 : 0.0);
    EXPECT_NEAR(reading_m, expected_m, 2e-3) << "cable " << i;  // within a TPDO of a move
  }
  // AND the winches hold still through the rest, the load cell says stable
  for (int k = 0; k < 20; ++k) robot.run_once(1'000);
  EXPECT_TRUE(robot.nodes().winches_still());
  EXPECT_LT(robot.physics().tension_unsettled_n(robot.nominal_robot().reference_cable), 1.0);
  EXPECT_EQ(robot.frames_from_clients(), 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace cdpr::integration
