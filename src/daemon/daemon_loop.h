#pragma once
// cdpr-calibd's event loop: the OS wiring around the pure state machine
// (docs/STYLE.md: logic apart from the module wrapper, as PX4's
// mc_att_control beside its module).
//
// Every period (config [loop] period_ms) it
//   - serves the control socket in between (poll() with the time left to
//     the next step as timeout, so a request is answered at once),
//   - steps the CalibrationStateMachine with monotonic time (hal::Clock),
//   - runs the solve on a worker thread when the machine asks for it, so
//     the loop, the socket and the watchdog stay alive during a long fit,
//   - runs the machine's waypoint jobs (planning, the sequential strategy's
//     re-solve and choice of the next waypoint) on a worker thread too: the
//     drives are enabled during the re-solves, and the machine's step keeps
//     polling them (the CANopen master's heartbeat goes out in the winch
//     bank's update; the drives quick-stop when it pauses for
//     consumer_heartbeat_ms), the pose and the load cell and keeps checking
//     for faults,
//   - when the machine does not own the devices: keeps the CAN bus and the
//     pose stream drained and reconnects devices that are not open (every
//     kReconnectIntervalUs), so a start finds fresh data,
//   - keeps the run marker (run_marker.h) while a run is in progress, and
//     at start reports a run a previous daemon left unfinished and what in
//     the store is unreadable (log and status),
//   - keeps every run's data in the history (run_recorder.h; written on a
//     thread of its own, within [history] budget_mb; the model check after
//     each solve runs there too),
//   - refits a kept run with an extra model term when the operator asks
//     (run_refitter.h: the `refit` request, on a worker of its own), and
//     keeps a committed refit in the history with its report,
//   - reports READY, STATUS and WATCHDOG through the ServiceNotifier.
// shutdown() stops the winches (abort a run: halt; then quick stop) and
// closes the devices; the owner calls it on SIGTERM and exits 0.
//
// Ownership: devices, store and clock are the owner's and must outlive the
// loop; the loop opens and closes the devices. Not thread-safe apart from
// the internal solve and waypoint threads, which get copies (or the moved
// WaypointSequence) and share nothing with the loop; one thread calls everything.

#include <atomic>
#include <functional>
#include <future>
#include <memory>
#include <string>

#include "hal/button.h"
#include "hal/clock.h"
#include "hal/load_cell.h"
#include "hal/pose_source.h"
#include "hal/winch_bank.h"
#include "solver/model/robot.h"
#include "src/calibration/calibration_state_machine.h"
#include "src/daemon/control_server.h"
#include "src/daemon/daemon_config.h"
#include "src/daemon/run_marker.h"
#include "src/daemon/run_recorder.h"
#include "src/daemon/run_refitter.h"
#include "src/daemon/watch_service.h"
#include "src/store/calibration_store.h"

namespace cdpr::daemon {

// The service manager (systemd's sd_notify in main(); a no-op or a recorder
// in tests). Calls come from the loop thread.
class ServiceNotifier {
 public:
  virtual ~ServiceNotifier() = default;
  virtual void ready() = 0;
  virtual void status(const std::string& text) = 0;
  // Called every step; the implementation decides how often to really ping.
  virtual void watchdog() = 0;
  virtual void stopping() = 0;
};

struct DaemonDevices {
  hal::WinchBank& winches;
  hal::LoadCell& load_cell;
  hal::PoseSource& pose;
  hal::Button* button = nullptr;  // null: start only from the control socket
};

class DaemonLoop {
 public:
  static constexpr hal::TimeUs kReconnectIntervalUs = 2'000'000;
  // Owner and group ([control] group) may connect; nobody else.
  static constexpr unsigned kControlSocketMode = 0660;

  // `log` receives one line per event (state changes, device errors); may be empty.
  DaemonLoop(const DaemonConfig& config, const Robot& robot, DaemonDevices devices, store::CalibrationStore& store,
             const hal::Clock& clock, ServiceNotifier& notifier, std::function<void(const std::string&)> log);
  ~DaemonLoop();

  // Opens the control socket and (best effort: failures are logged and
  // retried) the devices, then notifies READY. Errors: the control socket
  // could not be created (the daemon cannot be controlled: exit non-zero).
  hal::Status start();
  // One iteration: serve the socket until the next step is due, then step.
  void run_once();
  // run_once() until `stop` is set (by a signal handler), then shutdown().
  void run(const std::atomic<bool>& stop);
  // Stops the winches and closes everything (idempotent).
  void shutdown();

  const calibration::CalibrationStateMachine& machine() const { return *machine_; }
  // Waits until the run's data queued so far is on disk (tests).
  void wait_for_history() { recorder_->wait_idle(); }
  // Watch mode's status ([operation] watch); null when not watching.
  const operation::OperationStatus* operation_status() const { return watch_ ? &watch_->status() : nullptr; }

 private:
  void step(hal::TimeUs now_us);
  void service_idle_devices(hal::TimeUs now_us);
  // Watch mode: the watch's step, with the calibration read again when the committed one changed.
  void step_watch(hal::TimeUs now_us);
  // Idle: logs the load cell's first reading, or each new reason why none came.
  void note_load_cell_answer();
  void manage_solve(hal::TimeUs now_us);
  // Runs the machine's waypoint job on a worker and delivers it back.
  void manage_waypoint_job(hal::TimeUs now_us);
  // A refit's result taken, logged and, when committed, kept in the history.
  void manage_refit();
  void report(hal::TimeUs now_us);
  std::string handle_request(std::string_view line);
  // Start-up: a run marker left by a daemon that died mid-run, and the
  // store's problems, logged and put into the status.
  void report_previous_state();
  // Keeps the run marker (run_marker.h) in step with the machine's run.
  // A failed write stops the run (the next start could not report it).
  void track_run(hal::TimeUs now_us);
  // Logs the devices' latched faults (EMCY, 0x603F, a refused
  // configuration) when they appear, change or are reset.
  void log_device_faults();
  // The run recorder's queued writes for this step, and its failures logged.
  void record_run();

  DaemonConfig config_;
  Robot robot_;
  DaemonDevices devices_;
  store::CalibrationStore& store_;
  const hal::Clock& clock_;
  ServiceNotifier& notifier_;
  std::function<void(const std::string&)> log_;
  std::unique_ptr<calibration::CalibrationStateMachine> machine_;
  std::unique_ptr<ControlServer> server_;
  std::unique_ptr<RunRecorder> recorder_;
  std::unique_ptr<RunRefitter> refitter_;
  std::unique_ptr<WatchService> watch_;  // [operation] watch only
  int watched_seq_ = -1;                 // the committed seq the watch last read
  std::future<CalibrationResult> solve_;
  bool solving_ = false;
  std::future<calibration::WaypointJob> waypoint_job_;  // valid while a job is on the worker

  bool winches_open_ = false, load_cell_open_ = false, pose_open_ = false;
  bool load_cell_answered_ = false;  // a reading came since the daemon started
  std::string winches_error_, load_cell_error_, pose_error_;  // last logged open failure
  hal::TimeUs next_reconnect_us_ = 0;
  hal::TimeUs next_step_us_ = 0;
  bool shut_down_ = false;
  std::string last_report_;

  RunMarkerFile run_marker_;
  bool run_marker_written_ = false;
  bool run_marker_left_over_ = false;  // found at start-up, from a daemon that died mid-run
  bool run_marker_moving_ = false;     // the marker was written while the machine owned the hardware
  RunMarker run_marker_now_;
  hal::TimeUs run_marker_started_us_ = -1;  // monotonic start of the run the marker describes
  std::string logged_device_faults_;        // as last logged
};

// RFC 3339 UTC time of the wall clock ("2026-11-22T10:15:00Z") for the
// `created` key of calibration.toml.
std::string utc_now_rfc3339();

}  // namespace cdpr::daemon
