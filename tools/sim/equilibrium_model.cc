#include "sim/equilibrium_model.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "sim/swivel_pulley.h"

namespace cdpr::sim {
namespace {

namespace si = state_index;
const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

// One cable's geometry and forces at a state, shared by the equations and
// the description.
struct CableTerms {
  Eigen::Vector3d lever_world;       // R b_i
  Eigen::Vector3d attachment_world;  // p + R b_i
  Eigen::Vector3d toward_anchor;     // horizontal unit vector attachment -> anchor
  double span_m = 0.0;               // horizontal attachment-anchor distance
  Eigen::Vector3d force_n;           // on the platform
  PulleyDeparture departure;
  double end_tension_n = 0.0;        // |T| at the pulley
};

CableTerms cable_terms(const TrueRobot& robot, const State& x, const Eigen::Matrix3d& R, int i) {
  const double w = robot.cable_weight_per_length_npm();
  CableTerms c;
  c.lever_world = R * robot.robot.winches[i].attachment_platform;
  c.attachment_world = x.segment<3>(si::kPosition) + c.lever_world;
  const Eigen::Vector3d d = robot.robot.winches[i].anchor_world - c.attachment_world;
  c.span_m = std::hypot(d.x(), d.y());
  c.toward_anchor = Eigen::Vector3d(d.x(), d.y(), 0.0) / c.span_m;
  const double h = x(si::h(i));
  const double v = x(si::v(i));
  c.force_n = h * c.toward_anchor + v * kUp;
  const double end_v = v + w * x(si::free_length(i));
  c.end_tension_n = std::hypot(h, end_v);
  c.departure = pulley_departure(robot.effects.pulley_radius_m, h, end_v);
  return c;
}

double compliance_of(const TrueRobot& robot) {
  const double ea = robot.effects.axial_stiffness_n;
  return std::isfinite(ea) ? 1.0 / ea : 0.0;
}

}  // namespace

Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, kUp) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d rpy_from_rotation(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  return {std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0))};
}

EquilibriumModel::EquilibriumModel(const TrueRobot& robot, int segments)
    : robot_(robot),
      segments_(segments),
      cable_{robot.cable_weight_per_length_npm(), robot.effects.axial_stiffness_n} {}

bool EquilibriumModel::in_domain(const State& x) const {
  for (int i = 0; i < kCableCount; ++i) {
    if (!cable_in_domain(x, i)) return false;
  }
  return true;
}

bool EquilibriumModel::cable_in_domain(const State& x, int i) const {
  if (slack_[i]) return x.segment<6>(0).allFinite();
  if (!(x(si::h(i)) > 0.0 && x(si::free_length(i)) > 0.0 && x(si::payout(i)) > 0.0)) return false;
  if (!x.segment<6>(0).allFinite() || !std::isfinite(x(si::v(i)))) return false;
  const Eigen::Matrix3d R = rotation_from_rpy(x(si::kRoll), x(si::kPitch), x(si::kYaw));
  const Eigen::Vector3d d = robot_.robot.winches[i].anchor_world - x.segment<3>(si::kPosition) -
                            R * robot_.robot.winches[i].attachment_platform;
  return std::hypot(d.x(), d.y()) > 1e-9;
}

Equations EquilibriumModel::evaluate(const State& x) {
  for (int i = 0; i < kCableCount; ++i) {
    shots_[i] = slack_[i] ? CableShot{}
                          : shoot_cable(cable_, x(si::h(i)), x(si::v(i)), x(si::free_length(i)), segments_);
  }
  return geometry(x);
}

Eigen::Vector3d EquilibriumModel::cable_rows(const State& x, const Eigen::Matrix3d& R, int i) const {
  const CableTerms c = cable_terms(robot_, x, R, i);
  const double anchor_z = robot_.robot.winches[i].anchor_world.z();
  // The cable on a frictionless pulley carries the end tension all along.
  return {shots_[i].end.x() - (c.span_m - c.departure.horizontal_m),
          shots_[i].end.y() - (anchor_z + c.departure.height_m - c.attachment_world.z()),
          x(si::payout(i)) - x(si::free_length(i)) -
              c.departure.wrapped_arc_m / (1.0 + compliance_of(robot_) * c.end_tension_n)};
}

Equations EquilibriumModel::geometry(const State& x) const {
  const Eigen::Matrix3d R = rotation_from_rpy(x(si::kRoll), x(si::kPitch), x(si::kYaw));
  const double weight = robot_.platform_weight_n();
  // Gravity and wind at the true centre of mass.
  Eigen::Vector3d force = robot_.effects.wind_force_world_n - weight * kUp;
  Eigen::Vector3d moment = (R * robot_.center_of_mass_platform()).cross(force);

  Equations e;
  for (int i = 0; i < kCableCount; ++i) {
    if (slack_[i]) {
      e.segment<3>(6 + 3 * i).setZero();
      continue;
    }
    const CableTerms c = cable_terms(robot_, x, R, i);
    force += c.force_n;
    moment += c.lever_world.cross(c.force_n);
    e.segment<3>(6 + 3 * i) = cable_rows(x, R, i);
  }
  e.segment<3>(0) = force / weight;
  e.segment<3>(3) = moment / weight;
  return e;
}

bool EquilibriumModel::project_cable(State& x, int i, const std::array<int, 3>& unknowns, double tolerance) {
  if (slack_[i]) return true;
  const Eigen::Matrix3d R = rotation_from_rpy(x(si::kRoll), x(si::kPitch), x(si::kYaw));
  auto shoot = [&] { shots_[i] = shoot_cable(cable_, x(si::h(i)), x(si::v(i)), x(si::free_length(i)), segments_); };
  if (!cable_in_domain(x, i)) return false;
  shoot();
  Eigen::Vector3d rows = cable_rows(x, R, i);
  for (int iteration = 0; iteration < 30; ++iteration) {
    if (rows.cwiseAbs().maxCoeff() < tolerance) return true;
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) {
      const int j = unknowns[k];
      const double step = 1e-6 * std::max(1.0, std::abs(x(j)));
      State plus = x, minus = x;
      plus(j) += step;
      minus(j) -= step;
      J.col(k) = (cable_rows(plus, R, i) - cable_rows(minus, R, i)) / (2.0 * step);
      const int local = j - si::h(i);
      if (local >= 0 && local < 3) J.col(k).head<2>() += shots_[i].d_end.col(local);
    }
    const Eigen::Vector3d step = -J.fullPivLu().solve(rows);
    const State start = x;
    const double merit = rows.squaredNorm();
    double alpha = 1.0;
    for (;;) {
      for (int k = 0; k < 3; ++k) x(unknowns[k]) = start(unknowns[k]) + alpha * step(k);
      if (cable_in_domain(x, i)) {
        shoot();
        const Eigen::Vector3d trial = cable_rows(x, R, i);
        if (trial.squaredNorm() < merit || trial.cwiseAbs().maxCoeff() < tolerance) {
          rows = trial;
          break;
        }
      }
      alpha *= 0.5;
      if (alpha < 1e-6) {
        x = start;
        return false;
      }
    }
  }
  return false;
}

Eigen::MatrixXd EquilibriumModel::jacobian(const State& x, const std::vector<int>& free) const {
  Eigen::MatrixXd J(kEquationCount, static_cast<int>(free.size()));
  for (int k = 0; k < static_cast<int>(free.size()); ++k) {
    const int j = free[k];
    const double step = 1e-6 * std::max(1.0, std::abs(x(j)));
    State plus = x, minus = x;
    plus(j) += step;
    minus(j) -= step;
    J.col(k) = (geometry(plus) - geometry(minus)) / (2.0 * step);
    // The shot end moves with the cable's own force and free length.
    for (int i = 0; i < kCableCount; ++i) {
      const int local = j - si::h(i);
      if (local >= 0 && local < 3) J.block<2, 1>(6 + 3 * i, k) += shots_[i].d_end.col(local);
    }
  }
  return J;
}

Equilibrium EquilibriumModel::describe(const State& x) const {
  const Eigen::Matrix3d R = rotation_from_rpy(x(si::kRoll), x(si::kPitch), x(si::kYaw));
  Equilibrium eq;
  eq.world_T_platform.position_world = x.segment<3>(si::kPosition);
  eq.world_T_platform.world_R_platform = Eigen::Quaterniond(R);
  eq.roll_rad = x(si::kRoll);
  eq.pitch_rad = x(si::kPitch);
  eq.yaw_rad = x(si::kYaw);
  for (int i = 0; i < kCableCount; ++i) {
    CableEquilibrium& out = eq.cables[i];
    if (slack_[i]) {
      out.attachment_world = x.segment<3>(si::kPosition) + R * robot_.robot.winches[i].attachment_platform;
      out.payout_m = out.free_unstretched_m = out.free_arc_m = out.arc_length_m = x(si::payout(i));
      out.slack = true;
      continue;
    }
    const CableTerms c = cable_terms(robot_, x, R, i);
    out.attachment_world = c.attachment_world;
    out.h_n = x(si::h(i));
    out.v_n = x(si::v(i));
    out.tension_n = std::hypot(out.h_n, out.v_n);
    out.free_unstretched_m = x(si::free_length(i));
    out.payout_m = x(si::payout(i));
    out.free_arc_m = shots_[i].stretched_length_m;
    out.wrapped_arc_m = c.departure.wrapped_arc_m;
    out.arc_length_m = out.free_arc_m + out.wrapped_arc_m;
  }
  const Equations e = geometry(x);
  const double weight = robot_.platform_weight_n();
  eq.force_residual_n = e.segment<3>(0).norm() * weight;
  eq.moment_residual_nm = e.segment<3>(3).norm() * weight;
  for (int i = 0; i < kCableCount; ++i) {
    eq.length_residual_m = std::max(eq.length_residual_m, e.segment<3>(6 + 3 * i).cwiseAbs().maxCoeff());
  }
  return eq;
}

}  // namespace cdpr::sim
