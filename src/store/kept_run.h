#pragma once
// A kept run's data for new work on this daemon's robot (a refit of it, a
// run that appends to it): its history entry, the robot.toml it was
// measured with and its samples, each check's failure a reason naming the
// run. Reads small files; never throws.

#include <string>
#include <vector>

#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "src/formats/expected.h"
#include "src/store/run_history.h"

namespace cdpr::store {

struct KeptRun {
  RunEntry entry;
  Robot robot;  // as the run measured it
  std::vector<Sample> samples;
};

// Entry `run` (0: the newest) of `history`, refused when it is not kept, its
// log is unreadable, it kept no samples or none readable, or it was measured
// on another robot than `robot_name`. `use` completes "cannot be ...", e.g.
// "refitted" or "appended to".
Expected<KeptRun, std::string> read_kept_run(const RunHistory& history, int run, const std::string& robot_name,
                                             const std::string& use);

}  // namespace cdpr::store
