#pragma once
// The large robot's waypoint workspace and cable limits as the daemon ships
// them (its [waypoints] defaults), for the planner tests.

#include "src/calibration/waypoint_planner.h"

namespace cdpr::calibration {

// PlannerOptions' defaults are the daemon's (ConfigDefaults test).
inline PlannerOptions large_robot_planner_options() { return PlannerOptions{}; }

}  // namespace cdpr::calibration
