#pragma once
// The factor graph of rests seen in operation: per rest k its pose and
// reference force, the kineto-static factor of its readings (the base
// catenary's StaticPoseFactor, or EffectPoseFactor when the calibration has
// model terms) and, when asked, the prior of its measured pose; the
// calibration's variables shared (solver/operation/calibration_variables.h).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/model/calibration.h"
#include "solver/model/effects.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/nls/factor.h"
#include "solver/nls/pose.h"
#include "solver/nls/problem.h"

namespace cdpr {

// The kineto-static factor of `rest` as pose `pose_index` (least squares, no
// robust loss: the operation-time tests want the plain residuals).
std::unique_ptr<Factor> make_rest_factor(const Robot& robot, int pose_index, const Sample& rest,
                                         const std::vector<Effect>& effects, double height_sigma_m);

// The prior of the measured pose of `rest` (its own sigmas, else robot.toml's).
std::unique_ptr<Factor> make_measured_pose_factor(const Robot& robot, int pose_index, const Sample& rest);

// Whether a row carries a usable measured pose: finite, unit quaternion.
bool has_measured_pose(const Sample& rest);

// A start for rest `rest` from `start`: the position refined by least
// squares over the four cables taken straight (chord = encoder reading -
// offset), then the statics solved there (solve_static_pose) for the
// orientation (yaw zero) and the reference force. Empty with *why when the statics
// have no equilibrium there.
struct RestStart {
  Pose world_T_platform;
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();
};
std::optional<RestStart> rest_start(const Robot& robot, const Calibration& calibration, const Sample& rest,
                                    const Pose& start, std::string* why);

}  // namespace cdpr
