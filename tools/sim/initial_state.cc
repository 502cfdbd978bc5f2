#include "sim/initial_state.h"

#include <cmath>
#include <string>

#include <Eigen/LU>
#include <Eigen/QR>

namespace cdpr::sim {
namespace {

namespace si = state_index;

}  // namespace

Expected<State, EquilibriumFailure> initial_state(EquilibriumModel& model, const Eigen::Vector3d& position_world,
                                                  double yaw_rad, double tolerance_m) {
  const TrueRobot& robot = model.robot();
  const double w = model.cable_properties().weight_per_length_npm;
  const Eigen::Matrix3d R = rotation_from_rpy(0.0, 0.0, yaw_rad);

  // Straight cables: F_i ~ t_i e_i - (w l_i / 2) z (about half of each
  // cable's weight hangs on the platform). Force balance and the moment about
  // the vertical give 4 equations for the 4 tensions; the roll and pitch
  // moments are left to the tilt, which Newton finds. (The yaw moment matters:
  // a heading off the cables' neutral one needs large internal forces.)
  Eigen::Matrix4d statics;
  std::array<double, kCableCount> chord{};
  std::array<Eigen::Vector3d, kCableCount> attachment;
  const Eigen::Vector3d external = robot.effects.wind_force_world_n - robot.platform_weight_n() * Eigen::Vector3d::UnitZ();
  Eigen::Vector4d load;
  load << -external, -(R * robot.center_of_mass_platform()).cross(external).z();
  bool any_slack = false;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d lever = R * robot.robot.winches[i].attachment_platform;
    attachment[i] = position_world + lever;
    const Eigen::Vector3d d = robot.robot.winches[i].anchor_world - attachment[i];
    if (!(std::hypot(d.x(), d.y()) > 1e-9)) {
      return Unexpected{failure(EquilibriumError::kVerticalCable,
                                "cable " + std::to_string(i) + " hangs straight below its anchor")};
    }
    chord[i] = d.norm();
    if (model.slack(i)) {
      statics.col(i).setZero();
      any_slack = true;
      continue;
    }
    const Eigen::Vector3d direction = d / chord[i];
    statics.col(i) << direction, lever.cross(direction).z();
    load.z() += 0.5 * w * chord[i];
  }
  // Fewer than four taut cables: the force balance alone (the yaw moment is Newton's).
  const Eigen::Matrix<double, 3, kCableCount> forces = statics.topRows<3>();
  Eigen::Vector4d tension = any_slack ? Eigen::Vector4d(forces.colPivHouseholderQr().solve(load.head<3>()))
                                      : Eigen::Vector4d(statics.fullPivLu().solve(load));
  if (!any_slack && (!tension.allFinite() || !(statics * tension).isApprox(load, 1e-9))) {
    // Degenerate heading: fall back to the min-norm force balance.
    tension = forces.transpose() * (forces * forces.transpose()).inverse() * load.head<3>();
  }

  State x = State::Zero();
  x.segment<3>(si::kPosition) = position_world;
  x(si::kYaw) = yaw_rad;
  for (int i = 0; i < kCableCount; ++i) {
    if (model.slack(i)) {
      x(si::free_length(i)) = chord[i];
      x(si::payout(i)) = chord[i];
      continue;
    }
    if (!(tension(i) > 0.0)) {
      return Unexpected{failure(EquilibriumError::kInfeasible,
                                "rigid statics need cable " + std::to_string(i) + " to push at this pose")};
    }
    const Eigen::Vector3d force = tension(i) * (robot.robot.winches[i].anchor_world - attachment[i]) / chord[i];
    x(si::h(i)) = force.head<2>().norm();
    x(si::v(i)) = force.z() - 0.5 * w * chord[i];
    x(si::free_length(i)) = chord[i];
    x(si::payout(i)) = chord[i];
    // With h fixed a catenary of parameter h / w passes through any two
    // points, so this projection has a solution.
    if (!model.project_cable(x, i, {si::v(i), si::free_length(i), si::payout(i)}, tolerance_m)) {
      return Unexpected{failure(EquilibriumError::kNoConvergence,
                                "cable " + std::to_string(i) + " could not be shot onto its pulley")};
    }
  }
  return x;
}

}  // namespace cdpr::sim
