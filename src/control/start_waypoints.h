#pragma once
// What `start waypoints <path> [<run>]` (control_request.h) names, read and
// checked on the control socket before anything moves: the waypoints.csv
// (docs/FORMATS.md) and, with a run, the rows of that kept run the new run's
// data begin with (docs/diagnosis.md "Measuring the poses that tell them
// apart"). The workspace box and the planner's limits are the state
// machine's checks (calibration_state_machine.h request_start). Reads small
// files only; never throws.

#include <cstdint>
#include <string>

#include "solver/model/robot.h"
#include "src/calibration/given_waypoints.h"
#include "src/formats/expected.h"

namespace cdpr::control {

// A waypoints file larger than this is not one diagnose wrote (it is read
// on the daemon's loop thread).
inline constexpr std::uintmax_t kMaxWaypointsFileBytes = 64 * 1024;

// Refused, with a reason naming what failed: a path that is not a readable
// regular file of at most kMaxWaypointsFileBytes, a malformed file (its
// file:line: column: why), a run (> 0) that is not kept in `history_dir`, has no
// readable log or samples, or was measured on another robot than `robot`.
Expected<calibration::GivenWaypoints, std::string> load_start_waypoints(const std::string& path, int run,
                                                                        const std::string& history_dir,
                                                                        const Robot& robot);

}  // namespace cdpr::control
