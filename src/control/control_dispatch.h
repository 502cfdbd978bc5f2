#pragma once
// Answers one control-socket request line against the daemon's state
// machine and store: what the socket server (src/main.cc) calls for every
// line it reads. Pure logic apart from the store's file access; time is
// passed in. Never throws; every outcome is one response line
// (control_response.h).
//
// `start waypoints <path> [<run>]` reads and checks the file and the run
// (start_waypoints.h) before the machine is asked to start.
// rollback and commit are refused while a calibration runs (the run's
// validation compares against the current file and its commit would
// overwrite theirs). commit commits the fit a failed commit kept (in the
// machine's memory or in <state>/pending: request_commit_kept()); after
// either, the machine's view of the store's problems is refreshed. refit is refused while a
// calibration runs too, and handed to `refits` (refit_service.h) otherwise,
// which fits on a worker: the answer says it started (or why not), status
// says what became of it.

#include <string>
#include <string_view>

#include "hal/clock.h"
#include "src/calibration/calibration_state_machine.h"
#include "src/control/refit_service.h"
#include "src/operation/operation_watch.h"
#include "src/store/calibration_store.h"

namespace cdpr::control {

// `refits` may be null: refit is then refused as not available.
// `operation`: watch mode's status for `status` (null: not watching).
std::string respond(std::string_view request_line, calibration::CalibrationStateMachine& machine,
                    store::CalibrationStore& store, hal::TimeUs now_us, RefitService* refits = nullptr,
                    const operation::OperationStatus* operation = nullptr);

}  // namespace cdpr::control
