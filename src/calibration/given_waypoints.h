#pragma once
// A run through waypoints the operator gives instead of the planner's
// (`calibctl start --waypoints FILE [--append-to RUN]`, docs/diagnosis.md
// "Measuring the poses that tell them apart"): typically the poses
// `cdpr-calib diagnose` proposes to tell a mimic set apart, optionally
// appended to the run whose data raised the question.

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/model/sample.h"

namespace cdpr::calibration {

// More than a handful of poses is a plan, not a question: the limit keeps
// a request's checks short.
inline constexpr std::size_t kMaxGivenWaypoints = 100;

struct GivenWaypoints {
  std::vector<Eigen::Vector3d> positions_world;  // [m] platform origin, world; driven in this order
  std::string source;                            // where they came from (the file), for messages
  // The rows the run's data begin with (an earlier run's samples.csv): the
  // run's fit and its samples.csv hold them and then the new poses. Empty: the new poses alone.
  std::vector<Sample> earlier_samples;
  int earlier_run = 0;  // the run they are from; 0 when none
  std::size_t earlier_rows = 0;  // how many there were (the state machine moves the rows out)
};

}  // namespace cdpr::calibration
