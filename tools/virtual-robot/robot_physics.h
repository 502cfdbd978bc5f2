#pragma once
// The virtual robot's mechanics: four winches paying out cable in
// coordinated motion (all arrive together, the farthest at the profile
// speed), and a platform that follows the TRUE static equilibrium of the
// heavy cables (sim/equilibrium.h, solve_forward_equilibrium) as a lightly
// damped pendulum: after a move it sways about its rest pose with a period
// of several seconds on a large robot and comes to rest slowly, as a heavy
// platform on long cables does.
//
// Sway: every coordinate of the platform's deviation from the rest state
// (position, rotation vector relative to the rest orientation) obeys  e'' + 2 zeta w e' + w^2 e = 0  towards the latest rest
// state, integrated exactly for any step length. w comes from the cables'
// geometric stiffness at the rest pose, K = sum_i T_i / L_i (I - u_i u_i^T)
// (T_i tension, L_i and u_i chord length and direction): the horizontal
// stiffness k = (K_xx + K_yy) / 2 against the platform's mass plus a third
// of the free cables' mass, w = sqrt(k / m). For a single vertical cable
// this is the pendulum, w^2 = g / L. zeta is the damping ratio (air drag,
// cable and winch losses); sway_period_s > 0 replaces the geometric period.
//
// Units and conventions: payout [m] in encoder units, as the robot's
// encoders count it: payout_i = unstretched cable from the anchor point to
// the attachment + true encoder offset_i (docs/FORMATS.md enc_i). The
// equilibrium is recomputed whenever the cables have moved, at most every
// equilibrium_interval_s of simulated time; between solves the platform
// sways about the latest equilibrium; the cable tensions follow theirs with
// a first-order lag of tension_time_constant_s.
// Slack cables: when no rest pose with four taut cables is found for the
// commanded lengths (a cable paid out beyond what the others leave it, or
// far from the last rest pose), the platform hangs on three: the rest pose
// with one cable slack (sim/equilibrium.h: no tension, at least as long as
// its chord), the lowest-hanging one when several cables could be. Its
// tension settles to 0, so a load cell on it reads 0; its encoder counts the
// payout as ever; the sway's stiffness has no term from it. A heavy cable
// paid out a little hangs in a deeper loop that still pulls with part of its
// own weight: the taut solve finds that, and it is not slack.
// Time: simulated seconds passed to advance(); no clock read here.
// Not thread-safe.

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "sim/equilibrium.h"
#include "sim/true_robot.h"
#include "solver/nls/pose.h"
#include "src/formats/expected.h"

namespace cdpr::virtual_robot {

struct PhysicsOptions {
  double damping_ratio = 0.05;           // zeta of the sway (light damping)
  double sway_period_s = 0.0;            // > 0: sway period [s]; 0: from the cable geometry
  double tension_time_constant_s = 0.2;  // tensions' approach to their rest values [s]
  double winch_speed_mps = 2.0;          // profile velocity of every drive [m/s]
  double equilibrium_interval_s = 0.05;  // least simulated time between equilibrium solves [s]
  int segments = 200;                    // Simpson segments per cable (sim/cable_shooting.h)
};

class RobotPhysics {
 public:
  // The platform at rest at `start_world` with heading 0; fails when that
  // pose has no taut equilibrium.
  static Expected<RobotPhysics, std::string> at_rest(const sim::TrueRobot& robot, const Eigen::Vector3d& start_world,
                                                     const PhysicsOptions& options);

  // Drive i moves towards `payout_m` at the profile speed.
  void set_target(int winch, double payout_m) { target_m_[winch] = payout_m; }
  // Drive i stops where it is (halt, quick stop, power off).
  void stop(int winch) { target_m_[winch] = payout_m_[winch]; }
  // Winch i is at `payout_m` now: its drive runs its own profile (the
  // virtual robot's CiA 402 drives), the physics only follows.
  void set_payout(int winch, double payout_m) { payout_m_[winch] = target_m_[winch] = payout_m; }
  void advance(double dt_s);
  // The true robot changes under the running physics (an anchor moved, a
  // cable crept, a payload changed: operation_faults.h); the rest state is
  // solved again at the next advance().
  void change_robot(const sim::TrueRobot& robot);

  double payout_m(int winch) const { return payout_m_[winch]; }
  bool at_target(int winch) const { return payout_m_[winch] == target_m_[winch]; }
  const Pose& pose() const { return pose_; }
  // The platform's velocity [m/s, world] (the sway's, during and after a move).
  const Eigen::Vector3d& velocity_mps() const { return velocity_mps_; }
  // Where the platform is heading: the rest state of the latest solve.
  const sim::Equilibrium& rest() const { return rest_; }
  // The sway period at the latest rest pose [s].
  double sway_period_s() const;
  // Tension of cable i at its attachment [N] (what a load cell there reads).
  double tension_n(int cable) const { return tension_n_[cable]; }
  // Tension change still to come [N]: how far the cable is from its rest value.
  double tension_unsettled_n(int cable) const { return std::abs(rest_.cables[cable].tension_n - tension_n_[cable]); }
  // Equilibrium solves that failed (no rest pose found, taut or with one
  // cable slack); the platform stays at the last equilibrium then.
  int failed_solves() const { return failed_solves_; }
  // Equilibrium solves whose rest state has a slack cable.
  int slack_solves() const { return slack_solves_; }
  const sim::TrueRobot& robot() const { return robot_; }

 private:
  RobotPhysics(const sim::TrueRobot& robot, const sim::Equilibrium& rest, const PhysicsOptions& options);
  void solve_rest();
  // The rest state of `unstretched_m` with every cable taut, or with
  // `cable` slack; none when the solve fails.
  std::optional<sim::Equilibrium> solve_taut(const std::array<double, kCableCount>& unstretched_m) const;
  std::optional<sim::Equilibrium> solve_slack(const std::array<double, kCableCount>& unstretched_m, int cable) const;
  // w of the sway at rest_ [rad/s] (see above).
  double natural_frequency_radps() const;

  sim::TrueRobot robot_;
  PhysicsOptions options_;
  sim::Equilibrium rest_;  // where the platform is heading
  Pose pose_;
  Eigen::Vector3d velocity_mps_ = Eigen::Vector3d::Zero();       // [m/s, world]
  Eigen::Vector3d angular_velocity_radps_ = Eigen::Vector3d::Zero();  // of the rotation vector [rad/s]
  double omega_radps_ = 1.0;  // natural_frequency_radps() of rest_
  std::array<double, kCableCount> tension_n_{};
  std::array<double, kCableCount> payout_m_{};
  std::array<double, kCableCount> target_m_{};
  std::array<double, kCableCount> solved_payout_m_{};  // payouts of rest_
  double since_solve_s_ = 0.0;
  int failed_solves_ = 0;
  int slack_solves_ = 0;
};

}  // namespace cdpr::virtual_robot
