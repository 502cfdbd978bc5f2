#include "sim/equilibrium.h"

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "sim/equilibrium_model.h"
#include "sim/initial_state.h"

namespace cdpr::sim {
namespace {

namespace si = state_index;

// The unknowns of each problem: all Newton unknowns, and per cable the three
// that the projection solves for (see newton()).
struct Unknowns {
  std::vector<int> all;
  std::array<std::array<int, 3>, kCableCount> per_cable;
};

Unknowns inverse_unknowns() {
  Unknowns u;
  u.all = {si::kRoll, si::kPitch};
  for (int i = 0; i < kCableCount; ++i) {
    for (int j : {si::h(i), si::v(i), si::free_length(i), si::payout(i)}) u.all.push_back(j);
    u.per_cable[i] = {si::v(i), si::free_length(i), si::payout(i)};
  }
  return u;
}

Unknowns forward_unknowns(const SlackCables& slack) {
  Unknowns u;
  u.all = {0, 1, 2, si::kRoll, si::kPitch, si::kYaw};
  for (int i = 0; i < kCableCount; ++i) {
    if (!slack[i]) {
      for (int j : {si::h(i), si::v(i), si::free_length(i)}) u.all.push_back(j);
    }
    u.per_cable[i] = {si::h(i), si::v(i), si::free_length(i)};
  }
  return u;
}

// Projected Newton: the step comes from the full square system; each trial
// point is then projected back onto the cable equations (each cable solved
// alone, sim/equilibrium_model.h), so the line search only weighs the
// platform's force and moment balance. Without the projection Newton crawls
// from the rigid-cable start, whose tension split is far off when the
// heading or tilt matters. Backtracking keeps forces and lengths positive.
EquilibriumResult newton(EquilibriumModel& model, State x, const Unknowns& unknowns, const SolverOptions& options) {
  const double cable_tolerance = 0.1 * options.tolerance;
  auto project = [&](State& state) {
    for (int i = 0; i < kCableCount; ++i) {
      if (!model.project_cable(state, i, unknowns.per_cable[i], cable_tolerance)) return false;
    }
    return true;
  };
  if (!project(x)) return Unexpected{failure(EquilibriumError::kNoConvergence, "cables do not reach their pulleys")};
  Equations e = model.evaluate(x);
  const int n = static_cast<int>(unknowns.all.size());
  for (int iteration = 0; iteration <= options.max_iterations; ++iteration) {
    if (e.cwiseAbs().maxCoeff() < options.tolerance) {
      Equilibrium eq = model.describe(x);
      eq.iterations = iteration;
      return eq;
    }
    if (iteration == options.max_iterations) break;
    const Eigen::VectorXd step = model.jacobian(x, unknowns.all).fullPivLu().solve(-e);
    if (!step.allFinite()) return Unexpected{failure(EquilibriumError::kNoConvergence, "singular Jacobian")};
    const double merit = e.squaredNorm();
    double alpha = 1.0;
    for (;;) {
      State trial = x;
      for (int k = 0; k < n; ++k) trial(unknowns.all[k]) += alpha * step(k);
      if (model.in_domain(trial) && project(trial)) {
        const Equations trial_e = model.evaluate(trial);
        // Below round-off the merit cannot decrease any more: accept.
        if (trial_e.squaredNorm() <= (1.0 - 1e-4 * alpha) * merit || trial_e.cwiseAbs().maxCoeff() < options.tolerance) {
          x = trial;
          e = trial_e;
          break;
        }
      }
      alpha *= 0.5;
      if (alpha < 1e-8) {
        return Unexpected{failure(EquilibriumError::kNoConvergence,
                                  "line search stalled at |e| = " + std::to_string(std::sqrt(merit)) +
                                      " (no equilibrium with taut cables nearby?)")};
      }
    }
  }
  return Unexpected{failure(EquilibriumError::kNoConvergence,
                            "no convergence in " + std::to_string(options.max_iterations) +
                                " iterations, |e| = " + std::to_string(e.norm()))};
}

// Every taut cable pulls, every slack one is no shorter than its chord, and
// the platform hangs upright.
EquilibriumResult check_plausible(const TrueRobot& robot, EquilibriumResult result) {
  if (!result) return result;
  const Equilibrium& eq = *result;
  for (int i = 0; i < kCableCount; ++i) {
    const CableEquilibrium& c = eq.cables[i];
    if (c.slack) {
      if ((robot.robot.winches[i].anchor_world - c.attachment_world).norm() > c.payout_m) {
        return Unexpected{failure(EquilibriumError::kSlackCable,
                                  "cable " + std::to_string(i) + " is shorter than its chord: it would be taut")};
      }
      continue;
    }
    if (!(c.h_n > 0.0 && c.tension_n > 0.0)) {
      return Unexpected{failure(EquilibriumError::kSlackCable, "cable " + std::to_string(i) + " is slack")};
    }
  }
  const double max_tilt = std::numbers::pi / 3.0;
  if (std::abs(eq.roll_rad) > max_tilt || std::abs(eq.pitch_rad) > max_tilt) {
    return Unexpected{failure(EquilibriumError::kUnstable, "platform tilted beyond 60 degrees")};
  }
  return result;
}

}  // namespace

EquilibriumResult solve_equilibrium(const TrueRobot& robot, const Eigen::Vector3d& position_world, double yaw_rad,
                                    const SolverOptions& options) {
  EquilibriumModel model(robot, options.segments);
  const auto start = initial_state(model, position_world, yaw_rad, 0.1 * options.tolerance);
  if (!start) return Unexpected{start.error()};
  return check_plausible(robot, newton(model, *start, inverse_unknowns(), options));
}

EquilibriumResult solve_forward_equilibrium(const TrueRobot& robot, const std::array<double, kCableCount>& payout_m,
                                            const Pose& initial, const SolverOptions& options,
                                            const SlackCables& slack) {
  const Eigen::Vector3d rpy = rpy_from_rotation(initial.world_R_platform.toRotationMatrix());
  if (slack != SlackCables{}) {
    // No inverse problem to start from: at a given position three cables
    // cannot balance force and moment at once.
    EquilibriumModel model(robot, options.segments);
    model.set_slack(slack);
    auto start = initial_state(model, initial.position_world, rpy.z(), 0.1 * options.tolerance);
    if (!start) return Unexpected{start.error()};
    State& x = *start;
    for (int i = 0; i < kCableCount; ++i) {
      x(si::free_length(i)) += payout_m[i] - x(si::payout(i));
      x(si::payout(i)) = payout_m[i];
    }
    return check_plausible(robot, newton(model, x, forward_unknowns(slack), options));
  }
  const EquilibriumResult at_initial = solve_equilibrium(robot, initial.position_world, rpy.z(), options);
  if (!at_initial) return at_initial;

  State x;
  x.segment<3>(si::kPosition) = at_initial->world_T_platform.position_world;
  x(si::kRoll) = at_initial->roll_rad;
  x(si::kPitch) = at_initial->pitch_rad;
  x(si::kYaw) = at_initial->yaw_rad;
  for (int i = 0; i < kCableCount; ++i) {
    const CableEquilibrium& c = at_initial->cables[i];
    x(si::h(i)) = c.h_n;
    x(si::v(i)) = c.v_n;
    // Start the free cable with the commanded change of payout.
    x(si::free_length(i)) = c.free_unstretched_m + (payout_m[i] - c.payout_m);
    x(si::payout(i)) = payout_m[i];
  }
  EquilibriumModel model(robot, options.segments);
  return check_plausible(robot, newton(model, x, forward_unknowns(slack), options));
}

const char* to_string(EquilibriumError error) {
  switch (error) {
    case EquilibriumError::kVerticalCable: return "vertical cable";
    case EquilibriumError::kInfeasible: return "infeasible pose";
    case EquilibriumError::kSlackCable: return "slack cable";
    case EquilibriumError::kNoConvergence: return "no convergence";
    case EquilibriumError::kUnstable: return "implausible posture";
  }
  return "unknown";
}

}  // namespace cdpr::sim
