#pragma once
// Work on a run's waypoints that may take long: planning the run
// (WaypointSequence::start) or, for the sequential strategy, the re-solve and
// the choice of the next waypoint after a sample or a skip (sampled(),
// skipped()). The state machine moves its WaypointSequence into the job and
// takes it back with the result, so a job run on another thread shares
// nothing with the machine while it runs (calibration_state_machine.h).

#include <functional>
#include <string>
#include <utility>

#include "src/calibration/waypoint_sequence.h"

namespace cdpr::calibration {

struct WaypointJob {
  WaypointSequence sequence;
  // Works on `sequence`; returns what went wrong (a plan that failed), else "".
  // Owns copies of everything it needs.
  std::function<std::string(WaypointSequence&)> work;
  std::string problem;  // work()'s answer once run()

  void run() { problem = work(sequence); }
};

// Where the state machine's waypoint jobs run: inside step() (tests, tools),
// or handed to the owner (the daemon's worker thread) and delivered back.
enum class WaypointWork { kInline, kByOwner };

}  // namespace cdpr::calibration
