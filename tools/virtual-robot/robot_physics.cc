#include "virtual-robot/robot_physics.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace cdpr::virtual_robot {
namespace {

// Where the platform would hang on straight chords of (1 - shrink) times
// the given lengths, orientation kept: the lowest pose at which three chords
// are exactly that long and the fourth is not longer (that cable sags more).
// The forward equilibrium (sim/equilibrium.h) starts by hanging each cable
// between its pulley and the attachment at the initial pose, which needs
// every cable longer than its chord there; this gives such a start close to
// the solution, even after a long move or with one cable much too long.
// Falls back to `pose` when no three chords meet.
Pose hanging_chord_pose(const sim::TrueRobot& robot, const std::array<double, kCableCount>& length_m, double shrink,
                        const Pose& pose) {
  const auto chord = [&](const Pose& p, int i) {
    return (p.transform(robot.robot.winches[i].attachment_platform) - robot.robot.winches[i].anchor_world).eval();
  };
  Pose best = pose;
  double best_z = std::numeric_limits<double>::infinity();
  for (int skipped = 0; skipped < kCableCount; ++skipped) {
    Pose p = pose;
    p.position_world.z() -= 5.0;  // start below: Newton then finds the lower (hanging) intersection
    bool converged = false;
    for (int iteration = 0; iteration < 30 && !converged; ++iteration) {
      Eigen::Matrix3d jacobian;
      Eigen::Vector3d residual;
      for (int row = 0, i = 0; i < kCableCount; ++i) {
        if (i == skipped) continue;
        const Eigen::Vector3d c = chord(p, i);
        residual(row) = c.norm() - (1.0 - shrink) * length_m[i];
        jacobian.row(row++) = c.normalized().transpose();
      }
      const Eigen::Vector3d step = jacobian.fullPivLu().solve(-residual);
      if (!step.allFinite()) break;
      p.position_world += step;
      converged = step.norm() < 1e-9;
    }
    const bool fourth_fits = chord(p, skipped).norm() <= (1.0 - shrink) * length_m[skipped];
    if (converged && fourth_fits && p.position_world.z() < best_z) {
      best = p;
      best_z = p.position_world.z();
    }
  }
  return best;
}

}  // namespace

Expected<RobotPhysics, std::string> RobotPhysics::at_rest(const sim::TrueRobot& robot,
                                                           const Eigen::Vector3d& start_world,
                                                           const PhysicsOptions& options) {
  sim::SolverOptions solver;
  solver.segments = options.segments;
  const sim::EquilibriumResult rest = sim::solve_equilibrium(robot, start_world, 0.0, solver);
  if (!rest) return Unexpected{"no rest pose at the start position: " + rest.error().message};
  return RobotPhysics(robot, *rest, options);
}

RobotPhysics::RobotPhysics(const sim::TrueRobot& robot, const sim::Equilibrium& rest, const PhysicsOptions& options)
    : robot_(robot), options_(options), rest_(rest), pose_(rest.world_T_platform) {
  for (int i = 0; i < kCableCount; ++i) {
    payout_m_[i] = rest.cables[i].payout_m + robot.encoder_offset_m[i];
    target_m_[i] = payout_m_[i];
    solved_payout_m_[i] = payout_m_[i];
    tension_n_[i] = rest.cables[i].tension_n;
  }
}

void RobotPhysics::advance(double dt_s) {
  if (dt_s <= 0.0) return;
  // Coordinated motion, as the robot's motion controller runs it: every
  // winch arrives at the same time (the farthest at the profile speed), so
  // the cable lengths pass through consistent sets and no cable goes slack
  // between two taut rest poses.
  double farthest_m = 0.0;
  for (int i = 0; i < kCableCount; ++i) farthest_m = std::max(farthest_m, std::abs(target_m_[i] - payout_m_[i]));
  const double fraction = farthest_m > 0.0 ? std::min(1.0, options_.winch_speed_mps * dt_s / farthest_m) : 1.0;
  for (int i = 0; i < kCableCount; ++i) {
    payout_m_[i] = fraction == 1.0 ? target_m_[i] : payout_m_[i] + fraction * (target_m_[i] - payout_m_[i]);
  }
  since_solve_s_ += dt_s;
  if (payout_m_ != solved_payout_m_ && since_solve_s_ >= options_.equilibrium_interval_s) solve_rest();

  // First-order approach to the rest state: exact for any step length.
  const double a = 1.0 - std::exp(-dt_s / options_.time_constant_s);
  pose_.position_world += a * (rest_.world_T_platform.position_world - pose_.position_world);
  pose_.world_R_platform = pose_.world_R_platform.slerp(a, rest_.world_T_platform.world_R_platform).normalized();
  for (int i = 0; i < kCableCount; ++i) tension_n_[i] += a * (rest_.cables[i].tension_n - tension_n_[i]);
}

void RobotPhysics::solve_rest() {
  since_solve_s_ = 0.0;
  std::array<double, kCableCount> unstretched_m{};
  for (int i = 0; i < kCableCount; ++i) unstretched_m[i] = payout_m_[i] - robot_.encoder_offset_m[i];
  sim::SolverOptions solver;
  solver.segments = options_.segments;
  sim::EquilibriumResult next = sim::solve_forward_equilibrium(robot_, unstretched_m, rest_.world_T_platform, solver);
  // Hauling cable in leaves some cables shorter than their chords at the old
  // rest pose; start from straight-cable poses then (tighter chords first).
  for (const double shrink : {1e-3, 3e-3, 1e-2}) {
    if (next) break;
    const Pose guess = hanging_chord_pose(robot_, unstretched_m, shrink, rest_.world_T_platform);
    next = sim::solve_forward_equilibrium(robot_, unstretched_m, guess, solver);
  }
  if (!next) {
    // Back off: a configuration without a taut rest pose (a cable slack on
    // the way) costs several failed solves, which would stall the real-time
    // loop if retried at the full rate.
    since_solve_s_ = -9.0 * options_.equilibrium_interval_s;
    ++failed_solves_;
    return;  // keep the last rest state; a later solve from the moved cables may succeed
  }
  rest_ = *next;
  solved_payout_m_ = payout_m_;
}

}  // namespace cdpr::virtual_robot
