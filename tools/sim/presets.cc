#include "sim/presets.h"

#include <array>

namespace cdpr::sim {
namespace {

// Anchors on the top corners of a cuboid, counter-clockwise from the origin;
// attachment i on the platform's top corner towards anchor i.
Robot cuboid_robot(const char* name, const Eigen::Vector3d& cuboid, double half_width, double top_z) {
  Robot robot;
  robot.name = name;
  const std::array<Eigen::Vector2d, kCableCount> corner = {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                                           Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)};
  for (int i = 0; i < kCableCount; ++i) {
    Winch winch;
    winch.anchor_world = Eigen::Vector3d(corner[i].x() * cuboid.x(), corner[i].y() * cuboid.y(), cuboid.z());
    winch.attachment_platform = Eigen::Vector3d((2.0 * corner[i].x() - 1.0) * half_width,
                                                (2.0 * corner[i].y() - 1.0) * half_width, top_z);
    robot.winches.push_back(winch);
  }
  robot.reference_cable = 0;
  return robot;
}

// Everything that differs between the two scenarios.
struct PresetData {
  const char* name;
  Eigen::Vector3d cuboid;  // [m] anchor cuboid
  double half_width;       // [m] platform box half width
  double top_z;            // [m] attachment height in the platform frame
  double mass_kg;
  double density_kgpm;
  double com_z;            // [m] nominal centre of mass below the origin
  NoiseSigmas noise;
  Eigen::Vector3d workspace_min, workspace_max;
  double yaw_sigma_rad;
  double offset_range_m;
  double min_tension_n;
};

const PresetData kLarge{"large", {240.0, 220.0, 50.0}, 0.5, 0.5, 34.0, 0.0724, -0.3, {0.010, 5.0, 0.005, 0.01},
                        {95.0, 85.0, 10.0}, {145.0, 135.0, 24.0}, 0.002, 5.0, 50.0};
const PresetData kSmall{"small", {12.5, 4.5, 28.5}, 0.15, 0.1, 4.4, 0.0102, -0.3, {0.010, 1.0, 0.005, 0.01},
                        {4.0, 1.7, 3.0}, {8.5, 2.8, 18.0}, 0.003, 1.0, 2.0};

}  // namespace

PresetSpec preset_spec(Preset preset) {
  const PresetData& d = preset == Preset::kLarge ? kLarge : kSmall;
  PresetSpec spec;
  Robot& robot = spec.robot.robot;
  robot = cuboid_robot(d.name, d.cuboid, d.half_width, d.top_z);
  robot.platform_mass_kg = d.mass_kg;
  robot.cable_linear_density_kgpm = d.density_kgpm;
  robot.center_of_mass_platform = Eigen::Vector3d(0.0, 0.0, d.com_z);
  robot.noise = d.noise;
  spec.workspace_min = d.workspace_min;
  spec.workspace_max = d.workspace_max;
  spec.yaw_sigma_rad = d.yaw_sigma_rad;
  spec.offset_range_m = d.offset_range_m;
  spec.min_tension_n = d.min_tension_n;
  return spec;
}

std::optional<Preset> parse_preset(std::string_view name) {
  if (name == "large") return Preset::kLarge;
  if (name == "small") return Preset::kSmall;
  return std::nullopt;
}

}  // namespace cdpr::sim
