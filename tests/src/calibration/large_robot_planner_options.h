#pragma once
// The large robot's waypoint workspace and cable limits as the daemon ships
// them (its [waypoints] defaults), for the planner tests.

#include "src/calibration/waypoint_planner.h"

namespace cdpr::calibration {

inline PlannerOptions large_robot_planner_options() {
  PlannerOptions options;
  options.waypoint_count = 35;
  options.margin_m = 20.0;
  options.z_min_m = 5.0;
  options.z_max_m = 35.0;
  options.min_tension_n = 20.0;
  options.max_tension_n = 3000.0;
  return options;
}

}  // namespace cdpr::calibration
