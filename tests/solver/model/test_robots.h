#pragma once
// Robots and poses shared by the solver tests: the paper's large and small
// scenarios (Table I) with plausible attachment points.

#include <array>

#include "solver/nls/pose.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr::test {

inline Robot large_robot() {
  Robot robot;
  robot.name = "large";
  robot.platform_mass_kg = 34.0;
  robot.cable_linear_density_kgpm = 0.0724;
  const std::array<Eigen::Vector3d, 4> anchors = {Eigen::Vector3d(0, 0, 50), Eigen::Vector3d(240, 0, 50),
                                                  Eigen::Vector3d(240, 220, 50), Eigen::Vector3d(0, 220, 50)};
  const std::array<Eigen::Vector3d, 4> attachments = {
      Eigen::Vector3d(-0.5, -0.5, 0.5), Eigen::Vector3d(0.5, -0.5, 0.5), Eigen::Vector3d(0.5, 0.5, 0.5),
      Eigen::Vector3d(-0.5, 0.5, 0.5)};
  for (int i = 0; i < 4; ++i) robot.winches.push_back({anchors[i], attachments[i]});
  robot.center_of_mass_platform = Eigen::Vector3d(0.02, -0.01, -0.2);
  return robot;
}

inline Robot small_robot() {
  Robot robot;
  robot.name = "small";
  robot.platform_mass_kg = 4.4;
  robot.cable_linear_density_kgpm = 0.0102;
  const std::array<Eigen::Vector3d, 4> anchors = {Eigen::Vector3d(0, 0, 28.5), Eigen::Vector3d(12.5, 0, 28.5),
                                                  Eigen::Vector3d(12.5, 4.5, 28.5), Eigen::Vector3d(0, 4.5, 28.5)};
  const std::array<Eigen::Vector3d, 4> attachments = {
      Eigen::Vector3d(-0.15, -0.15, 0.1), Eigen::Vector3d(0.15, -0.15, 0.1), Eigen::Vector3d(0.15, 0.15, 0.1),
      Eigen::Vector3d(-0.15, 0.15, 0.1)};
  for (int i = 0; i < 4; ++i) robot.winches.push_back({anchors[i], attachments[i]});
  robot.noise.force_n = 1.0;
  return robot;
}

inline Pose tilted_pose(const Eigen::Vector3d& position) {
  Pose pose;
  pose.position_world = position;
  pose.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()));
  return pose;
}

// A measurement at `pose` with plausible readings of the large robot, for
// Jacobian checks (the values need not be consistent).
inline Sample sample_at(const Pose& pose) {
  Sample s;
  s.position_world = pose.position_world;
  s.world_R_platform = pose.world_R_platform;
  s.encoder_m = {150.0, 160.0, 170.0, 180.0};
  s.force_n = 600.0;
  return s;
}

inline std::array<Eigen::Vector3d, 4> anchors_of(const Robot& robot) {
  std::array<Eigen::Vector3d, 4> anchors;
  for (int i = 0; i < 4; ++i) anchors[i] = robot.winches[i].anchor_world;
  return anchors;
}

}  // namespace cdpr::test
