#pragma once
// The pose from the cables as the daemon serves it at every rest (watch
// mode, [operation] pose_output; docs/FORMATS.md "Pose from the cables"):
// two lines per rest,
//
//   POSE <t_us> <x> <y> <z> <qw> <qx> <qy> <qz> 1\n
//   COV <t_us> <c_11> <c_12> ... <c_16> <c_22> ... <c_66>\n
//
// POSE is the pose line of drivers/pose/pose_line.h (a reader of the
// onboard pose stream reads it unchanged), stamped with the rest's pose
// source time; COV the 21 upper-triangle entries, row by row, of the 6x6
// covariance of (position [m], rotation vector [rad]), both world frame
// (solver/operation/localize.h: p = p_hat + d_p, R = Exp(d_theta) R_hat).
// Numbers in 17 significant digits: they read back exactly. Pure functions.

#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "hal/clock.h"
#include "solver/nls/pose.h"

namespace cdpr::operation {

std::string format_pose_output(hal::TimeUs source_time_us, const Pose& pose,
                               const Eigen::Matrix<double, 6, 6>& covariance);

// A COV line (without its '\n') back into its stamp and symmetric matrix; nullopt if it is none.
struct PoseCovarianceLine {
  hal::TimeUs source_time_us = 0;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};
std::optional<PoseCovarianceLine> parse_covariance_line(std::string_view line);

}  // namespace cdpr::operation
