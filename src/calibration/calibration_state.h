#pragma once
// The states of one field calibration (docs/DESIGN.md "Data flow") and the
// status the daemon reports on the control socket.

#include <string>
#include <vector>

#include "hal/clock.h"
#include "hal/winch_bank.h"

namespace cdpr::calibration {

enum class CalibrationState {
  kIdle,       // nothing run since start-up
  kPreflight,  // checking nodes, load cell, pose
  kPlan,       // planning waypoints from the geometry; then enabling the drives
  kMove,       // winches travelling to waypoint k
  kSettle,     // waiting for equilibrium at waypoint k
  kSample,     // averaging the rest window into one sample row
  kSolve,      // fitting anchors and offsets
  kValidate,   // accepting or refusing the fit
  kCommit,     // writing calibration.toml atomically
  kAbort,      // stopping the winches after a fault or an abort request
  kDone,       // last run committed a new calibration
  kFailed,     // last run stopped; status.reason says why; old calibration kept
  kAborted,    // last run aborted on request (operator, stopping daemon); old calibration kept
};

const char* to_string(CalibrationState state);

// True for the states of a run in progress (preflight .. abort).
bool is_running(CalibrationState state);
// True for the end of a run that committed nothing (failed, aborted).
bool ended_without_commit(CalibrationState state);

struct CalibrationStatus {
  CalibrationState state = CalibrationState::kIdle;
  int waypoint = 0;            // 1-based waypoint being worked on; 0 before planning
  int waypoint_count = 0;      // N of the plan; 0 before planning
  int samples = 0;             // waypoints sampled so far
  int skipped = 0;             // waypoints skipped (settle timeout)
  double progress = 0.0;       // 0 .. 1 over the whole run
  std::string reason;          // why the last run failed, or what it committed
  std::string note;            // latest remark (skipped waypoint, ignored button press, ...)
  std::string detail;          // what the current state waits for (e.g. "platform moving: 4.1 mm/s")
  // Latched device faults and their causes ("winch 0: node 11: position
  // jumped ..."; EMCY codes), until `reset-faults` or a run's enable.
  std::string device_faults;
  // Every bus node of the winches as last heard (NMT and CiA 402 state,
  // 0x603F, last EMCY, PDO age), refreshed every step; for the operator.
  struct Node {
    int winch = 0;
    hal::NodeStatus status;
  };
  std::vector<Node> nodes;
  int committed_seq = 0;       // store sequence number committed by the last run; 0 if none
  hal::TimeUs started_us = -1;        // monotonic start of the last run; -1 never
  hal::TimeUs state_entered_us = -1;  // when the current state was entered
  hal::TimeUs finished_us = -1;       // when the last run ended (done or failed)
  // The last run's history entry (docs/FORMATS.md "History entry of a run")
  // as the owner reports it; empty when it keeps none. Its outcome as in
  // run.toml: "running", "committed", "failed", "aborted"; empty before a run.
  std::string run_entry;
  std::string run_outcome;
  // The waypoint strategy of the run ("spread", "informative",
  // "sequential"; empty before planning), and why its waypoints ended
  // ("plan done", "target reached", "max count", "no candidates left").
  std::string strategy;
  std::string stop_reason;
  // Largest anchor-axis and offset 1-sigma [m] of the sequential strategy's
  // last re-solve, then of the run's fit; < 0 while unknown. Their targets.
  double largest_anchor_sigma_m = -1.0;
  double largest_offset_sigma_m = -1.0;
  double target_anchor_sigma_m = 0.0;
  double target_offset_sigma_m = 0.0;
  // Robot time [s] the remaining waypoints are estimated to take, as
  // estimated at time_left_at_us (the last waypoint's end); < 0 unknown.
  double time_left_s = -1.0;
  hal::TimeUs time_left_at_us = -1;
  // The model check's one-line verdict on the last run's data
  // (model_check_verdict.h), once the owner has it; empty before.
  std::string run_diagnosis;

  // Kept across runs (not reset by a start):
  std::vector<std::string> store_problems;  // what the last store check found unreadable
  bool pending_commit = false;              // a fit whose commit failed waits in <state>/pending
  // Reset by a start:
  std::string interrupted;  // "run interrupted at <time>, waypoint k of n": a daemon died mid-run
};

}  // namespace cdpr::calibration
