#pragma once
// The equations of the true static equilibrium of the platform on four heavy
// (optionally elastic) cables, for Newton's method (sim/equilibrium.h).
//
// State x (kStateSize): platform position (3) [m], roll, pitch, yaw [rad]
// (rotation Rz(yaw) Ry(pitch) Rx(roll)), then per cable i: h_n, v_n [N]
// (force on the platform, sim/cable_shooting.h), free unstretched length [m],
// payout [m] (unstretched, A over the pulley to the attachment).
//
// Equations (kEquationCount), scaled to comparable size:
//   0-2  net force on the platform / platform weight: cables + gravity + wind
//   3-5  net moment about the platform origin / (weight * 1 m); gravity and
//        wind act at the true centre of mass
//   per cable i, rows 6+3i..6+3i+2:
//        horizontal and vertical miss [m] of the shot cable's end from the
//        pulley departure point (sim/swivel_pulley.h), and
//        payout - free length - unstretched wrapped arc [m].
// 22 unknowns and 18 equations: the inverse problem frees roll, pitch and the
// cable unknowns; the forward problem frees the pose, forces and free lengths.
// A slack cable (set_slack) adds no force and its three rows are 0: the
// forward problem then frees the pose and the taut cables' unknowns only.

#include <array>
#include <vector>

#include <Eigen/Core>

#include "sim/cable_shooting.h"
#include "sim/equilibrium_state.h"
#include "sim/true_robot.h"

namespace cdpr::sim {

inline constexpr int kStateSize = 6 + 4 * kCableCount;
inline constexpr int kEquationCount = 6 + 3 * kCableCount;
using State = Eigen::Matrix<double, kStateSize, 1>;
using Equations = Eigen::Matrix<double, kEquationCount, 1>;

namespace state_index {
inline constexpr int kPosition = 0;
inline constexpr int kRoll = 3;
inline constexpr int kPitch = 4;
inline constexpr int kYaw = 5;
inline constexpr int h(int cable) { return 6 + 4 * cable; }
inline constexpr int v(int cable) { return 7 + 4 * cable; }
inline constexpr int free_length(int cable) { return 8 + 4 * cable; }
inline constexpr int payout(int cable) { return 9 + 4 * cable; }
}  // namespace state_index

Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw);
// Inverse of rotation_from_rpy for |pitch| < pi/2: (roll, pitch, yaw).
Eigen::Vector3d rpy_from_rotation(const Eigen::Matrix3d& world_R_platform);

class EquilibriumModel {
 public:
  // Keeps a reference to `robot`, which must outlive the model.
  EquilibriumModel(const TrueRobot& robot, int segments);

  // Cables that hang slack (none by default).
  void set_slack(const SlackCables& slack) { slack_ = slack; }
  bool slack(int cable) const { return slack_[cable]; }

  // Forces positive, lengths positive, no cable vertical (taut cables).
  bool in_domain(const State& x) const;
  bool cable_in_domain(const State& x, int cable) const;
  // Shoots every cable (the costly part), keeps the shots for jacobian() and
  // describe(), and returns the scaled equations. Precondition: in_domain(x).
  Equations evaluate(const State& x);
  // d equations / d x[free[k]] at the last evaluated x: shot derivatives are
  // analytic, the cheap geometric rest by central differences.
  Eigen::MatrixXd jacobian(const State& x, const std::vector<int>& free) const;
  // Solves cable i's three rows for the three state indices `unknowns` (of
  // that cable) with everything else fixed, by Newton from x; updates x and
  // the stored shot. Inverse problem: (v, free length, payout) at fixed h;
  // forward problem: (h, v, free length) at fixed payout. False when it fails
  // (leaving the domain, or no convergence to `tolerance` [m]).
  bool project_cable(State& x, int cable, const std::array<int, 3>& unknowns, double tolerance);
  // The physical state at the last evaluated x (== x).
  Equilibrium describe(const State& x) const;

  const TrueRobot& robot() const { return robot_; }
  int segments() const { return segments_; }
  const CableProperties& cable_properties() const { return cable_; }

 private:
  Equations geometry(const State& x) const;  // uses shots_ for the cable ends
  Eigen::Vector3d cable_rows(const State& x, const Eigen::Matrix3d& R, int cable) const;

  const TrueRobot& robot_;
  int segments_;
  CableProperties cable_;
  std::array<CableShot, kCableCount> shots_;
  SlackCables slack_{};
};

}  // namespace cdpr::sim
