#pragma once
// The re-fit the health watch offers (docs/operation.md): from the rests
// watched since a change, the calibration with the changed term estimated
// anew, everything else as committed. Returned, never applied: the operator
// commits it or not.
//
// The graph: per rest its pose and reference force, its kineto-static
// factor (Eq. 14-16) and the prior of its measured pose (required: without
// the onboard pose the rests cannot tell an offset from a pose); the
// calibration held fixed but for the re-fitted variables, which are free
// (no prior: the committed value is what went wrong).

#include <optional>
#include <string>
#include <vector>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "solver/operation/health_watch.h"

namespace cdpr {

struct RefitRequest {
  // All four encoder offsets (true), or the term below alone.
  bool offsets_only = true;
  FaultTerm term = FaultTerm::kEncoderOffset;
  int cable = 0;
};

// The request for a finding's term: offset i -> offset i, anchor i -> anchor
// i, elongation of cable i -> offset i (at the payouts of these rests the
// offset absorbs it; the cable needs replacing or a new calibration run).
// Load and load-cell bias are no calibration terms: offsets only.
RefitRequest refit_request_for(const StaleFinding& finding);

struct RefitOptions {
  double height_sigma_m = 1e-2;  // Eq. (15)
  int max_iterations = 100;
};

// Empty with *why when the rests cannot carry the fit: none, a row without
// a measured pose, a calibration the model cannot use, no convergence.
// The re-fitted values come with the sigmas of this fit; `samples` counts
// the rests.
std::optional<Calibration> refit_from_rests(const Robot& robot, const Calibration& committed,
                                            const std::vector<Sample>& rests, const RefitRequest& request,
                                            const RefitOptions& options, std::string* why);

}  // namespace cdpr
