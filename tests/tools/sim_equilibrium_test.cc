// The simulator's equilibrium: balance checked independently of the model's
// own equations, the forward problem inverting the inverse one, and the
// swivel pulley reducing to the plain anchor.
#include "sim/equilibrium.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "sim/cable_shooting.h"
#include "sim/presets.h"
#include "sim/swivel_pulley.h"

namespace cdpr::sim {
namespace {

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

struct PoseCase {
  Preset preset;
  Eigen::Vector3d position;
  double yaw;
};
const PoseCase kPoses[] = {
    {Preset::kLarge, {120.0, 110.0, 20.0}, 0.0},
    {Preset::kLarge, {100.0, 92.0, 14.0}, 0.004},
    {Preset::kSmall, {5.0, 2.0, 9.0}, -0.01},
};

TrueRobot robot_with(Preset preset, const HiddenEffects& effects) {
  TrueRobot robot = preset_spec(preset).robot;
  robot.effects = effects;
  return robot;
}

HiddenEffects all_physical_effects() {
  HiddenEffects e;
  e.axial_stiffness_n = 4.0e5;
  e.com_offset_platform = Eigen::Vector3d(0.03, -0.02, 0.05);
  e.density_error = 0.05;
  e.pulley_radius_m = 0.1;
  e.wind_force_world_n = Eigen::Vector3d(4.0, -2.0, 0.0);
  return e;
}

// Net force and moment on the platform from the reported state alone.
void net_wrench(const TrueRobot& robot, const Equilibrium& eq, Eigen::Vector3d& force, Eigen::Vector3d& moment) {
  const Eigen::Matrix3d R = eq.world_T_platform.world_R_platform.toRotationMatrix();
  const Eigen::Vector3d& p = eq.world_T_platform.position_world;
  const Eigen::Vector3d external = robot.effects.wind_force_world_n - robot.platform_weight_n() * kUp;
  force = external;
  moment = (R * robot.center_of_mass_platform()).cross(external);
  for (int i = 0; i < kCableCount; ++i) {
    const CableEquilibrium& c = eq.cables[i];
    const Eigen::Vector3d toward = robot.robot.winches[i].anchor_world - c.attachment_world;
    const Eigen::Vector3d horizontal = Eigen::Vector3d(toward.x(), toward.y(), 0.0).normalized();
    const Eigen::Vector3d f = c.h_n * horizontal + c.v_n * kUp;
    force += f;
    moment += (c.attachment_world - p).cross(f);
  }
}

TEST(SimEquilibrium, ForcesAndMomentsBalanceAndCablesReachTheirAnchors) {
  for (const bool with_effects : {false, true}) {
    for (const PoseCase& pc : kPoses) {
      // GIVEN a robot (with or without hidden physical effects) and a pose
      const TrueRobot robot = robot_with(pc.preset, with_effects ? all_physical_effects() : HiddenEffects{});
      // WHEN its equilibrium is solved
      const EquilibriumResult eq = solve_equilibrium(robot, pc.position, pc.yaw);
      ASSERT_TRUE(eq) << eq.error().message;
      // THEN the platform is where it was asked to be
      EXPECT_NEAR((eq->world_T_platform.position_world - pc.position).norm(), 0.0, 1e-12);
      EXPECT_NEAR(eq->yaw_rad, pc.yaw, 1e-15);
      // AND the forces and moments recomputed from the state balance
      Eigen::Vector3d force, moment;
      net_wrench(robot, *eq, force, moment);
      EXPECT_LT(force.norm(), 1e-6);
      EXPECT_LT(moment.norm(), 1e-6);
      // AND each cable, shot again from its attachment, ends on its pulley
      const CableProperties props{robot.cable_weight_per_length_npm(), robot.effects.axial_stiffness_n};
      for (int i = 0; i < kCableCount; ++i) {
        const CableEquilibrium& c = eq->cables[i];
        EXPECT_GT(c.h_n, 0.0);
        const CableShot shot = shoot_cable(props, c.h_n, c.v_n, c.free_unstretched_m, 4000);
        const PulleyDeparture dep =
            pulley_departure(robot.effects.pulley_radius_m, shot.end_tension_n.x(), shot.end_tension_n.y());
        const Eigen::Vector3d d = robot.robot.winches[i].anchor_world - c.attachment_world;
        EXPECT_NEAR(shot.end.x(), std::hypot(d.x(), d.y()) - dep.horizontal_m, 1e-7);
        EXPECT_NEAR(shot.end.y(), d.z() + dep.height_m, 1e-7);
        EXPECT_NEAR(c.arc_length_m, shot.stretched_length_m + dep.wrapped_arc_m, 1e-7);
      }
    }
  }
}

TEST(SimEquilibrium, ForwardProblemInvertsTheInverseProblem) {
  for (const PoseCase& pc : kPoses) {
    // GIVEN the payouts that hold the platform at a pose (elastic cables, pulleys)
    const TrueRobot robot = robot_with(pc.preset, all_physical_effects());
    const EquilibriumResult target = solve_equilibrium(robot, pc.position, pc.yaw);
    ASSERT_TRUE(target) << target.error().message;
    std::array<double, kCableCount> payout{};
    for (int i = 0; i < kCableCount; ++i) payout[i] = target->cables[i].payout_m;
    // WHEN the platform settles under those payouts from a pose nearby
    const double scale = pc.preset == Preset::kLarge ? 1.0 : 0.1;
    Pose initial;
    initial.position_world = pc.position + scale * Eigen::Vector3d(0.8, -0.5, 0.4);
    initial.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(pc.yaw + 0.01, kUp));
    const EquilibriumResult settled = solve_forward_equilibrium(robot, payout, initial);
    ASSERT_TRUE(settled) << settled.error().message;
    // THEN it comes to rest at the original pose with the original forces
    EXPECT_NEAR((settled->world_T_platform.position_world - pc.position).norm(), 0.0, 1e-7);
    EXPECT_NEAR(settled->world_T_platform.world_R_platform.angularDistance(target->world_T_platform.world_R_platform),
                0.0, 1e-9);
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_NEAR(settled->cables[i].tension_n, target->cables[i].tension_n, 1e-6 * target->cables[i].tension_n);
      EXPECT_NEAR(settled->cables[i].payout_m, payout[i], 1e-9);
    }
  }
}

TEST(SimEquilibrium, ZeroPulleyRadiusEqualsPlainAnchor) {
  // GIVEN the same robot without pulley and with a pulley of radius 0
  HiddenEffects zero_pulley;
  zero_pulley.pulley_radius_m = 0.0;
  const TrueRobot plain = robot_with(Preset::kLarge, {});
  const TrueRobot zero = robot_with(Preset::kLarge, zero_pulley);
  // WHEN both are solved at the same pose
  const EquilibriumResult a = solve_equilibrium(plain, kPoses[1].position, kPoses[1].yaw);
  const EquilibriumResult b = solve_equilibrium(zero, kPoses[1].position, kPoses[1].yaw);
  ASSERT_TRUE(a && b);
  // THEN nothing differs
  for (int i = 0; i < kCableCount; ++i) {
    EXPECT_EQ(a->cables[i].payout_m, b->cables[i].payout_m);
    EXPECT_EQ(a->cables[i].tension_n, b->cables[i].tension_n);
    EXPECT_EQ(b->cables[i].wrapped_arc_m, 0.0);
  }
}

TEST(SimEquilibrium, PulleyWrapsCableOverItsTop) {
  // GIVEN a pulley of radius 0.2 m
  HiddenEffects effects;
  effects.pulley_radius_m = 0.2;
  const TrueRobot robot = robot_with(Preset::kLarge, effects);
  // WHEN solved
  const EquilibriumResult eq = solve_equilibrium(robot, kPoses[0].position, kPoses[0].yaw);
  ASSERT_TRUE(eq);
  for (const CableEquilibrium& c : eq->cables) {
    // THEN the cable rises to the pulley, so it leaves past the top but
    // before the far side: the wrapped arc is between a quarter and half a turn
    EXPECT_GT(c.wrapped_arc_m, 0.2 * std::numbers::pi / 2.0);
    EXPECT_LT(c.wrapped_arc_m, 0.2 * std::numbers::pi);
    EXPECT_NEAR(c.arc_length_m, c.free_arc_m + c.wrapped_arc_m, 1e-12);
  }
}

TEST(SimEquilibrium, ElasticityStretchesCablesUnderTension) {
  HiddenEffects elastic;
  elastic.axial_stiffness_n = 2.0e5;
  // GIVEN the same pose with inextensible and elastic cables
  const EquilibriumResult rigid = solve_equilibrium(robot_with(Preset::kLarge, {}), kPoses[0].position, 0.0);
  const EquilibriumResult stretchy = solve_equilibrium(robot_with(Preset::kLarge, elastic), kPoses[0].position, 0.0);
  ASSERT_TRUE(rigid && stretchy);
  for (int i = 0; i < kCableCount; ++i) {
    // THEN the elastic cable's arc exceeds its unstretched length by about T l / EA
    const CableEquilibrium& c = stretchy->cables[i];
    const double stretch = c.arc_length_m - c.payout_m;
    EXPECT_NEAR(stretch, c.tension_n * c.payout_m / elastic.axial_stiffness_n, 0.2 * stretch);
    // AND the inextensible cable's arc is its unstretched length
    EXPECT_DOUBLE_EQ(rigid->cables[i].arc_length_m, rigid->cables[i].payout_m);
  }
}

// Inside the triangle of anchors 1, 2, 3 (the large robot's far half):
// those three cables can hold the platform there without cable 0.
const Eigen::Vector3d kFarHalf(150.0, 140.0, 17.0);

TEST(SimEquilibrium, SlackCableCarriesNothingAndThePlatformHangsOnTheOtherThree) {
  // GIVEN the payouts of a taut rest pose, cable 0 paid out 30 m beyond it
  const TrueRobot robot = robot_with(Preset::kLarge, {});
  const Eigen::Vector3d position = kFarHalf;
  const EquilibriumResult taut = solve_equilibrium(robot, position, 0.0);
  ASSERT_TRUE(taut) << taut.error().message;
  std::array<double, kCableCount> payout{};
  for (int i = 0; i < kCableCount; ++i) payout[i] = taut->cables[i].payout_m;
  payout[0] += 30.0;
  // WHEN the platform settles with cable 0 slack
  const EquilibriumResult slack =
      solve_forward_equilibrium(robot, payout, taut->world_T_platform, SolverOptions{}, SlackCables{true});
  ASSERT_TRUE(slack) << slack.error().message;
  // THEN cable 0 carries nothing and hangs no shorter than its chord
  const CableEquilibrium& c0 = slack->cables[0];
  EXPECT_TRUE(c0.slack);
  EXPECT_EQ(c0.tension_n, 0.0);
  EXPECT_EQ(c0.payout_m, payout[0]);
  EXPECT_LE((robot.robot.winches[0].anchor_world - c0.attachment_world).norm(), payout[0]);
  // AND the other three hold the platform alone: forces and moments balance, their lengths are the commanded ones
  Eigen::Vector3d force, moment;
  net_wrench(robot, *slack, force, moment);
  EXPECT_LT(force.norm(), 1e-6);
  EXPECT_LT(moment.norm(), 1e-6);
  for (int i = 1; i < kCableCount; ++i) {
    EXPECT_FALSE(slack->cables[i].slack);
    EXPECT_GT(slack->cables[i].tension_n, 0.0);
    EXPECT_NEAR(slack->cables[i].payout_m, payout[i], 1e-9);
  }
  // AND the platform moved away from cable 0's anchor
  EXPECT_GT((slack->world_T_platform.position_world - robot.robot.winches[0].anchor_world).norm(),
            (position - robot.robot.winches[0].anchor_world).norm() + 0.1);
}

TEST(SimEquilibrium, CableShorterThanItsChordCannotHangSlack) {
  // GIVEN the payouts of a taut rest pose, cable 0 hauled in by 1 m
  const TrueRobot robot = robot_with(Preset::kLarge, {});
  const EquilibriumResult taut = solve_equilibrium(robot, kFarHalf, 0.0);
  ASSERT_TRUE(taut) << taut.error().message;
  std::array<double, kCableCount> payout{};
  for (int i = 0; i < kCableCount; ++i) payout[i] = taut->cables[i].payout_m;
  payout[0] -= 1.0;
  // WHEN the rest pose with cable 0 slack is asked for
  const EquilibriumResult slack =
      solve_forward_equilibrium(robot, payout, taut->world_T_platform, SolverOptions{}, SlackCables{true});
  // THEN there is none: the other three would pull cable 0 taut
  ASSERT_FALSE(slack);
  EXPECT_EQ(slack.error().code, EquilibriumError::kSlackCable) << slack.error().message;
}

TEST(SimEquilibrium, InfeasiblePoseIsAnErrorValue) {
  // GIVEN a pose outside the anchors' footprint, where a cable would have to push
  const TrueRobot robot = robot_with(Preset::kLarge, {});
  const EquilibriumResult eq = solve_equilibrium(robot, Eigen::Vector3d(-30.0, 110.0, 20.0), 0.0);
  // THEN the solver says so instead of aborting
  ASSERT_FALSE(eq);
  EXPECT_FALSE(eq.error().message.empty());
}

}  // namespace
}  // namespace cdpr::sim
