#include "sim/rest_sequence.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cdpr::sim {
namespace {

RestSequence rests_with(InjectedFault fault, int count) {
  RestSequenceConfig config;
  config.robot.preset = Preset::kSmall;
  config.robot.seed = 4;
  config.robot.noise_scale = 0.0;
  config.robot.segments = 200;
  config.rest_count = count;
  config.fault = fault;
  auto sequence = simulate_rest_sequence(config);
  EXPECT_TRUE(sequence.has_value()) << (sequence ? "" : sequence.error());
  return *sequence;
}

InjectedFault fault(FaultKind kind, int cable, double size, int from_rest) {
  InjectedFault f;
  f.kind = kind;
  f.cable = cable;
  f.size = size;
  f.from_rest = from_rest;
  return f;
}

TEST(SimRestSequence, AnEncoderSlipChangesThatEncoderAloneFromItsRestOn) {
  // GIVEN the same robot and rests with and without a 2 cm slip of cable 1 from rest 3
  const InjectedFault slip = fault(FaultKind::kEncoderSlip, 1, 0.02, 3);
  const RestSequence clean = rests_with({}, 6), slipped = rests_with(slip, 6);
  // THEN the rests lie at the same poses and only encoder 1 reads 2 cm more, from rest 3 on
  for (int k = 0; k < 6; ++k) {
    EXPECT_TRUE(clean.rests[k].position_world.isApprox(slipped.rests[k].position_world));
    for (int i = 0; i < kCableCount; ++i) {
      const double expected = (i == 1 && k >= 3) ? 0.02 : 0.0;
      EXPECT_NEAR(slipped.rests[k].encoder_m[i] - clean.rests[k].encoder_m[i], expected, 1e-12) << k << " " << i;
    }
  }
}

TEST(SimRestSequence, AMovedAnchorAndAPayloadChangeTheTrueRobotFromTheirRest) {
  const InjectedFault anchor = fault(FaultKind::kAnchorMoved, 2, 0.05, 2);
  const RestSequence moved = rests_with(anchor, 3);
  EXPECT_NEAR(moved.anchor_shift_world.norm(), 0.05, 1e-12);
  const TrueRobot before = robot_at_rest(moved, anchor, 1), after = robot_at_rest(moved, anchor, 2);
  EXPECT_TRUE((after.robot.winches[2].anchor_world - before.robot.winches[2].anchor_world)
                  .isApprox(moved.anchor_shift_world));

  const InjectedFault payload = fault(FaultKind::kPayloadChange, 0, 0.4, 1);
  const TrueRobot heavier = robot_at_rest(moved, payload, 1);
  EXPECT_NEAR(heavier.robot.platform_mass_kg - moved.true_robot.robot.platform_mass_kg, 0.4, 1e-12);
}

TEST(SimRestSequence, AnAnchorMovesInTheChosenDirectionWhenGivenOne) {
  InjectedFault up = fault(FaultKind::kAnchorMoved, 1, 0.05, 1);
  up.direction_world = Eigen::Vector3d(0.0, 0.0, 2.0);
  EXPECT_TRUE(rests_with(up, 2).anchor_shift_world.isApprox(Eigen::Vector3d(0.0, 0.0, 0.05)));
}

TEST(SimRestSequence, FaultNamesParse) {
  EXPECT_EQ(parse_fault_kind("slip"), FaultKind::kEncoderSlip);
  EXPECT_EQ(parse_fault_kind("creep"), FaultKind::kCableCreep);
  EXPECT_FALSE(parse_fault_kind("wind"));
}

}  // namespace
}  // namespace cdpr::sim
