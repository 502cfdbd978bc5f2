#include "src/calibration/calibration_state.h"

namespace cdpr::calibration {

const char* to_string(CalibrationState state) {
  switch (state) {
    case CalibrationState::kIdle: return "idle";
    case CalibrationState::kPreflight: return "preflight";
    case CalibrationState::kPlan: return "plan";
    case CalibrationState::kMove: return "move";
    case CalibrationState::kSettle: return "settle";
    case CalibrationState::kSample: return "sample";
    case CalibrationState::kSolve: return "solve";
    case CalibrationState::kValidate: return "validate";
    case CalibrationState::kCommit: return "commit";
    case CalibrationState::kAbort: return "abort";
    case CalibrationState::kDone: return "done";
    case CalibrationState::kFailed: return "failed";
    case CalibrationState::kAborted: return "aborted";
  }
  return "unknown";
}

bool is_running(CalibrationState state) {
  return state != CalibrationState::kIdle && state != CalibrationState::kDone && state != CalibrationState::kFailed &&
         state != CalibrationState::kAborted;
}

bool ended_without_commit(CalibrationState state) {
  return state == CalibrationState::kFailed || state == CalibrationState::kAborted;
}

}  // namespace cdpr::calibration
