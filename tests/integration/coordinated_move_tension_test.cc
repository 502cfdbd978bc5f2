// Why the winches move together: the virtual robot's true physics driven
// through the first planned waypoints by its simulated CiA 402 drives
// (tools/virtual-robot/cia402_device.h, commanded over their CANopen
// interface as the daemon does), once with every drive on the same
// profile (each winch at its own pace) and once with
// the profiles scaled by |delta_i| / max |delta| (what the winch bank
// writes before every move). The measure is how far each cable's tension
// leaves the band between its rest tensions before and after the move.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "sim/dataset.h"
#include "sim/equilibrium.h"
#include "src/calibration/waypoint_planner.h"
#include "src/daemon/daemon_config.h"
#include "virtual-robot/cia402_device.h"
#include "virtual-robot/robot_physics.h"
#include "drive_commands.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

constexpr double kMPerCount = 1e-5;
constexpr int kMoves = 6;

using virtual_robot::Cia402Device;

struct Excursion {
  double outside_band_n = 0.0;  // largest distance of a tension outside [rest before, rest after]
  double min_n = 1e9, max_n = 0.0;
};

Excursion drive_through(const sim::TrueRobot& truth, const Eigen::Vector3d& start_world,
                        const std::vector<calibration::Waypoint>& waypoints, bool coordinated) {
  auto physics = virtual_robot::RobotPhysics::at_rest(truth, start_world, virtual_robot::PhysicsOptions{});
  EXPECT_TRUE(physics) << physics.error();
  std::vector<std::unique_ptr<Cia402Device>> drives;
  hal::TimeUs now_us = 0;
  std::vector<virtual_robot::BusFrame> sink;
  for (int i = 0; i < kCableCount; ++i) {
    drives.push_back(std::make_unique<Cia402Device>(i + 1, virtual_robot::DriveDefaults{}));
    Cia402Device& d = *drives.back();
    d.set_initial_position(physics->payout_m(i) / kMPerCount);
    enable_profile_position(d, now_us);
  }
  const auto step = [&](double dt_s) {
    now_us += static_cast<hal::TimeUs>(dt_s * 1e6);
    for (int i = 0; i < kCableCount; ++i) {
      drives[i]->advance(dt_s);
      drives[i]->poll(now_us, sink);
      physics->set_payout(i, drives[i]->position_counts() * kMPerCount);
    }
    physics->advance(dt_s);
    sink.clear();
  };
  Excursion e;
  for (int k = 0; k < kMoves; ++k) {
    const calibration::Waypoint& w = waypoints[k];
    std::array<double, kCableCount> before_n{};
    double longest_m = 0.0;
    for (int i = 0; i < kCableCount; ++i) {
      before_n[i] = physics->tension_n(i);
      longest_m = std::max(longest_m, std::abs(w.payout_m[i] - physics->payout_m(i)));
    }
    for (int i = 0; i < kCableCount; ++i) {
      Cia402Device& d = *drives[i];
      const double share = coordinated ? std::abs(w.payout_m[i] - physics->payout_m(i)) / longest_m : 1.0;
      start_move(d, static_cast<std::int32_t>(std::lround(w.payout_m[i] / kMPerCount)), share * kProfileVelocityMps / kMPerCount,
                 share * kProfileAccelerationMps2 / kMPerCount, now_us);
    }
    std::vector<std::array<double, kCableCount>> during;
    for (int n = 0; n < 200'000; ++n) {
      step(0.01);
      std::array<double, kCableCount> t{};
      for (int i = 0; i < kCableCount; ++i) t[i] = physics->tension_n(i);
      during.push_back(t);
      if (n == 5) {
        for (auto& d : drives) finish_move(*d, now_us);
      }
      bool still = n > 20;
      for (auto& d : drives) still = still && d->at_rest();
      if (still) break;
    }
    for (int n = 0; n < 300; ++n) step(0.01);  // settle: 15 time constants
    for (const auto& t : during) {
      for (int i = 0; i < kCableCount; ++i) {
        const double lo = std::min(before_n[i], physics->tension_n(i)), hi = std::max(before_n[i], physics->tension_n(i));
        e.outside_band_n = std::max({e.outside_band_n, lo - t[i], t[i] - hi});
        e.min_n = std::min(e.min_n, t[i]);
        e.max_n = std::max(e.max_n, t[i]);
      }
    }
  }
  return e;
}

TEST(CoordinatedMove, TensionsStayBetweenTheirRestValuesWhenTheWinchesMoveTogether) {
  // GIVEN the large virtual robot of the full calibration and the daemon's plan
  const auto planned = plan_acceptance_robot(calibration::WaypointSelection::kSpread);
  ASSERT_TRUE(planned);
  const calibration::WaypointPlan& plan = planned->plan;
  ASSERT_TRUE(plan.ok()) << plan.problem;
  const sim::TrueRobot& truth = planned->data.true_robot;
  const Eigen::Vector3d& start_world = planned->start_world;
  const calibration::PlannerOptions options = daemon::default_daemon_config().calibrator.planner;

  // WHEN it is driven through the first moves with each winch at its own pace, then together
  const Excursion independent = drive_through(truth, start_world, plan.waypoints, false);
  const Excursion together = drive_through(truth, start_world, plan.waypoints, true);
  std::printf("first %d moves, all cables: tension outside its rest band by up to %.1f N independently "
              "(range %.1f..%.1f N), %.1f N together (range %.1f..%.1f N); monitor limits %.0f..%.0f N\n",
              kMoves, independent.outside_band_n, independent.min_n, independent.max_n, together.outside_band_n,
              together.min_n, together.max_n, options.min_tension_n, options.max_tension_n);
  // THEN moving together keeps every tension within the monitor's limits and
  // leaves the rest band by much less (at most 0.7 times as far)
  EXPECT_LT(together.outside_band_n, 0.7 * independent.outside_band_n);
  EXPECT_LT(together.max_n - together.min_n, independent.max_n - independent.min_n);
  EXPECT_GT(together.min_n, options.min_tension_n);
  EXPECT_LT(together.max_n, options.max_tension_n);
}

}  // namespace
}  // namespace cdpr::integration
