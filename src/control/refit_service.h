#pragma once
// The daemon's re-fit of a kept run (the `refit` request,
// src/daemon/run_refitter.h) as the control dispatch sees it: start one,
// and what became of the last one. An interface, so that the dispatch stays
// pure logic and its tests need no solver run.

#include <optional>
#include <string>

#include "src/formats/expected.h"

namespace cdpr::control {

// The last refit the daemon was asked for (status response "refit").
struct RefitStatus {
  std::string run;    // the entry refitted, "run-000007"
  std::string terms;  // the model terms added to the catenary, "load_cell_bias"
  // "running" (fitting on a worker), "committed", "refused" (validation or
  // a run started meanwhile: nothing committed) or "failed" (the fit or
  // the store failed: nothing committed).
  std::string state;
  std::string message;  // one sentence: what was committed, or why not
  int committed_seq = 0;  // the calibration it committed; 0 none
  std::string entry;      // the history entry that keeps it (with its report.html); "" none
};

class RefitService {
 public:
  virtual ~RefitService() = default;
  // Starts refitting entry `run` (0: the newest kept run) with the catenary
  // plus `terms` (comma-separated model term names). Returns the sentence
  // for the operator, or why it is refused (unknown term, no such run, run
  // without samples, a refit already running). Never blocks on the fit.
  virtual Expected<std::string, std::string> start_refit(int run, const std::string& terms) = 0;
  // The last refit requested; none before the first.
  virtual std::optional<RefitStatus> refit_status() const = 0;
};

}  // namespace cdpr::control
