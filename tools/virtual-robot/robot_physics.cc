#include "virtual-robot/robot_physics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

namespace cdpr::virtual_robot {
namespace {

// One step of dt of  e'' + 2 zeta w e' + w^2 e = 0  (0 <= zeta < 1), exact:
// the deviation e and its rate v of any number of coordinates at once.
template <typename Deviation>
void sway_step(double omega, double zeta, double dt, Deviation& e, Deviation& v) {
  const double decay = zeta * omega;
  const double omega_d = omega * std::sqrt(1.0 - zeta * zeta);
  const double c = std::cos(omega_d * dt), s = std::sin(omega_d * dt), damp = std::exp(-decay * dt);
  const Deviation e0 = e;
  e = damp * (c * e0 + (s / omega_d) * (v + decay * e0));
  v = damp * (c * v - (s / omega_d) * (omega * omega * e0 + decay * v));
}

// Where the platform would hang on straight chords of (1 - shrink) times
// the given lengths, orientation kept: the lowest pose at which three chords
// are exactly that long and the fourth is not longer (that cable sags more).
// The forward equilibrium (sim/equilibrium.h) starts by hanging each cable
// between its pulley and the attachment at the initial pose, which needs
// every cable longer than its chord there; this gives such a start close to
// the solution, even after a long move or with one cable much too long.
// The pose, orientation kept, at which the chords of all cables but
// `skipped` are exactly (1 - shrink) times their lengths and that of
// `skipped` is not longer (that cable sags more, or hangs slack); none when
// no such pose is found.
std::optional<Pose> three_chord_pose(const sim::TrueRobot& robot, const std::array<double, kCableCount>& length_m,
                                     double shrink, const Pose& pose, int skipped) {
  const auto chord = [&](const Pose& p, int i) {
    return (p.transform(robot.robot.winches[i].attachment_platform) - robot.robot.winches[i].anchor_world).eval();
  };
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
  if (!converged || chord(p, skipped).norm() > (1.0 - shrink) * length_m[skipped]) return std::nullopt;
  return p;
}

// The lowest three_chord_pose() over the skipped cable; falls back to
// `pose` when no three chords meet.
Pose hanging_chord_pose(const sim::TrueRobot& robot, const std::array<double, kCableCount>& length_m, double shrink,
                        const Pose& pose) {
  Pose best = pose;
  double best_z = std::numeric_limits<double>::infinity();
  for (int skipped = 0; skipped < kCableCount; ++skipped) {
    const std::optional<Pose> p = three_chord_pose(robot, length_m, shrink, pose, skipped);
    if (p && p->position_world.z() < best_z) {
      best = *p;
      best_z = p->position_world.z();
    }
  }
  return best;
}

sim::SlackCables only(int cable) {
  sim::SlackCables slack{};
  slack[cable] = true;
  return slack;
}

int slack_cable_of(const sim::Equilibrium& rest) {
  for (int i = 0; i < kCableCount; ++i) {
    if (rest.cables[i].slack) return i;
  }
  return -1;
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
  omega_radps_ = natural_frequency_radps();
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

  // The sway about the rest state, the rest state held for this step.
  const double zeta = std::clamp(options_.damping_ratio, 0.0, 0.99);
  Eigen::Vector3d e = pose_.position_world - rest_.world_T_platform.position_world;
  sway_step(omega_radps_, zeta, dt_s, e, velocity_mps_);
  pose_.position_world = rest_.world_T_platform.position_world + e;
  const Eigen::Quaterniond& rest_r = rest_.world_T_platform.world_R_platform;
  Eigen::Vector3d r = so3_log(rest_r.conjugate() * pose_.world_R_platform);
  sway_step(omega_radps_, zeta, dt_s, r, angular_velocity_radps_);
  pose_.world_R_platform = (rest_r * so3_exp(r)).normalized();
  // Tensions approach their rest values with a first-order lag: an
  // oscillator of its own would swing a cable's tension below zero.
  const double a = 1.0 - std::exp(-dt_s / options_.tension_time_constant_s);
  for (int i = 0; i < kCableCount; ++i) tension_n_[i] += a * (rest_.cables[i].tension_n - tension_n_[i]);
}

void RobotPhysics::change_robot(const sim::TrueRobot& robot) {
  robot_ = robot;
  solved_payout_m_.fill(std::numeric_limits<double>::quiet_NaN());  // differs from any payout: solved again
  since_solve_s_ = options_.equilibrium_interval_s;
}

double RobotPhysics::natural_frequency_radps() const {
  if (options_.sway_period_s > 0.0) return 2.0 * std::numbers::pi / options_.sway_period_s;
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();
  double mass_kg = robot_.robot.platform_mass_kg;
  for (int i = 0; i < kCableCount; ++i) {
    const sim::CableEquilibrium& cable = rest_.cables[i];
    const Eigen::Vector3d chord = robot_.robot.winches[i].anchor_world - cable.attachment_world;
    const double length = chord.norm();
    if (!(length > 0.0)) continue;
    const Eigen::Vector3d u = chord / length;
    stiffness += cable.tension_n / length * (Eigen::Matrix3d::Identity() - u * u.transpose());
    mass_kg += robot_.robot.cable_linear_density_kgpm * cable.free_arc_m / 3.0;
  }
  const double horizontal = 0.5 * (stiffness(0, 0) + stiffness(1, 1));
  return horizontal > 0.0 && mass_kg > 0.0 ? std::sqrt(horizontal / mass_kg) : 1.0;
}

double RobotPhysics::sway_period_s() const { return 2.0 * std::numbers::pi / omega_radps_; }

std::optional<sim::Equilibrium> RobotPhysics::solve_taut(const std::array<double, kCableCount>& unstretched_m) const {
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
  if (!next) return std::nullopt;
  return *next;
}

std::optional<sim::Equilibrium> RobotPhysics::solve_slack(const std::array<double, kCableCount>& unstretched_m,
                                                          int cable) const {
  sim::SolverOptions solver;
  solver.segments = options_.segments;
  // From the last rest pose while that cable was already slack, else from
  // where the other three hang on straight chords.
  sim::EquilibriumResult next = Unexpected{sim::EquilibriumFailure{}};
  if (slack_cable_of(rest_) == cable) {
    next = sim::solve_forward_equilibrium(robot_, unstretched_m, rest_.world_T_platform, solver, only(cable));
  }
  if (!next) {
    const std::optional<Pose> guess = three_chord_pose(robot_, unstretched_m, 1e-3, rest_.world_T_platform, cable);
    if (!guess) return std::nullopt;  // that cable is too short to hang slack
    next = sim::solve_forward_equilibrium(robot_, unstretched_m, *guess, solver, only(cable));
  }
  if (!next) return std::nullopt;
  return *next;
}

void RobotPhysics::solve_rest() {
  since_solve_s_ = 0.0;
  std::array<double, kCableCount> unstretched_m{};
  for (int i = 0; i < kCableCount; ++i) unstretched_m[i] = payout_m_[i] - robot_.encoder_offset_m[i];
  // A cable slack at the last rest most likely still is; else taut; else the
  // lowest-hanging of the poses with one cable slack (least potential energy).
  const int was_slack = slack_cable_of(rest_);
  std::optional<sim::Equilibrium> next;
  if (was_slack >= 0) next = solve_slack(unstretched_m, was_slack);
  if (!next) next = solve_taut(unstretched_m);
  if (!next) {
    const auto com_height = [&](const sim::Equilibrium& rest) {
      return rest.world_T_platform.transform(robot_.center_of_mass_platform()).z();
    };
    for (int cable = 0; cable < kCableCount; ++cable) {
      if (cable == was_slack) continue;
      const std::optional<sim::Equilibrium> candidate = solve_slack(unstretched_m, cable);
      if (candidate && (!next || com_height(*candidate) < com_height(*next))) next = candidate;
    }
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
  if (slack_cable_of(rest_) >= 0) ++slack_solves_;
  solved_payout_m_ = payout_m_;
  omega_radps_ = natural_frequency_radps();
}

}  // namespace cdpr::virtual_robot
