// The stop of a moving robot, in robot time: the virtual robot (its true
// physics: the platform a lightly damped pendulum whose sway period comes
// from the cable geometry; its simulated CiA 402 drives) driven as the
// daemon drives it: profiles scaled per move (drivers/can/move_profile.h),
// all targets in one cycle, master heartbeat every 100 ms, the drives'
// consumer heartbeat 500 ms with 0x6007 = 3 and 0x605A = 6. Mid-move, at
// full speed, the master falls silent (kill -9: the drives quick-stop on
// 0x6085 on their own) or the operator aborts (halt: 0x6084). Measured: the
// drives' stop times, how far the payouts left the move's straight line,
// and the platform's largest distance from where it was at the kill or
// abort. Every figure comes from robot time and the physics, never from
// the wall clock.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "drive_commands.h"
#include "drivers/can/device_configuration.h"
#include "drivers/can/move_profile.h"
#include "sim/equilibrium.h"
#include "sim/presets.h"
#include "virtual-robot/virtual_robot.h"

namespace cdpr::integration {
namespace {

using drivers::can::DriveDescription;
using drivers::can::MoveProfileCounts;
using virtual_robot::Cia402Device;

constexpr double kStepS = 0.01;
constexpr hal::TimeUs kStepUs = 10'000;
constexpr int kMasterNodeId = 127;
constexpr hal::TimeUs kConsumerHeartbeatMs = 500;
// Robot time watched after the stop: the largest excursion comes half a
// sway period after it (large preset 14.8 s, small 8.9 s).
constexpr double kWatchS = 40.0;
// The keep-out distances docs/fieldbus.md states ("Stopping: cables and
// platform") for the default drive profile: the largest excursion measured
// (large: 14.8 m with the daemon's first move, 13.7 m here; small: 7.5 m
// here) plus 15 %, rounded up.
constexpr double kKeepOutLargeM = 17.0;
constexpr double kKeepOutSmallM = 9.0;

enum class Stop {
  kHeartbeatLossOneQuickStopRamp,  // the master dies; every drive on the same 0x6085 (before)
  kHeartbeatLoss,                  // the master dies; 0x6085 scaled per move like 0x6084
  kAbort,                          // the operator aborts: halt on the scaled 0x6084
};

struct StopFigures {
  double stop_after_s = 0.0;         // when the stop came, after the move began (worst_stop())
  double longest_cable_m = 0.0;      // the move's longest cable travel
  double sway_period_s = 0.0;        // the platform's at the start
  double platform_speed_mps = 0.0;   // when the master died or the abort came
  double stop_spread_s = 0.0;        // between the first and the last drive at rest
  double first_stop_s = 0.0;         // the first drive at rest, after the kill or abort
  double off_line_fraction = 0.0;    // largest distance of the payouts from the move's line / its length
  double cable_after_m = 0.0;        // the longest cable's travel after the kill or abort
  double platform_largest_m = 0.0;   // largest distance from where the platform was then
  double platform_largest_at_s = 0.0;
  double platform_end_m = 0.0;       // that distance at the end of the watch
  double from_braking_largest_m = 0.0;  // largest distance from where it was when the first drive began to brake
  virtual_robot::StopReport watched;  // the virtual robot's own report (from the braking on)
};

// The move of stop_mid_move(): from the middle of the preset's workspace
// towards its upper corner; `stop_after_s` after it began.
StopFigures stop_mid_move(sim::Preset preset, Stop stop, const DriveDescription& description, double stop_after_s) {
  StopFigures figures;
  char pattern[] = "/tmp/cdpr-stop-swing-XXXXXX";
  const std::string dir = mkdtemp(pattern);
  virtual_robot::VirtualRobotOptions options;
  options.preset = preset;
  options.noise_scale = 0.0;
  options.dir = dir;
  auto created = virtual_robot::VirtualRobot::create(options);
  EXPECT_TRUE(created) << created.error();
  if (!created) return figures;
  virtual_robot::VirtualRobot& robot = **created;
  const double m_per_count = options.nodes.drive_m_per_count;
  hal::TimeUs now_us = 0;
  std::vector<drivers::can::CanFrame> sink;
  bool master_alive = true;
  // One step of robot time; the drives' consumer heartbeat is checked in
  // poll(), after `observe` saw the step's motion.
  const auto step = [&](const auto& observe) {
    now_us += kStepUs;
    if (master_alive && now_us % 100'000 == 0) {
      for (int i = 0; i < kCableCount; ++i) {
        robot.nodes().drive(i).on_frame(virtual_robot::BusFrame{0x700 + kMasterNodeId, 1, {0x05}}, now_us);
      }
    }
    robot.advance(kStepS);
    observe();
    sink.clear();
    robot.nodes().poll(now_us, sink);
  };
  for (int i = 0; i < kCableCount; ++i) {
    Cia402Device& d = robot.nodes().drive(i);
    enable_profile_position(d, now_us);
    sdo_write(d, 0x605A, static_cast<std::uint32_t>(description.quick_stop_option), 2, now_us);
    sdo_write(d, 0x6007, static_cast<std::uint32_t>(description.abort_connection_option), 2, now_us);
    sdo_write(d, 0x1016, static_cast<std::uint32_t>(kMasterNodeId << 16 | kConsumerHeartbeatMs), 4, now_us, 1);
  }
  // A long move at full speed: the platform from the middle of the workspace
  // towards its upper corner, the payouts of the true equilibrium there.
  const sim::PresetSpec spec = sim::preset_spec(preset);
  const sim::TrueRobot& truth = robot.physics().robot();
  const Eigen::Vector3d start_world = virtual_robot::start_position_world(preset);
  const Eigen::Vector3d goal_world = start_world + 0.35 * (spec.workspace_max - spec.workspace_min);
  const sim::EquilibriumResult goal = sim::solve_equilibrium(truth, goal_world, 0.0);
  EXPECT_TRUE(goal);
  if (!goal) return figures;
  std::array<double, kCableCount> start_m{}, delta_m{};
  double longest_m = 0.0, length_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) {
    start_m[i] = robot.physics().payout_m(i);
    delta_m[i] = goal->cables[i].payout_m + truth.encoder_offset_m[i] - start_m[i];
    longest_m = std::max(longest_m, std::abs(delta_m[i]));
    length_m += delta_m[i] * delta_m[i];
  }
  length_m = std::sqrt(length_m);
  for (int i = 0; i < kCableCount; ++i) {
    Cia402Device& d = robot.nodes().drive(i);
    MoveProfileCounts p = drivers::can::scaled_move_profile(description, std::abs(delta_m[i]) / longest_m, m_per_count);
    if (stop == Stop::kHeartbeatLossOneQuickStopRamp) {
      p.quick_stop_deceleration = drivers::can::scaled_move_profile(description, 1.0, m_per_count).quick_stop_deceleration;
    }
    sdo_write(d, 0x6081, p.velocity, 4, now_us);
    sdo_write(d, 0x6083, p.acceleration, 4, now_us);
    sdo_write(d, 0x6084, p.deceleration, 4, now_us);
    sdo_write(d, 0x6085, p.quick_stop_deceleration, 4, now_us);
    sdo_write(d, 0x607A, static_cast<std::uint32_t>(std::lround((start_m[i] + delta_m[i]) / m_per_count)), 4, now_us);
    controlword(d, 0x3F, now_us);
  }
  figures.longest_cable_m = longest_m;
  figures.sway_period_s = robot.physics().sway_period_s();
  const int cruise_steps = static_cast<int>(std::lround(stop_after_s / kStepS));
  for (int n = 0; n < cruise_steps; ++n) {
    step([] {});
    if (n == 2) {
      for (int i = 0; i < kCableCount; ++i) controlword(robot.nodes().drive(i), 0x2F, now_us);
    }
  }
  const Eigen::Vector3d stop_world = robot.physics().pose().position_world;
  figures.platform_speed_mps = robot.physics().velocity_mps().norm();
  std::array<double, kCableCount> at_stop_m{};
  for (int i = 0; i < kCableCount; ++i) at_stop_m[i] = robot.physics().payout_m(i);
  if (robot.nodes().axes_still()) ADD_FAILURE() << "the move ended before the stop at " << stop_after_s << " s";
  if (stop == Stop::kAbort) {
    for (int i = 0; i < kCableCount; ++i) controlword(robot.nodes().drive(i), 0x2F | 0x100, now_us);
  } else {
    master_alive = false;
  }
  std::array<double, kCableCount> stopped_s{-1.0, -1.0, -1.0, -1.0};
  std::optional<Eigen::Vector3d> braking_world;
  const auto observe = [&](double t_s) {
    double along_m = 0.0;
    std::array<double, kCableCount> moved_m{};
    for (int i = 0; i < kCableCount; ++i) {
      moved_m[i] = robot.physics().payout_m(i) - start_m[i];
      along_m += moved_m[i] * delta_m[i] / length_m;
      if (stopped_s[i] < 0.0 && robot.nodes().drive(i).axis_still()) stopped_s[i] = t_s;
      figures.cable_after_m = std::max(figures.cable_after_m, std::abs(robot.physics().payout_m(i) - at_stop_m[i]));
    }
    double off_m = 0.0;
    for (int i = 0; i < kCableCount; ++i) off_m += std::pow(moved_m[i] - along_m * delta_m[i] / length_m, 2);
    figures.off_line_fraction = std::max(figures.off_line_fraction, std::sqrt(off_m) / length_m);
    const double from_stop_m = (robot.physics().pose().position_world - stop_world).norm();
    if (from_stop_m > figures.platform_largest_m) {
      figures.platform_largest_m = from_stop_m;
      figures.platform_largest_at_s = t_s;
    }
    figures.platform_end_m = from_stop_m;
    if (!braking_world && robot.nodes().any_drive_braking()) braking_world = robot.physics().pose().position_world;
    if (braking_world) {
      figures.from_braking_largest_m =
          std::max(figures.from_braking_largest_m, (robot.physics().pose().position_world - *braking_world).norm());
    }
  };
  for (int n = 1; n * kStepS <= kWatchS; ++n) {
    step([&] { observe(n * kStepS); });
  }
  const auto [first, last] = std::minmax_element(stopped_s.begin(), stopped_s.end());
  EXPECT_GT(*first, 0.0) << "a drive never stopped";
  figures.first_stop_s = *first;
  figures.stop_spread_s = *last - *first;
  if (robot.stops().latest()) figures.watched = *robot.stops().latest();
  std::filesystem::remove_all(dir);
  return figures;
}

const char* name_of(Stop stop) {
  switch (stop) {
    case Stop::kHeartbeatLossOneQuickStopRamp: return "kill -9, one 0x6085";
    case Stop::kHeartbeatLoss: return "kill -9, 0x6085 per move";
    case Stop::kAbort: return "abort (halt)";
  }
  return "";
}

void print(sim::Preset preset, Stop stop, const StopFigures& f) {
  std::printf("%s preset (sway period %.1f s), %s: platform at %.2f m/s; drives at rest %.2f s after, %.3f s apart, "
              "payouts %.4f of the move off its line, longest cable %.2f m further; platform up to %.2f m away "
              "(%.1f s after), %.2f m after %.0f s; the virtual robot's report: up to %.2f m from where the braking "
              "began\n",
              preset == sim::Preset::kLarge ? "large" : "small", f.sway_period_s, name_of(stop), f.platform_speed_mps,
              f.first_stop_s, f.stop_spread_s, f.off_line_fraction, f.cable_after_m, f.platform_largest_m,
              f.platform_largest_at_s, f.platform_end_m, kWatchS, f.watched.largest_m);
}

// The largest of stop_mid_move()'s excursions over stops every second of
// the move, from 0.5 s after its start to 0.5 s before its end, or to one
// sway period after its acceleration: the platform's swing relative to its
// moving rest pose is excited by the acceleration and decays after it, so
// later stops swing it less.
StopFigures worst_stop(sim::Preset preset, Stop stop, const DriveDescription& description) {
  const StopFigures first = stop_mid_move(preset, stop, description, 0.5);
  const double accelerating_s = description.profile_velocity_mps / description.profile_acceleration_mps2;
  const double move_s = first.longest_cable_m / description.profile_velocity_mps + accelerating_s;
  const double last_s = std::min(move_s - 0.5, accelerating_s + first.sway_period_s + 1.0);
  StopFigures worst = first;
  double worst_at_s = 0.5;
  for (double at_s = 1.5; at_s < last_s; at_s += 1.0) {
    const StopFigures f = stop_mid_move(preset, stop, description, at_s);
    if (f.platform_largest_m > worst.platform_largest_m) {
      worst = f;
      worst_at_s = at_s;
    }
  }
  worst.stop_after_s = worst_at_s;
  std::printf("worst over stops every 1 s of a %.1f s move (%.1f s into it): ", move_s, worst_at_s);
  print(preset, stop, worst);
  return worst;
}

TEST(StopSwing, HeartbeatLossStopsEveryDriveTogetherOnTheMovesLine) {
  // GIVEN the large virtual robot on a long move, at full speed for 1 s, the daemon's default drive profile
  const DriveDescription description;
  const double at_s = 1.0 + description.profile_velocity_mps / description.profile_acceleration_mps2;
  // WHEN the master dies, with one quick-stop ramp for all (before) and with it scaled per move
  const StopFigures one = stop_mid_move(sim::Preset::kLarge, Stop::kHeartbeatLossOneQuickStopRamp, description, at_s);
  const StopFigures scaled = stop_mid_move(sim::Preset::kLarge, Stop::kHeartbeatLoss, description, at_s);
  print(sim::Preset::kLarge, Stop::kHeartbeatLossOneQuickStopRamp, one);
  print(sim::Preset::kLarge, Stop::kHeartbeatLoss, scaled);
  // THEN scaled, every drive is at rest within one step of the others, and the
  // payouts stay within 0.1 % of the move's length of its line
  EXPECT_LE(scaled.stop_spread_s, kStepS + 1e-9);
  EXPECT_LT(scaled.off_line_fraction, 1e-3);
  // AND they stop after the consumer heartbeat time plus the braking
  const double braking_s = description.profile_velocity_mps / description.quick_stop_deceleration_mps2;
  EXPECT_LT(scaled.first_stop_s, kConsumerHeartbeatMs * 1e-3 + braking_s + 0.05);
  // AND with one ramp for all they did not (the defect this guards against)
  EXPECT_GT(one.stop_spread_s, 0.2);
  EXPECT_GT(one.off_line_fraction, 5 * scaled.off_line_fraction);
}

TEST(StopSwing, PlatformExcursionAfterAStopIsBoundedAndReported) {
  const DriveDescription description;
  for (const sim::Preset preset : {sim::Preset::kLarge, sim::Preset::kSmall}) {
    for (const Stop stop : {Stop::kHeartbeatLoss, Stop::kAbort}) {
      // GIVEN a virtual robot on a long move WHEN the master dies or the operator aborts, at any second of it
      const StopFigures f = worst_stop(preset, stop, description);
      // THEN the virtual robot reported the platform's largest excursion
      // from where the braking began, as the test saw it
      EXPECT_GT(f.watched.began_s, 0.0);
      EXPECT_NEAR(f.watched.largest_m, f.from_braking_largest_m, 1e-6);
      EXPECT_GE(f.watched.cables_stopped_s, f.watched.began_s);
      // AND the platform stayed within the keep-out distance docs/fieldbus.md states
      const double keep_out_m = preset == sim::Preset::kLarge ? kKeepOutLargeM : kKeepOutSmallM;
      EXPECT_LT(f.platform_largest_m, keep_out_m);
      if (stop == Stop::kHeartbeatLoss) {  // the same stop with one 0x6085 for all (before), for the docs
        print(preset, Stop::kHeartbeatLossOneQuickStopRamp,
              stop_mid_move(preset, Stop::kHeartbeatLossOneQuickStopRamp, description, f.stop_after_s));
      }
    }
  }
}

TEST(StopSwing, SlowerMovesSwingLess) {
  // GIVEN the large virtual robot moving at a quarter of the default profile velocity (0.5 m/s)
  DriveDescription slow;
  slow.profile_velocity_mps = 0.5;
  // WHEN the master dies or the operator aborts, at any second of the move
  const StopFigures killed = worst_stop(sim::Preset::kLarge, Stop::kHeartbeatLoss, slow);
  const StopFigures aborted = worst_stop(sim::Preset::kLarge, Stop::kAbort, slow);
  // THEN the platform swings about a quarter as far as at 2 m/s (13.7 m):
  // the swing comes from the platform trailing its moving rest pose, which
  // grows with the speed (docs/fieldbus.md "Stopping: cables and platform")
  EXPECT_LT(killed.platform_largest_m, 3.5);
  EXPECT_LT(aborted.platform_largest_m, 3.5);
}

}  // namespace
}  // namespace cdpr::integration
