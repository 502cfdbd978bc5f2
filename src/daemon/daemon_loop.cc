#include "src/daemon/daemon_loop.h"

#include <poll.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <ctime>
#include <optional>
#include <vector>

#include "src/control/control_dispatch.h"

namespace cdpr::daemon {

std::string utc_now_rfc3339() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

namespace {

// The calibrator's options with what other tables know: the sequential
// strategy re-solves as the final solve does and times moves at the drives' profile speed.
calibration::CalibratorOptions calibrator_options(const DaemonConfig& config) {
  calibration::CalibratorOptions options = config.calibrator;
  options.sequential.solver = config.solver;
  options.sequential.winch_speed_mps = config.winches.drive.profile_velocity_mps;
  return options;
}

}  // namespace

DaemonLoop::DaemonLoop(const DaemonConfig& config, const Robot& robot, DaemonDevices devices,
                       store::CalibrationStore& store, const hal::Clock& clock, ServiceNotifier& notifier,
                       std::function<void(const std::string&)> log)
    : config_(config), robot_(robot), devices_(devices), store_(store), clock_(clock), notifier_(notifier),
      log_(std::move(log)), run_marker_(store.state_dir()) {
  // No SolveFunction and waypoint jobs by the owner: the loop runs the fit and
  // the waypoint planning on worker threads (manage_solve, manage_waypoint_job).
  machine_ = std::make_unique<calibration::CalibrationStateMachine>(
      robot_,
      calibration::CalibratorDevices{devices_.winches, devices_.load_cell, devices_.pose, devices_.button, store_},
      calibrator_options(config_), calibration::SolveFunction{}, utc_now_rfc3339,
      calibration::WaypointWork::kByOwner);
  constexpr double kBytesPerMb = 1e6;
  std::optional<DiagnosisOptions> model_check;
  if (config_.history.model_check) {
    model_check.emplace();
    model_check->fit = config_.solver;
  }
  recorder_ = std::make_unique<RunRecorder>(
      store_.state_dir(), static_cast<std::uintmax_t>(config_.history.budget_mb * kBytesPerMb), model_check,
      config_.solver);
  if (config_.operation.watch) watch_ = std::make_unique<WatchService>(config_, robot_, store_, log_);
  refitter_ = std::make_unique<RunRefitter>(robot_, store_.history_dir(), store_, config_.solver,
                                            config_.calibrator.validation, utc_now_rfc3339, log_);
}

DaemonLoop::~DaemonLoop() { shutdown(); }

hal::Status DaemonLoop::start() {
  auto server = ControlServer::listen(
      config_.control_socket, [this](std::string_view line) { return handle_request(line); }, kControlSocketMode,
      config_.control_socket_group);
  if (!server.ok()) return server.status();
  server_ = std::move(server.value());
  if (watch_) {
    if (hal::Status started = watch_->start(); !started.ok()) return started;
  }
  report_previous_state();
  const hal::TimeUs now_us = clock_.now_us();
  service_idle_devices(now_us);
  next_step_us_ = now_us;
  notifier_.ready();
  report(now_us);
  return hal::Status::Ok();
}

void DaemonLoop::report_previous_state() {
  const auto marker = run_marker_.read();
  std::string interrupted;
  std::string interrupted_at = utc_now_rfc3339();
  std::optional<store::RunProgress> progress;
  if (!marker) {
    interrupted = "a run was interrupted (its marker is unreadable: " + marker.error() + ")";
  } else if (*marker) {
    interrupted = describe_interrupted_run(**marker);
    interrupted_at = (*marker)->updated;
    progress = store::RunProgress{(*marker)->waypoints, (*marker)->elapsed_s};
  }
  for (const std::string& message : recorder_->recover(
           interrupted_at, interrupted.empty() ? "the daemon stopped or died during the run" : interrupted,
           progress)) {
    if (log_) log_(message);
  }
  if (!interrupted.empty()) {
    run_marker_left_over_ = true;
    machine_->note_interrupted_run(interrupted);
    if (log_) log_(interrupted);
  }
  machine_->refresh_store_problems();
  if (!log_) return;
  for (const std::string& problem : machine_->status().store_problems) log_("store: " + problem);
  if (machine_->status().pending_commit) {
    log_("store: a fit whose commit failed is kept in " + store_.state_dir() +
         "/pending; `calibctl commit` commits it once the cause is fixed");
  }
}

void DaemonLoop::track_run(hal::TimeUs now_us) {
  const calibration::CalibrationStatus& s = machine_->status();
  if (!calibration::is_running(s.state)) {
    // A marker a previous daemon left stays until a run of this one has
    // started (and ended: a start and an abort may fall between two steps).
    const bool left_over_done = run_marker_left_over_ && s.started_us >= 0;
    if (!run_marker_written_ && !left_over_done) return;
    run_marker_written_ = run_marker_left_over_ = false;
    if (const auto removed = run_marker_.remove(); !removed && log_) {
      log_("run marker: " + removed.error().message());
    }
    return;
  }
  // Once per waypoint and when the motion ends (solve): each write costs two
  // fsyncs on the loop thread, so not at every state change.
  const bool moving = machine_->owns_hardware();
  if (run_marker_written_ && s.started_us == run_marker_started_us_ && s.waypoint == run_marker_now_.waypoint &&
      moving == run_marker_moving_) {
    return;
  }
  run_marker_moving_ = moving;
  const char* state = calibration::to_string(s.state);
  const std::string now = utc_now_rfc3339();
  if (s.started_us != run_marker_started_us_) {
    run_marker_started_us_ = s.started_us;
    run_marker_now_.started = now;
  }
  run_marker_now_.updated = now;
  run_marker_now_.waypoint = s.waypoint;
  run_marker_now_.waypoints = s.waypoint_count;
  run_marker_now_.state = state;
  run_marker_now_.elapsed_s = 1e-6 * static_cast<double>(now_us - s.started_us);
  run_marker_written_ = true;  // also after a failed write: the end of the run removes what is there
  const auto written = run_marker_.write(run_marker_now_);
  if (written) return;
  // Without its marker a run that dies is not known at the next start: it stops now.
  const std::string error = "run marker: " + written.error().message();
  if (log_) log_(error);
  machine_->request_stop_for_store(now_us, error);
}

void DaemonLoop::record_run() {
  recorder_->track(*machine_, robot_, clock_.now_us());
  for (const std::string& message : recorder_->take_messages()) {
    if (log_) log_(message);
  }
}

void DaemonLoop::log_device_faults() {
  const std::string& faults = machine_->status().device_faults;
  if (faults == logged_device_faults_) return;
  if (log_) log_(faults.empty() ? std::string("device faults cleared") : "device faults: " + faults);
  logged_device_faults_ = faults;
}

std::string DaemonLoop::handle_request(std::string_view line) {
  return control::respond(line, *machine_, store_, clock_.now_us(), refitter_.get(), operation_status());
}

void DaemonLoop::run(const std::atomic<bool>& stop) {
  while (!stop.load()) run_once();
  shutdown();
}

void DaemonLoop::run_once() {
  // Serve the control socket until the next step is due.
  std::vector<pollfd> fds;
  for (;;) {
    const hal::TimeUs left_us = next_step_us_ - clock_.now_us();
    if (left_us <= 0) break;
    fds.clear();
    server_->append_poll_fds(fds);
    const int ready = poll(fds.data(), fds.size(), static_cast<int>((left_us + 999) / 1000));
    if (ready < 0 && errno == EINTR) return;  // a signal: let run() look at its flag
    if (ready > 0) server_->service(fds);
  }
  const hal::TimeUs now_us = clock_.now_us();
  // Fixed rate without drift; after a stall (a slow bus call) skip ahead.
  next_step_us_ += config_.loop_period_us;
  if (next_step_us_ < now_us) next_step_us_ = now_us + config_.loop_period_us;
  step(now_us);
}

void DaemonLoop::step(hal::TimeUs now_us) {
  if (!machine_->owns_hardware()) {
    service_idle_devices(now_us);
    if (watch_) step_watch(now_us);
  }
  machine_->step(now_us);
  manage_waypoint_job(now_us);
  manage_solve(now_us);
  manage_refit();
  track_run(now_us);
  record_run();
  log_device_faults();
  report(now_us);
  notifier_.watchdog();
}

void DaemonLoop::step_watch(hal::TimeUs now_us) {
  // A commit (a run's, `calibctl commit`, a refit) or a rollback changes what the rests are checked against.
  const int seq = machine_->status().committed_seq;
  if (seq != watched_seq_) {
    if (watched_seq_ >= 0) watch_->reload_calibration();
    watched_seq_ = seq;
  }
  watch_->step(devices_, now_us);
  if (watch_->take_pending_offered()) machine_->refresh_store_problems();  // status: pending_commit
}

void DaemonLoop::service_idle_devices(hal::TimeUs now_us) {
  if (now_us >= next_reconnect_us_) {
    next_reconnect_us_ = now_us + kReconnectIntervalUs;
    // Logged when the outcome changes, not every round.
    const auto reopen = [&](bool& open, std::string& last_error, const char* name, auto&& open_device,
                            const char* opened = " connected") {
      if (open) return;
      const hal::Status status = open_device();
      open = status.ok();
      if (open) {
        last_error.clear();
        if (log_) log_(std::string(name) + opened);
      } else if (status.to_string() != last_error) {
        last_error = status.to_string();
        if (log_) log_(std::string(name) + " not available (retrying): " + last_error);
      }
    };
    reopen(winches_open_, winches_error_, "winches", [&] { return devices_.winches.open(); });
    // The load cell's open() starts its reader and connects: it has not answered yet.
    reopen(load_cell_open_, load_cell_error_, "load cell", [&] { return devices_.load_cell.open(); },
           " opened (not answered yet)");
    if (load_cell_open_) note_load_cell_answer();
    reopen(pose_open_, pose_error_, "pose stream", [&] { return devices_.pose.open(); });
  }
  // Keep the bus and the pose stream drained so a start sees fresh data; a
  // lost connection is reopened above on the next reconnect round.
  if (winches_open_) {
    const hal::Status status = devices_.winches.update(now_us);
    if (status.code() == hal::ErrorCode::kNotConnected) {
      devices_.winches.close();
      winches_open_ = false;
    }
  }
  if (pose_open_) {
    const hal::Status status = devices_.pose.update(0);
    if (status.code() == hal::ErrorCode::kNotConnected) {
      devices_.pose.close();
      pose_open_ = false;
    }
  }
}

void DaemonLoop::note_load_cell_answer() {
  if (load_cell_answered_) return;
  // A non-blocking read (drivers/common/load_cell_reader.h): its first reading, or why none came.
  const hal::Result<hal::TensionSample> reading = devices_.load_cell.read();
  if (reading.ok()) {
    load_cell_answered_ = true;
    load_cell_error_.clear();
    if (log_) log_("load cell answering: " + std::to_string(static_cast<int>(std::lround(reading.value().tension_n))) + " N");
    return;
  }
  if (reading.status().to_string() == load_cell_error_) return;
  load_cell_error_ = reading.status().to_string();
  if (log_) log_("load cell not answering: " + load_cell_error_);
}

void DaemonLoop::manage_solve(hal::TimeUs now_us) {
  if (solving_) {
    if (solve_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    solving_ = false;
    machine_->deliver_solve_result(solve_.get(), now_us);
    return;
  }
  if (!machine_->solve_pending()) return;
  if (log_) log_("solving with " + std::to_string(machine_->samples().size()) + " samples");
  solving_ = true;
  // Copies: the worker must not share anything with the loop thread.
  solve_ = std::async(std::launch::async, [robot = robot_, samples = machine_->samples(), options = config_.solver] {
    return calibrate(robot, samples, options);
  });
}

void DaemonLoop::manage_waypoint_job(hal::TimeUs now_us) {
  if (waypoint_job_.valid()) {
    if (waypoint_job_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    // Dropped by the machine when its run ended meanwhile.
    machine_->deliver_waypoint_job(waypoint_job_.get(), now_us);
  }
  if (!machine_->waypoint_job_pending()) return;
  // The job owns the run's waypoints and copies of its inputs: nothing shared.
  waypoint_job_ = std::async(std::launch::async, [job = machine_->take_waypoint_job()]() mutable {
    job.run();
    return std::move(job);
  });
}

void DaemonLoop::manage_refit() {
  if (!refitter_->poll(calibration::is_running(machine_->status().state))) return;
  std::optional<CommittedRefit> committed = refitter_->take_committed();
  if (!committed) return;
  // The headline says what is current now, not the last run's end.
  machine_->note_commit(committed->seq,
                        "by the refit of " + store::RunHistory::entry_name(committed->source_log.run) +
                            " with the terms " + committed->terms + " (operator's choice)",
                        clock_.now_us());
  refitter_->note_entry(recorder_->keep_refit(std::move(*committed)));
}

void DaemonLoop::report(hal::TimeUs /*now_us*/) {
  const calibration::CalibrationStatus& s = machine_->status();
  std::string text = calibration::to_string(s.state);
  if (s.waypoint_count > 0 && calibration::is_running(s.state)) {
    text += " " + std::to_string(s.waypoint) + "/" + std::to_string(s.waypoint_count);
  }
  text += " (" + std::to_string(static_cast<int>(std::lround(100.0 * s.progress))) + "%)";
  if (!s.reason.empty() && !calibration::is_running(s.state)) text += ": " + s.reason;
  if (text == last_report_) return;
  last_report_ = text;
  notifier_.status(text);
  if (log_) log_(text);
}

void DaemonLoop::shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  notifier_.stopping();
  const hal::TimeUs now_us = clock_.now_us();
  if (calibration::is_running(machine_->status().state)) {
    machine_->request_abort(now_us, "daemon stopping");
    machine_->step(now_us);
  }
  record_run();
  recorder_->finish();
  for (const std::string& message : recorder_->take_messages()) {
    if (log_) log_(message);
  }
  if (winches_open_ && !watch_) {
    // Stop every winch whatever the machine did: the daemon will not watch them any more.
    const hal::Status stopped = devices_.winches.quick_stop();
    if (!stopped.ok() && log_) log_("quick stop failed: " + stopped.to_string());
    (void)devices_.winches.update(clock_.now_us());
  }
  if (solving_) solve_.wait();  // a fit in progress finishes; its result is dropped
  if (waypoint_job_.valid()) machine_->deliver_waypoint_job(waypoint_job_.get(), now_us);  // dropped: the run ended
  devices_.winches.close();
  devices_.load_cell.close();
  devices_.pose.close();
  winches_open_ = load_cell_open_ = pose_open_ = false;
  server_.reset();
  if (log_) log_(watch_ ? "stopped: devices closed (watch mode: the drives stay the controller's)"
                        : "stopped: winches quick-stopped, devices closed");
}

}  // namespace cdpr::daemon
