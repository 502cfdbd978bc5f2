#pragma once
// Where the platform rests when its origin is held at a given position: the
// forward model of the sagging-cable statics (paper Eq. 1-11) solved for the
// orientation and the reference cable's force.
//
// A four-cable platform has 6 DoF but 4 cable lengths, so for a chosen
// position one more freedom remains; the planner fixes the yaw (rotation
// about world z) to zero and solves roll, pitch and the reference force
// (f_h, f_v) so that every cable's catenary reaches its attachment point
// (Eq. 15 height consistency for all four cables: 4 equations, 4 unknowns).
// The cable arc lengths (Eq. 4) are then what the winches must pay out (plus
// their encoder offsets) and the tensions are what the load cell should see.
// Pure numerics, no allocation beyond the result.

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "solver/model/robot.h"
#include "solver/nls/pose.h"

namespace cdpr {

struct StaticPose {
  Pose world_T_platform;
  std::array<double, kCableCount> arc_length_m{};  // Eq. (4), anchor to attachment
  std::array<double, kCableCount> tension_n{};     // at the attachment
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();  // (f_h, f_v) [N]
  double height_residual_m = 0.0;  // max |catenary end height - attachment height| at the solution
};

// Solves as above by the small damped solver
// (solver/nls/dense_damped_solver.h) with a central-difference Jacobian. Empty when there is no
// equilibrium; *why (if given) then says why (a cable would push, the
// statics fail, no convergence).
std::optional<StaticPose> solve_static_pose(const Robot& robot, const std::array<Eigen::Vector3d, kCableCount>& anchors,
                                            const Eigen::Vector3d& position_world, std::string* why = nullptr);

// The nominal anchors of `robot` in cable order.
std::array<Eigen::Vector3d, kCableCount> nominal_anchors(const Robot& robot);

}  // namespace cdpr
