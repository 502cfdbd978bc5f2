#pragma once
// One catenary or rigid fit from one start, the building block calibrate()
// (calibrate.h) repeats for its restarts, row hypotheses and multi-start.

#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

// The robust stages when options.robust asks for them (Huber, then Cauchy
// when a reading still stands out, then the gross-error test), then the
// final loss. When the robust stages find gross errors, the result carries
// them in gross_errors with the robust fit's anchors and ok = false, for
// the caller to refit without them.
CalibrationResult calibrate_once(const Robot& robot, const std::vector<Sample>& samples,
                                 const CalibrationOptions& options);

}  // namespace cdpr
