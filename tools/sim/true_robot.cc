#include "sim/true_robot.h"

#include <algorithm>
#include <cmath>

namespace cdpr::sim {
namespace {

std::vector<double> values_of(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

EffectValues effect_values(const HiddenEffects& e) {
  EffectValues values;
  if (std::isfinite(e.axial_stiffness_n)) values["axial_stiffness"] = {e.axial_stiffness_n};
  bool any_scale = false;
  for (double s : e.encoder_scale) any_scale = any_scale || s != 0.0;
  if (any_scale) values["encoder_scale"] = {e.encoder_scale.begin(), e.encoder_scale.end()};
  bool any_drift = false;
  for (double d : e.encoder_drift_m) any_drift = any_drift || d != 0.0;
  if (any_drift) values["encoder_drift"] = {e.encoder_drift_m.begin(), e.encoder_drift_m.end()};
  if (e.force_bias_n != 0.0) values["force_bias"] = {e.force_bias_n};
  if (e.force_gain != 0.0) values["force_gain"] = {e.force_gain};
  if (!e.com_offset_platform.isZero(0.0)) values["com_offset"] = values_of(e.com_offset_platform);
  if (e.density_error != 0.0) values["density_error"] = {e.density_error};
  if (e.pulley_radius_m != 0.0) values["pulley_radius"] = {e.pulley_radius_m};
  if (!e.pose_reference_offset_platform.isZero(0.0)) {
    values["pose_reference_offset"] = values_of(e.pose_reference_offset_platform);
  }
  if (!e.wind_force_world_n.isZero(0.0)) values["wind_force"] = values_of(e.wind_force_world_n);
  return values;
}

Truth truth_of(const TrueRobot& robot) {
  Truth truth;
  for (int i = 0; i < robot.robot.cable_count(); ++i) {
    truth.winches.push_back({robot.robot.winches[i].anchor_world, robot.encoder_offset_m[i]});
  }
  truth.effects = effect_values(robot.effects);
  return truth;
}

HiddenEffects hidden_effects_of(const EffectValues& values) {
  HiddenEffects e;
  auto value = [&](const char* name, std::size_t size) -> const std::vector<double>* {
    const auto v = values.find(name);
    return v != values.end() && v->second.size() == size ? &v->second : nullptr;
  };
  auto vector3 = [](const std::vector<double>& v) { return Eigen::Vector3d(v[0], v[1], v[2]); };
  if (const auto* v = value("axial_stiffness", 1)) e.axial_stiffness_n = (*v)[0];
  if (const auto* v = value("encoder_scale", kCableCount)) std::copy(v->begin(), v->end(), e.encoder_scale.begin());
  if (const auto* v = value("encoder_drift", kCableCount)) std::copy(v->begin(), v->end(), e.encoder_drift_m.begin());
  if (const auto* v = value("force_bias", 1)) e.force_bias_n = (*v)[0];
  if (const auto* v = value("force_gain", 1)) e.force_gain = (*v)[0];
  if (const auto* v = value("com_offset", 3)) e.com_offset_platform = vector3(*v);
  if (const auto* v = value("density_error", 1)) e.density_error = (*v)[0];
  if (const auto* v = value("pulley_radius", 1)) e.pulley_radius_m = (*v)[0];
  if (const auto* v = value("pose_reference_offset", 3)) e.pose_reference_offset_platform = vector3(*v);
  if (const auto* v = value("wind_force", 3)) e.wind_force_world_n = vector3(*v);
  return e;
}

TrueRobot robot_of(const Robot& nominal, const Calibration& calibration) {
  TrueRobot robot;
  robot.robot = nominal;
  for (std::size_t i = 0; i < calibration.winches.size() && i < robot.robot.winches.size(); ++i) {
    robot.robot.winches[i].anchor_world = calibration.winches[i].anchor_world;
    robot.encoder_offset_m[i] = calibration.winches[i].offset_m;
  }
  robot.effects = hidden_effects_of(calibration.effects);
  return robot;
}

}  // namespace cdpr::sim
