#pragma once
// The one-button field calibration (docs/DESIGN.md "Data flow"), as an explicit
// state machine driven by step(now_us): pure logic with time passed in; all
// I/O goes through the hal interfaces and the store.
//
//   idle/done/failed/aborted --start--> preflight -> plan -> { move -> settle -> sample }xN
//     -> solve -> validate -> commit -> done
//   any fault, or a store write the owner saw fail, while running -> abort -> failed
//   an abort request while running -> abort -> aborted
//
// preflight  the store proves it can write at the run's first step (a run
//            it could not commit is not started); every winch alive, pose fresh and valid, load cell
//            answering and the tension inside its limits. The drives stay
//            disabled.
// plan       the waypoints (waypoint_sequence.h) with the current
//            calibration's anchors when one exists, else the nominal ones: a
//            fixed plan (spread, informative) or the sequential strategy's
//            candidates; an infeasible plan fails the run. Planned by a
//            waypoint job (below; status().detail "planning") from the pose
//            and the encoder payouts, which the devices report with the
//            drives disabled. Encoder offsets for the payout targets: the
//            current calibration's, else estimated at the start pose
//            (waypoint_planner.h) from the mean of the detector's rest
//            window once it is covered and still (status().detail
//            "measuring the start pose"; after settle_timeout_us the
//            window's mean, noted). Then the drives are enabled and the
//            machine waits for operation enabled (enable_timeout_us;
//            "enabling drives"). Enabled only once the plan exists: no drive
//            holds torque while the plan is worked out or when there is none,
//            and a stall of the planning cannot quick-stop a powered drive.
// move       payout targets sent; waits for motion_finished() (move_timeout_us
//            is a fault: a winch is stuck).
// settle     EquilibriumDetector on every new pose; settle_timeout_us without
//            equilibrium skips the waypoint (noted), it is not a fault.
// sample     the window's average becomes one sample row. The sequential
//            strategy re-solves with the rows so far and picks the next
//            waypoint in a waypoint job (status().detail "choosing the next
//            waypoint"; a skip in settle does the same); when its stop rule
//            ends the waypoints, the run goes on to solve.
// solve      after the last waypoint the winches are halted (hold). With a
//            SolveFunction the solve runs inside step(); without, the owner
//            polls solve_pending(), runs calibrate() on samples() wherever it
//            likes (a worker thread) and hands the result to
//            deliver_solve_result().
// validate   validate_fit() against the current calibration (an unreadable
//            current file: the newest readable history version); then `created`
//            (from utc_now_text), `robot` and `samples` are filled in; the
//            model terms are the solver's.
// commit     CalibrationStore::commit(); a store error fails the run and the
//            store guarantees the old file is intact. The fit and its
//            samples are then kept in <state>/pending (pending_calibration.h)
//            and the fit in memory (when pending/ cannot be written either,
//            on the same full disk) for a later `commit` request
//            (request_commit_kept()), so the run's work is not lost.
// abort      quick stop for a fault, halt (decelerate and hold) for an abort
//            request; the reason goes to status().reason and, as the latest
//            remark, to status().note.
//
// Waypoint jobs (waypoint_job.h): planning and choosing the next waypoint
// can take seconds (a large candidate grid, the robust stages of a re-solve
// working through a gross error). With WaypointWork::kInline they run inside
// step(). With kByOwner the owner takes the job (waypoint_job_pending(),
// take_waypoint_job()), runs it wherever it likes (a worker thread) and
// hands it back (deliver_waypoint_job()); meanwhile step() goes on polling
// the hardware and checking for faults, and status and current_waypoint()
// show what they showed when the job left (plan() is empty meanwhile). A
// fault or an abort meanwhile ends the run as ever, and the job delivered
// later is dropped (the run does not go on; plan() shows the waypoints
// again); a new run does not start before the job is back.
//
// Every run is logged in run_log() (docs/FORMATS.md "run.toml"): start and
// end (utc_now_text), robot time, every waypoint sampled or skipped and why,
// faults and the outcome; the owner keeps it with samples() in the history.
//
// While running (preflight .. sample) every step polls the hardware once
// (HardwareMonitor: winch update, pose update, one load-cell read) and any
// fault aborts; owns_hardware() says so, and the owner must not poll the
// devices itself then. Otherwise (idle, solve .. done/failed) the machine
// does not touch the devices: the owner may keep the bus serviced
// (WinchBank::update) for diagnostics. After a run the drives stay enabled
// and halted (holding); disabling them is the owner's choice. A start request (button or control
// socket) while running is ignored with a note, never a restart.
// Not thread-safe: step(), request_*() and deliver_solve_result() from one thread.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hal/button.h"
#include "solver/calibration/calibrate.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"
#include "src/calibration/calibration_state.h"
#include "src/calibration/equilibrium_detector.h"
#include "src/calibration/fit_validation.h"
#include "src/calibration/given_waypoints.h"
#include "src/calibration/hardware_monitor.h"
#include "src/calibration/waypoint_job.h"
#include "src/calibration/waypoint_planner.h"
#include "src/calibration/waypoint_sequence.h"
#include "src/formats/run_log_toml.h"
#include "src/store/calibration_store.h"

namespace cdpr::calibration {

// The equilibrium detector's ring size: the 40 s sway window at a 100 Hz
// pose source, with margin (the daemon's [equilibrium] capacity default).
inline constexpr std::size_t kEquilibriumCapacity = 4096;

struct CalibratorOptions {
  PlannerOptions planner;
  WaypointStrategy strategy = WaypointStrategy::kSpread;
  // The sequential strategy's targets, max_count and time model; its
  // min_count is validation.min_samples, so that a run it stops can be accepted.
  SequentialOptions sequential;
  EquilibriumThresholds equilibrium;
  std::size_t equilibrium_capacity = kEquilibriumCapacity;  // >= window x pose rate, with margin
  ValidationLimits validation;
  MonitorLimits monitor;
  // Preflight waits this long for the first word from every device (a node's
  // heartbeat, a pose, a load-cell reading) before calling one missing a
  // fault: a button pressed just after the daemon or a sensor started.
  hal::TimeUs first_contact_timeout_us = 3'000'000;
  hal::TimeUs enable_timeout_us = 5'000'000;  // from the enable command
  hal::TimeUs move_timeout_us = 600'000'000;
  hal::TimeUs settle_timeout_us = 60'000'000;
};

using SolveFunction = std::function<CalibrationResult(const Robot&, const std::vector<Sample>&)>;

// A SolveFunction calling solver/calibration/calibrate.h with `options`.
SolveFunction make_solver_function(CalibrationOptions options);

struct CalibratorDevices {
  hal::WinchBank& winches;  // opened by the owner before the first step
  hal::LoadCell& load_cell;
  hal::PoseSource& pose;
  hal::Button* button = nullptr;  // may be null: starts only by request_start()
  store::CalibrationStore& store;  // opened by the owner
};

class CalibrationStateMachine {
 public:
  // `utc_now_text` gives calibration.toml's `created` (RFC 3339 UTC); the
  // state machine never reads a clock itself. `solve` may be empty and
  // `waypoint_work` says where the waypoint jobs run (see above).
  CalibrationStateMachine(const Robot& robot, CalibratorDevices devices, CalibratorOptions options,
                          SolveFunction solve, std::function<std::string()> utc_now_text,
                          WaypointWork waypoint_work = WaypointWork::kInline);

  // Advances the machine; call periodically (e.g. every 20 ms) with monotonic time.
  void step(hal::TimeUs now_us);

  // Starts a run when not running; otherwise ignored with a note. Returns
  // whether a run was started. Same effect as a button press. With `given`
  // the run drives exactly those waypoints instead of a plan (its strategy
  // "given"), with the same preflight, limits, equilibrium wait, validation
  // and stops as a planned run, and its samples begin with
  // given->earlier_samples. Refused (note says why) when they are more than
  // kMaxGivenWaypoints or one lies outside the planner's workspace box; the
  // rest of the planner's checks (a rest within the tension band, the sag
  // and travel limits, on the anchors and offsets the run plans with) come
  // in plan, where the first waypoint that fails them fails the run before
  // the drives are enabled.
  bool request_start(hal::TimeUs now_us, std::optional<GivenWaypoints> given = std::nullopt);
  // Aborts a run in progress (winches halted, old calibration kept). Returns
  // false (and notes it) when nothing is running.
  // The operator's request to clear the devices' latched faults (calibctl
  // reset-faults). Refused (false, note says why) while a run is going.
  bool request_reset_faults(hal::TimeUs now_us);
  bool request_abort(hal::TimeUs now_us, const std::string& why = "abort requested");
  // A write the run's record depends on failed (its history entry, the run
  // marker; `why` names the path and errno): the run stops at once as for
  // an abort (winches halted, old calibration kept) and ends "failed". A
  // validated fit is kept as after a failed commit. False when no run is going.
  bool request_stop_for_store(hal::TimeUs now_us, const std::string& why);
  // The operator's `commit`: commits the fit whose commit failed, from
  // memory when this daemon holds it (it does until the fit is committed or
  // a newer run's fit replaces it, also when pending/ could not be written),
  // else from pending/ (pending_calibration.h). Refused while running, or
  // when nothing is kept (the note says why, with the last run's end).
  // Success: state done, reason and note say what was committed.
  bool request_commit_kept(hal::TimeUs now_us);
  // The owner committed calibration `seq` outside a run (an operator's
  // refit, `what` says which): the status says so (state done) instead of
  // the last run's end. Ignored while a run is going.
  void note_commit(int seq, const std::string& what, hal::TimeUs now_us);

  // Asynchronous solve (no SolveFunction given).
  bool solve_pending() const;
  const std::vector<Sample>& samples() const { return samples_; }
  void deliver_solve_result(CalibrationResult result, hal::TimeUs now_us);

  // Waypoint jobs handed to the owner (WaypointWork::kByOwner). A job
  // delivered after its run ended does not go on with the run.
  bool waypoint_job_pending() const { return job_.has_value(); }
  WaypointJob take_waypoint_job();
  void deliver_waypoint_job(WaypointJob job, hal::TimeUs now_us);
  // A job was taken and is not back yet.
  bool waypoint_job_out() const { return job_out_; }

  // True while step() polls the devices (preflight .. sample).
  bool owns_hardware() const;

  // Checks the stored files again (CalibrationStore::problems(), a pending
  // commit) into status().store_problems and pending_commit. Done at the end
  // of every run; the owner calls it at start-up and after it changed the
  // store (rollback, commit of the pending fit).
  void refresh_store_problems();
  // Reports a run that a previous daemon did not finish (status().interrupted),
  // until the next start.
  void note_interrupted_run(std::string text) { status_.interrupted = std::move(text); }
  // The owner names the history entry that keeps the current run's data
  // (status().run_entry); empty when it could not make one.
  void note_run_entry(std::string path) { status_.run_entry = std::move(path); }
  // The owner's model check of the last run's data (status().run_diagnosis).
  void note_run_diagnosis(std::string verdict) { status_.run_diagnosis = std::move(verdict); }

  // The current or last run's log; `run` is the owner's to fill in.
  const formats::RunLog& run_log() const { return run_log_; }
  // The fit of the current or last run once validation accepted it, with
  // created/robot/samples filled in; null before that and after a refusal.
  const Calibration* validated_fit() const { return fit_validated_ ? &solve_result_->calibration : nullptr; }
  // The whole result behind validated_fit() (covariance, rejected readings), for its report.
  const CalibrationResult* validated_result() const { return fit_validated_ ? &*solve_result_ : nullptr; }

  const CalibrationStatus& status() const { return status_; }
  // The nominal robot the runs calibrate.
  const Robot& robot() const { return robot_; }
  // The fixed plan's waypoints in travel order, or the sequential strategy's
  // candidates; empty while a waypoint job is away.
  const WaypointPlan& plan() const { return waypoints_.plan(); }
  // The waypoint being worked on (move .. sample); null otherwise.
  const Waypoint* current_waypoint() const;

 private:
  void enter(CalibrationState state, hal::TimeUs now_us);
  // Ends the run in `end` (kFailed, or kAborted for an abort request).
  void fail(const std::string& reason, hal::TimeUs now_us, bool fault, CalibrationState end = CalibrationState::kFailed);
  void poll_button(hal::TimeUs now_us);
  // Why `given` cannot start a run (count, workspace box); empty when it can.
  std::string given_waypoints_problem(const GivenWaypoints& given) const;
  // status().device_faults from the winch bank's latched faults.
  void refresh_device_faults();
  // status().nodes from the winch bank (sized once; no allocation after).
  void refresh_nodes();
  void run_preflight(hal::TimeUs now_us);
  void run_plan(hal::TimeUs now_us);
  // The mean pose and encoders of the platform at rest before the first
  // move, for the offset estimate without a previous calibration: once the
  // rest window is covered and still (or settled), or after
  // settle_timeout_us with a note; nullopt while gathering (or failed).
  std::optional<Sample> start_rest(hal::TimeUs now_us);
  // Adds the current readings to the detector when a new pose came in.
  void observe_rest();
  // Commands the drives on, then waits for them (enable_timeout_us) and moves on.
  void enable_drives(hal::TimeUs now_us);
  void run_move(hal::TimeUs now_us);
  void run_settle(hal::TimeUs now_us);
  void run_sample(hal::TimeUs now_us);
  void next_waypoint(hal::TimeUs now_us);
  // What the run does once a waypoint job is back.
  enum class AfterJob { kNone, kPlanned, kSampled, kSkipped };
  // Moves the waypoints into a job running `work`: inline, or for the owner.
  void begin_job(AfterJob after, std::function<std::string(WaypointSequence&)> work, hal::TimeUs now_us);
  void finish_job(WaypointJob job, hal::TimeUs now_us);
  void after_plan(const std::string& problem, hal::TimeUs now_us);
  void after_sample(hal::TimeUs now_us);
  void run_solve(hal::TimeUs now_us);
  void run_validate_and_commit(hal::TimeUs now_us);
  // Keeps a fit whose commit failed in <state>/pending; the sentence for the reason.
  std::string keep_pending(const Calibration& calibration) const;
  void update_progress();
  // The run's strategy, sigmas and time left into the status and the run log.
  void update_waypoint_status();
  // run_log_ at now_us: robot time, and the outcome into the status too.
  void log_run(hal::TimeUs now_us, const char* outcome = nullptr);
  double run_seconds(hal::TimeUs now_us) const;

  const Robot robot_;
  CalibratorDevices devices_;
  CalibratorOptions options_;
  SolveFunction solve_;
  std::function<std::string()> utc_now_text_;
  WaypointWork waypoint_work_;
  HardwareMonitor monitor_;
  EquilibriumDetector detector_;

  CalibrationStatus status_;
  // Per run:
  std::optional<hal::TimeUs> enable_sent_us_;  // when the drives were commanded on (the plan exists)
  bool store_probed_ = false;                  // at the run's first step (preflight)
  std::optional<store::CurrentCalibration> previous_;
  std::optional<GivenWaypoints> given_;  // the run's waypoints when given (positions; rows moved to samples_)
  WaypointSequence waypoints_;
  std::optional<WaypointJob> job_;       // begun, not taken yet (kByOwner)
  bool job_out_ = false;                 // taken, not delivered yet (outlives its run)
  AfterJob after_job_ = AfterJob::kNone;  // a job of this run is away
  hal::TimeUs job_begun_us_ = 0;
  std::optional<Waypoint> job_waypoint_;  // current_waypoint() while the job is away
  bool targets_sent_ = false;
  std::vector<Sample> samples_;
  std::optional<CalibrationResult> solve_result_;
  bool fit_validated_ = false;
  formats::RunLog run_log_;
  // Across runs: the newest validated fit that was not committed (see request_commit_kept).
  std::optional<Calibration> kept_fit_;
};

}  // namespace cdpr::calibration
