#pragma once
// The paper's two scenarios (Table I, Sec. V) as simulation presets: robot,
// sensor noise, and the workspace box that waypoints are drawn from.
//
// large: anchors at the top corners of a 240 x 220 x 50 m cuboid, 34 kg
//        platform, 0.0724 kg/m cable (4 mm), platform box +-0.5 m.
// small: 12.5 x 4.5 x 28.5 m, 4.4 kg, 0.0102 kg/m, platform box +-0.15 m.
// Cable i runs to anchor i from the platform's top corner nearest to it;
// cable 0 carries the load cell; the nominal centre of mass hangs below the
// attachments so the platform hangs upright. Noise per paper Sec. V-B:
// encoder 10 mm, force 5 N (large) / 1 N (small), pose 5 mm / 0.01 rad.

#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "sim/true_robot.h"

namespace cdpr::sim {

enum class Preset { kLarge, kSmall };

struct PresetSpec {
  TrueRobot robot;  // zero encoder offsets, no hidden effects
  // Waypoint positions are drawn inside this box (platform origin, world);
  // chosen so the cable lengths and forces span ranges like Table I.
  Eigen::Vector3d workspace_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d workspace_max = Eigen::Vector3d::Zero();
  double yaw_sigma_rad = 0.05;        // heading spread of the waypoints
  double offset_range_m = 0.0;        // true encoder offsets uniform in +-this
  double min_tension_n = 0.0;         // waypoints with a cable below this are skipped
};

PresetSpec preset_spec(Preset preset);
std::optional<Preset> parse_preset(std::string_view name);  // "large" | "small"

}  // namespace cdpr::sim
