#include "src/calibration/calibration_state_machine.h"

#include <algorithm>
#include <utility>

#include "src/calibration/message_text.h"
#include "src/formats/samples_csv.h"
#include "src/store/pending_calibration.h"

namespace cdpr::calibration {
namespace {

std::string seconds(hal::TimeUs duration_us) { return significant(1e-6 * static_cast<double>(duration_us), 3) + " s"; }

// The equilibrium detector's verdict and figures, for the status line.
std::string rest_detail(const EquilibriumCheck& check) {
  return std::string(to_string(check.verdict)) + ": speed " + significant(1e3 * check.speed_mps, 3) + " mm/s, rate " +
         significant(1e3 * check.angular_rate_radps, 3) + " mrad/s, tension std " + significant(check.tension_std_n, 3) +
         " N, " + std::to_string(check.samples) + " poses";
}

// At a waypoint (moving to it, settling, sampling): the drives were enabled
// before the first move and stay so until the run ends.
bool at_waypoint(CalibrationState state) {
  return state == CalibrationState::kMove || state == CalibrationState::kSettle || state == CalibrationState::kSample;
}

constexpr const char* kKeptInMemory =
    "the fit is kept in memory until the daemon stops: fix the cause, then `calibctl commit`";

bool in_motion_phase(CalibrationState state) {
  return state == CalibrationState::kPreflight || state == CalibrationState::kPlan || at_waypoint(state);
}

}  // namespace

SolveFunction make_solver_function(CalibrationOptions options) {
  return [options = std::move(options)](const Robot& robot, const std::vector<Sample>& samples) {
    return calibrate(robot, samples, options);
  };
}

CalibrationStateMachine::CalibrationStateMachine(const Robot& robot, CalibratorDevices devices,
                                                 CalibratorOptions options, SolveFunction solve,
                                                 std::function<std::string()> utc_now_text,
                                                 WaypointWork waypoint_work)
    : robot_(robot),
      devices_(devices),
      options_(std::move(options)),
      solve_(std::move(solve)),
      utc_now_text_(std::move(utc_now_text)),
      waypoint_work_(waypoint_work),
      monitor_(devices.winches, devices.load_cell, devices.pose, options_.monitor),
      detector_(options_.equilibrium, options_.equilibrium_capacity) {}

void CalibrationStateMachine::enter(CalibrationState state, hal::TimeUs now_us) {
  status_.state = state;
  status_.state_entered_us = now_us;
  status_.detail.clear();
}

bool CalibrationStateMachine::request_start(hal::TimeUs now_us, std::optional<GivenWaypoints> given) {
  if (is_running(status_.state)) {
    status_.note = std::string("start ignored: a calibration is already running (") + to_string(status_.state) +
                   (status_.waypoint_count > 0
                        ? ", waypoint " + std::to_string(status_.waypoint) + "/" + std::to_string(status_.waypoint_count)
                        : std::string()) +
                   ")";
    return false;
  }
  if (job_out_) {
    // Its result would land in the new run: wait until the worker is done.
    status_.note = "start refused: the last run's waypoint planning is still finishing, try again";
    return false;
  }
  if (given) {
    if (const std::string why = given_waypoints_problem(*given); !why.empty()) {
      status_.note = "start refused: " + why;
      return false;
    }
  }
  CalibrationStatus fresh;
  fresh.store_problems = std::move(status_.store_problems);
  fresh.pending_commit = status_.pending_commit;
  status_ = std::move(fresh);
  status_.started_us = now_us;
  status_.note = "started";
  enable_sent_us_.reset();
  store_probed_ = false;
  previous_.reset();
  waypoints_ = WaypointSequence{};
  job_.reset();
  after_job_ = AfterJob::kNone;
  job_waypoint_.reset();
  samples_.clear();
  given_ = std::move(given);
  if (given_) {
    // The earlier run's rows first: the fit and the run's samples.csv hold them and the new poses.
    samples_ = std::move(given_->earlier_samples);
    given_->earlier_samples.clear();
    given_->earlier_rows = samples_.size();
  }
  solve_result_.reset();
  fit_validated_ = false;
  monitor_.reset();
  detector_.reset();
  run_log_ = formats::RunLog{};
  run_log_.robot = robot_.name;
  if (utc_now_text_) run_log_.started = utc_now_text_();
  if (given_) {
    run_log_.extends = given_->earlier_run;
    status_.samples = run_log_.samples = static_cast<int>(samples_.size());
    status_.note = "started: " + std::to_string(given_->positions_world.size()) + " waypoints from " + given_->source +
                   (given_->earlier_run > 0 ? " after the " + std::to_string(samples_.size()) + " samples of run " +
                                                  std::to_string(given_->earlier_run)
                                            : std::string());
  }
  log_run(now_us, formats::kRunRunning);
  enter(CalibrationState::kPreflight, now_us);
  update_progress();
  return true;
}

std::string CalibrationStateMachine::given_waypoints_problem(const GivenWaypoints& given) const {
  const std::size_t count = given.positions_world.size();
  if (count == 0) return given.source + " has no waypoints";
  if (count > kMaxGivenWaypoints) {
    return given.source + " has " + std::to_string(count) + " waypoints, at most " +
           std::to_string(kMaxGivenWaypoints) + " are taken";
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (const std::string why = outside_workspace(robot_, given.positions_world[k], options_.planner); !why.empty()) {
      return given.source + " waypoint " + std::to_string(k + 1) + " of " + std::to_string(count) + ": " + why;
    }
  }
  return {};
}

bool CalibrationStateMachine::request_reset_faults(hal::TimeUs now_us) {
  (void)now_us;
  if (is_running(status_.state)) {
    status_.note = "reset-faults refused: a calibration is running (abort it first)";
    return false;
  }
  if (const hal::Status s = devices_.winches.reset_faults(); !s.ok()) {
    status_.note = "reset-faults failed: " + s.to_string();
    return false;
  }
  status_.note = "faults reset" + (status_.device_faults.empty() ? std::string(" (there were none)")
                                                                  : " (were: " + status_.device_faults + ")");
  status_.device_faults.clear();
  return true;
}

void CalibrationStateMachine::refresh_device_faults() {
  // Cheap flags first: the texts are built only while a fault is there.
  bool any = false;
  for (int i = 0; i < devices_.winches.winch_count(); ++i) {
    const hal::WinchStatus s = devices_.winches.status(i);
    any = any || s.fault || s.drive == hal::DriveState::kFault;
  }
  if (!any) {
    if (!status_.device_faults.empty()) status_.device_faults.clear();
    return;
  }
  std::string faults;
  for (int i = 0; i < devices_.winches.winch_count(); ++i) {
    const hal::WinchStatus s = devices_.winches.status(i);
    if (!s.fault && s.drive != hal::DriveState::kFault) continue;
    const std::string text = devices_.winches.fault_text(i);
    faults += (faults.empty() ? "" : "; ") + std::string("winch ") + std::to_string(i) + ": " +
              (text.empty() ? std::string("drive fault") : text);
  }
  if (faults != status_.device_faults) status_.device_faults = std::move(faults);
}

void CalibrationStateMachine::refresh_nodes() {
  std::size_t n = 0;
  for (int i = 0; i < devices_.winches.winch_count(); ++i) {
    for (int k = 0; k < devices_.winches.node_count(i); ++k, ++n) {
      if (status_.nodes.size() <= n) status_.nodes.emplace_back();
      status_.nodes[n] = {i, devices_.winches.node_status(i, k)};
    }
  }
  status_.nodes.resize(n);
}

bool CalibrationStateMachine::request_abort(hal::TimeUs now_us, const std::string& why) {
  if (!is_running(status_.state)) {
    status_.note = "abort ignored: no calibration running";
    return false;
  }
  fail(why, now_us, false, CalibrationState::kAborted);
  return true;
}

bool CalibrationStateMachine::request_stop_for_store(hal::TimeUs now_us, const std::string& why) {
  if (!is_running(status_.state)) return false;
  std::string reason = "store: " + why + ": the run's data cannot be kept";
  if (fit_validated_) {
    // As after a failed commit: in pending/ where it can be written, in memory anyway.
    kept_fit_ = solve_result_->calibration;
    reason += keep_pending(*kept_fit_);
  }
  fail(reason, now_us, false);
  return true;
}

bool CalibrationStateMachine::request_commit_kept(hal::TimeUs now_us) {
  if (is_running(status_.state)) {
    status_.note = "commit refused: a calibration is running";
    return false;
  }
  const store::PendingCalibration pending(devices_.store.state_dir());
  std::string source;
  std::optional<store::StoreResult<int>> committed;
  if (kept_fit_) {
    // The newest kept fit: pending/ holds the same one, or none when it could not be written.
    source = "memory";
    committed = devices_.store.commit(*kept_fit_);
    if (*committed) {
      kept_fit_.reset();
      (void)pending.remove();  // the same fit, or none: a leftover is reported by refresh_store_problems()
    }
  } else if (pending.exists()) {
    source = pending.dir();
    committed = pending.commit_into(devices_.store);
  } else {
    status_.note = "nothing to commit: no fit is kept in " + pending.dir() + " nor in memory";
    if (status_.started_us >= 0 && !is_running(status_.state)) {
      status_.note += std::string(" (the last run: ") + to_string(status_.state) + ": " + status_.reason + ")";
    }
    return false;
  }
  refresh_store_problems();
  if (!*committed) {
    status_.note = "commit of the fit kept in " + source + " failed again: " + committed->error().message();
    return false;
  }
  note_commit(**committed, "from " + source, now_us);
  return true;
}

void CalibrationStateMachine::note_commit(int seq, const std::string& what, hal::TimeUs now_us) {
  if (is_running(status_.state)) return;
  status_.committed_seq = seq;
  status_.reason = status_.note = "committed calibration " + std::to_string(seq) + " " + what;
  enter(CalibrationState::kDone, now_us);
  refresh_store_problems();
}

void CalibrationStateMachine::fail(const std::string& reason, hal::TimeUs now_us, bool fault, CalibrationState end) {
  const std::string where = std::string(" (during ") + to_string(status_.state) +
                            (status_.waypoint > 0 ? ", waypoint " + std::to_string(status_.waypoint) + "/" +
                                                        std::to_string(status_.waypoint_count)
                                                  : std::string()) +
                            ")";
  enter(CalibrationState::kAbort, now_us);
  // A waypoint job still away is dropped when it comes back: the run does
  // not go on with it. Its waypoints stay the run's record (plan()).
  if (job_) waypoints_ = std::move(job_->sequence);
  job_.reset();
  after_job_ = AfterJob::kNone;
  job_waypoint_.reset();
  // A fault may mean the robot is not where we think: brake now. An abort
  // request is an operator's choice: decelerate and hold.
  hal::Status stopped = fault ? devices_.winches.quick_stop() : devices_.winches.halt();
  if (!stopped.ok() && !fault) stopped = devices_.winches.quick_stop();
  status_.reason = reason + where;
  if (!stopped.ok()) status_.reason += "; stopping the winches failed: " + stopped.to_string();
  status_.reason += "; previous calibration kept";
  status_.note = (fault ? "fault: " : "") + reason + where;
  status_.finished_us = now_us;
  if (fault) run_log_.faults.push_back({run_seconds(now_us), reason + where});
  run_log_.reason = status_.reason;
  if (utc_now_text_) run_log_.finished = utc_now_text_();
  log_run(now_us, end == CalibrationState::kAborted ? formats::kRunAborted : formats::kRunFailed);
  enter(end, now_us);
  refresh_store_problems();
}

void CalibrationStateMachine::refresh_store_problems() {
  status_.store_problems = devices_.store.problems();
  status_.pending_commit = kept_fit_.has_value() || store::PendingCalibration(devices_.store.state_dir()).exists();
}

void CalibrationStateMachine::poll_button(hal::TimeUs now_us) {
  if (!devices_.button) return;
  const hal::Result<int> presses = devices_.button->take_presses();
  if (!presses.ok()) {
    status_.note = "button: " + presses.status().to_string();
  } else if (presses.value() > 0) {
    request_start(now_us);
  }
}

void CalibrationStateMachine::step(hal::TimeUs now_us) {
  poll_button(now_us);
  refresh_device_faults();
  refresh_nodes();
  const CalibrationState state = status_.state;
  if (state == CalibrationState::kPreflight && !store_probed_) {
    // Before anything moves, and before the run's first own write (its
    // history entry) could fail with a less telling message: a run whose fit
    // could not be committed would be wasted.
    store_probed_ = true;
    if (const auto probed = devices_.store.probe_writable(); !probed) {
      return fail("the store cannot be written (" + probed.error().message() + "): a fit could not be committed",
                  now_us, false);
    }
  }
  if (in_motion_phase(state)) {
    if (std::string fault = monitor_.poll(now_us); !fault.empty()) return fail(fault, now_us, true);
    if (state == CalibrationState::kPreflight && now_us - status_.state_entered_us < options_.first_contact_timeout_us) {
      if (std::string missing = monitor_.not_yet_heard(); !missing.empty()) {
        status_.detail = "waiting for first contact: " + missing;
        update_progress();
        return;
      }
    }
    if (std::string fault = monitor_.check(now_us, at_waypoint(state)); !fault.empty()) return fail(fault, now_us, true);
  }
  if (after_job_ != AfterJob::kNone) return;  // the waypoint job is away: status as it left
  switch (state) {
    case CalibrationState::kPreflight: run_preflight(now_us); break;
    case CalibrationState::kPlan: run_plan(now_us); break;
    case CalibrationState::kMove: run_move(now_us); break;
    case CalibrationState::kSettle: run_settle(now_us); break;
    case CalibrationState::kSample: run_sample(now_us); break;
    case CalibrationState::kSolve: run_solve(now_us); break;
    case CalibrationState::kValidate:
    case CalibrationState::kCommit: run_validate_and_commit(now_us); break;
    case CalibrationState::kIdle:
    case CalibrationState::kAbort:
    case CalibrationState::kDone:
    case CalibrationState::kFailed:
    case CalibrationState::kAborted: break;
  }
  update_progress();
}

void CalibrationStateMachine::run_preflight(hal::TimeUs now_us) {
  auto current = devices_.store.load_current();
  if (current) {
    previous_ = std::move(*current);
  } else if (auto newest = devices_.store.newest_readable_version(); newest && *newest) {
    // The newest readable version is what the robot most likely ran on.
    previous_ = std::move(**newest);
    status_.note = "current calibration unreadable (" + current.error().message() +
                   "): checking the change against history version " + std::to_string(previous_->seq);
  } else {
    status_.note = "current calibration unreadable (" + current.error().message() +
                   "): no readable version in the history either, calibrating without the change check";
  }
  enter(CalibrationState::kPlan, now_us);
}

void CalibrationStateMachine::enable_drives(hal::TimeUs now_us) {
  if (!enable_sent_us_) {
    if (const hal::Status s = devices_.winches.enable(); !s.ok()) return fail("enable: " + s.to_string(), now_us, true);
    enable_sent_us_ = now_us;
    status_.detail = "enabling drives";
    return;
  }
  const Readings& readings = monitor_.readings();
  for (int i = 0; i < kCableCount; ++i) {
    if (readings.winches[i].drive != hal::DriveState::kEnabled) {
      if (now_us - *enable_sent_us_ > options_.enable_timeout_us) {
        return fail("winch " + std::to_string(i) + " drive not enabled after " + seconds(options_.enable_timeout_us) +
                        " (" + hal::to_string(readings.winches[i].drive) + ")",
                    now_us, true);
      }
      return;
    }
  }
  targets_sent_ = false;
  enter(CalibrationState::kMove, now_us);
  status_.waypoint = 1;
}

void CalibrationStateMachine::run_plan(hal::TimeUs now_us) {
  // The drives are enabled once the plan exists (the header says why):
  // after_plan() sent the enable.
  if (enable_sent_us_) return enable_drives(now_us);
  const Readings& readings = monitor_.readings();
  Eigen::Vector3d start_world(readings.pose->platform_world.x, readings.pose->platform_world.y,
                              readings.pose->platform_world.z);
  Robot planning_robot = robot_;
  std::array<double, kCableCount> offsets_m{};
  const bool use_previous = previous_ && previous_->calibration.winches.size() == robot_.winches.size();
  if (use_previous) {
    // The last calibration knows anchors and offsets better than the nominal geometry.
    for (int i = 0; i < kCableCount; ++i) {
      planning_robot.winches[i].anchor_world = previous_->calibration.winches[i].anchor_world;
      offsets_m[i] = previous_->calibration.winches[i].offset_m;
    }
  } else {
    // Every target carries the estimate's error: the mean of a rest window,
    // not one pose and encoder reading (docs/calibration.md).
    const std::optional<Sample> rest = start_rest(now_us);
    if (!rest) return;
    start_world = rest->position_world;
    const auto estimated = estimate_payout_offsets(robot_, start_world, rest->encoder_m);
    if (!estimated) return fail("plan: " + estimated.error(), now_us, false);
    offsets_m = *estimated;
  }
  SequentialOptions sequential = options_.sequential;
  sequential.min_count = options_.validation.min_samples;
  sequential.settle_s = expected_settle_s(options_.equilibrium);
  if (given_) {
    begin_job(AfterJob::kPlanned,
              [planning_robot, offsets_m, start_world, planner = options_.planner,
               positions = given_->positions_world, sequential, now_us](WaypointSequence& waypoints) {
                return waypoints.start_given(planning_robot, offsets_m, start_world, planner, positions, sequential,
                                             now_us);
              },
              now_us);
    return;
  }
  begin_job(AfterJob::kPlanned,
            [planning_robot, offsets_m, start_world, planner = options_.planner, strategy = options_.strategy,
             sequential, now_us](WaypointSequence& waypoints) {
              return waypoints.start(planning_robot, offsets_m, start_world, planner, strategy, sequential, now_us);
            },
            now_us);
}

std::optional<Sample> CalibrationStateMachine::start_rest(hal::TimeUs now_us) {
  observe_rest();
  const EquilibriumCheck check = detector_.check();
  const EquilibriumThresholds& limits = detector_.thresholds();
  // The drives are off: the platform is still unless it swings from before
  // (a run stopped mid-move). The rest window's rates suffice; the return
  // window would cost every first run its length in robot time.
  const bool still = check.settled() || (check.covered && check.speed_mps <= limits.max_speed_mps &&
                                         check.angular_rate_radps <= limits.max_angular_rate_radps);
  if (still) return detector_.average();
  status_.detail = "measuring the start pose: " + rest_detail(check);
  if (now_us - status_.state_entered_us <= options_.settle_timeout_us) return std::nullopt;
  if (detector_.size() == 0) {
    fail("plan: no pose at the start within " + seconds(options_.settle_timeout_us), now_us, false);
    return std::nullopt;
  }
  status_.note = "start pose not at rest within " + seconds(options_.settle_timeout_us) + " (" + status_.detail +
                 "): offsets estimated from the window's mean";
  return detector_.average();
}

void CalibrationStateMachine::observe_rest() {
  const Readings& readings = monitor_.readings();
  if (!readings.pose_is_new || !readings.tension) return;
  EquilibriumObservation o;
  // The source's stamp: rates are the platform's (equilibrium_detector.h).
  o.time_us = readings.pose->source_time_us;
  o.position_world = Eigen::Vector3d(readings.pose->platform_world.x, readings.pose->platform_world.y,
                                     readings.pose->platform_world.z);
  const hal::Quaternion& q = readings.pose->world_R_platform;
  o.world_R_platform = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
  for (int i = 0; i < kCableCount; ++i) o.encoder_m[i] = readings.winches[i].payout_m;
  o.tension_n = readings.tension->tension_n;
  o.tension_stable = readings.tension->stable;
  detector_.add(o);
}

void CalibrationStateMachine::after_plan(const std::string& problem, hal::TimeUs now_us) {
  if (!problem.empty()) return fail("plan: " + problem, now_us, false);
  status_.waypoint_count = waypoints_.planned();
  run_log_.waypoints_planned = status_.waypoint_count;
  update_waypoint_status();
  log_run(now_us);
  enable_drives(now_us);
}

void CalibrationStateMachine::run_move(hal::TimeUs now_us) {
  const Waypoint& waypoint = *waypoints_.current();
  if (!targets_sent_) {
    // All four together: they start and arrive at the same time.
    if (const hal::Status s = devices_.winches.set_target_payouts(waypoint.payout_m.data()); !s.ok()) {
      return fail("winch targets: " + s.to_string(), now_us, true);
    }
    targets_sent_ = true;
    status_.detail = "moving to waypoint " + std::to_string(status_.waypoint);
    return;
  }
  if (devices_.winches.motion_finished()) {
    detector_.reset();
    enter(CalibrationState::kSettle, now_us);
    return;
  }
  if (now_us - status_.state_entered_us > options_.move_timeout_us) {
    fail("winches did not reach the waypoint within " + seconds(options_.move_timeout_us), now_us, true);
  }
}

void CalibrationStateMachine::run_settle(hal::TimeUs now_us) {
  observe_rest();
  const EquilibriumCheck check = detector_.check();
  if (check.settled()) {
    enter(CalibrationState::kSample, now_us);
    return;
  }
  status_.detail = rest_detail(check);
  if (now_us - status_.state_entered_us > options_.settle_timeout_us) {
    ++status_.skipped;
    status_.note = "waypoint " + std::to_string(status_.waypoint) + " skipped: no equilibrium within " +
                   seconds(options_.settle_timeout_us) + " (" + status_.detail + ")";
    run_log_.waypoints.push_back({status_.waypoint, "skipped", run_seconds(now_us), -1,
                                  "no equilibrium within " + seconds(options_.settle_timeout_us) + " (" +
                                      status_.detail + ")"});
    run_log_.skipped = status_.skipped;
    begin_job(AfterJob::kSkipped,
              [now_us](WaypointSequence& waypoints) {
                waypoints.skipped(now_us);
                return std::string();
              },
              now_us);
  }
}

void CalibrationStateMachine::run_sample(hal::TimeUs now_us) {
  Sample sample = detector_.average();
  sample.sigma = detector_.average_sigmas(robot_.noise);
  // After an earlier run's rows (given waypoints) the ids go on from theirs.
  sample.id = samples_.empty() ? 0 : samples_.back().id + 1;
  samples_.push_back(sample);
  status_.samples = static_cast<int>(samples_.size());
  begin_job(AfterJob::kSampled,
            [sample = std::move(sample), now_us](WaypointSequence& waypoints) {
              waypoints.sampled(sample, now_us);
              return std::string();
            },
            now_us);
}

void CalibrationStateMachine::after_sample(hal::TimeUs now_us) {
  // A remark on how the next waypoint was chosen (a failed re-solve) goes with this one.
  if (!waypoints_.remark().empty()) status_.note = waypoints_.remark();
  run_log_.waypoints.push_back(
      {status_.waypoint, "sampled", run_seconds(job_begun_us_), samples_.back().id, waypoints_.remark()});
  run_log_.samples = status_.samples;
  log_run(job_begun_us_);
  next_waypoint(now_us);
}

void CalibrationStateMachine::begin_job(AfterJob after, std::function<std::string(WaypointSequence&)> work,
                                        hal::TimeUs now_us) {
  const Waypoint* at = current_waypoint();
  job_waypoint_ = at ? std::optional<Waypoint>(*at) : std::nullopt;
  WaypointJob job{std::move(waypoints_), std::move(work), {}};
  waypoints_ = WaypointSequence{};
  after_job_ = after;
  job_begun_us_ = now_us;
  status_.detail = after == AfterJob::kPlanned ? "planning" : "choosing the next waypoint";
  if (waypoint_work_ == WaypointWork::kInline) {
    job.run();
    return finish_job(std::move(job), now_us);
  }
  job_ = std::move(job);
}

WaypointJob CalibrationStateMachine::take_waypoint_job() {
  WaypointJob job = std::move(*job_);
  job_.reset();
  job_out_ = true;
  return job;
}

void CalibrationStateMachine::deliver_waypoint_job(WaypointJob job, hal::TimeUs now_us) {
  job_out_ = false;
  if (after_job_ == AfterJob::kNone) {
    // The run ended meanwhile: it does not go on; plan() shows its waypoints again.
    waypoints_ = std::move(job.sequence);
    return;
  }
  finish_job(std::move(job), now_us);
}

void CalibrationStateMachine::finish_job(WaypointJob job, hal::TimeUs now_us) {
  waypoints_ = std::move(job.sequence);
  const AfterJob after = std::exchange(after_job_, AfterJob::kNone);
  job_waypoint_.reset();
  switch (after) {
    case AfterJob::kPlanned: after_plan(job.problem, now_us); break;
    case AfterJob::kSampled: after_sample(now_us); break;
    case AfterJob::kSkipped:
      log_run(job_begun_us_);
      next_waypoint(now_us);
      break;
    case AfterJob::kNone: break;
  }
  update_progress();
}

void CalibrationStateMachine::next_waypoint(hal::TimeUs now_us) {
  update_waypoint_status();
  if (waypoints_.current()) {
    targets_sent_ = false;
    enter(CalibrationState::kMove, now_us);
    status_.waypoint = waypoints_.visited() + 1;
    return;
  }
  if (const hal::Status s = devices_.winches.halt(); !s.ok()) return fail("halt: " + s.to_string(), now_us, true);
  if (static_cast<int>(samples_.size()) < options_.validation.min_samples) {
    // An appended-to run's rows count towards the minimum, but they did not settle here.
    const std::size_t earlier = given_ ? given_->earlier_rows : 0;
    return fail("only " + std::to_string(samples_.size() - earlier) + " of " + std::to_string(waypoints_.visited()) +
                    " waypoints settled (at least " + std::to_string(options_.validation.min_samples) + " needed" +
                    (earlier > 0 ? ", counting the " + std::to_string(earlier) + " rows of run " +
                                       std::to_string(given_->earlier_run)
                                 : std::string()) +
                    ")",
                now_us, false);
  }
  enter(CalibrationState::kSolve, now_us);
}

bool CalibrationStateMachine::owns_hardware() const { return in_motion_phase(status_.state); }

bool CalibrationStateMachine::solve_pending() const {
  return status_.state == CalibrationState::kSolve && !solve_ && !solve_result_;
}

void CalibrationStateMachine::deliver_solve_result(CalibrationResult result, hal::TimeUs now_us) {
  if (!solve_pending()) return;  // aborted meanwhile: the result is dropped
  solve_result_ = std::move(result);
  enter(CalibrationState::kValidate, now_us);
}

void CalibrationStateMachine::run_solve(hal::TimeUs now_us) {
  if (!solve_) {
    status_.detail = "waiting for the solver";
    return;
  }
  solve_result_ = solve_(robot_, samples_);
  enter(CalibrationState::kValidate, now_us);
}

void CalibrationStateMachine::run_validate_and_commit(hal::TimeUs now_us) {
  Calibration& calibration = solve_result_->calibration;
  if (status_.state == CalibrationState::kValidate) {
    const Calibration* previous = previous_ ? &previous_->calibration : nullptr;
    const ValidationResult validation = validate_fit(*solve_result_, robot_, previous, options_.validation);
    if (!validation.accepted()) return fail("fit refused: " + validation.summary(), now_us, false);
    stamp_for_commit(calibration, robot_, samples_.size(), utc_now_text_);
    for (const WinchCalibration& w : calibration.winches) {
      status_.largest_anchor_sigma_m = std::max(status_.largest_anchor_sigma_m, w.anchor_sigma.maxCoeff());
      status_.largest_offset_sigma_m = std::max(status_.largest_offset_sigma_m, w.offset_sigma_m);
    }
    calibration.run = RunSummary{run_seconds(now_us), waypoints_.visited(), status_.strategy, status_.stop_reason};
    fit_validated_ = true;
    kept_fit_.reset();  // replaced by this newer fit
    enter(CalibrationState::kCommit, now_us);
    return;
  }
  const auto committed = devices_.store.commit(calibration);
  if (!committed) {
    kept_fit_ = calibration;
    return fail("store: " + committed.error().message() + keep_pending(calibration), now_us, false);
  }
  status_.committed_seq = *committed;
  status_.reason = "committed calibration " + std::to_string(*committed) + " from " +
                   std::to_string(samples_.size()) + " samples (rms encoder " +
                   significant(1e3 * calibration.fit.rms_encoder_m, 3) + " mm, rms force " +
                   significant(calibration.fit.rms_force_n, 3) + " N)";
  status_.finished_us = now_us;
  run_log_.calibration = *committed;
  run_log_.reason = status_.reason;
  if (utc_now_text_) run_log_.finished = utc_now_text_();
  log_run(now_us, formats::kRunCommitted);
  enter(CalibrationState::kDone, now_us);
  refresh_store_problems();
}

std::string CalibrationStateMachine::keep_pending(const Calibration& calibration) const {
  const store::PendingCalibration pending(devices_.store.state_dir());
  const auto kept = pending.keep(calibration, formats::format_samples_csv(samples_));
  if (!kept) {
    return "; keeping the fit in " + pending.dir() + " failed too: " + kept.error().message() + "; " + kKeptInMemory;
  }
  return "; the fit and its " + std::to_string(samples_.size()) + " samples are kept in " + pending.dir() +
         ": fix the cause, then `calibctl commit`";
}

double CalibrationStateMachine::run_seconds(hal::TimeUs now_us) const {
  return 1e-6 * static_cast<double>(now_us - status_.started_us);
}

void CalibrationStateMachine::log_run(hal::TimeUs now_us, const char* outcome) {
  run_log_.robot_time_s = run_seconds(now_us);
  if (outcome) run_log_.outcome = status_.run_outcome = outcome;
}

void CalibrationStateMachine::update_progress() {
  // Waypoints dominate the run's duration; solve and commit take the rest.
  // The sequential strategy counts against its forecast, not its maximum.
  constexpr double kWaypointsStart = 0.05;
  constexpr double kWaypointsSpan = 0.85;
  double phase = 0.0;
  switch (status_.state) {
    case CalibrationState::kPreflight: status_.progress = 0.02; return;
    case CalibrationState::kPlan: status_.progress = 0.04; return;
    case CalibrationState::kMove: phase = 0.0; break;
    case CalibrationState::kSettle: phase = 0.5; break;
    case CalibrationState::kSample: phase = 0.9; break;
    case CalibrationState::kSolve: status_.progress = 0.92; return;
    case CalibrationState::kValidate: status_.progress = 0.96; return;
    case CalibrationState::kCommit: status_.progress = 0.98; return;
    case CalibrationState::kDone: status_.progress = 1.0; return;
    case CalibrationState::kIdle:
    case CalibrationState::kAbort:
    case CalibrationState::kFailed:
    case CalibrationState::kAborted: return;
  }
  if (after_job_ != AfterJob::kNone) return;  // the waypoints are away: the progress as they left
  const int count = std::max(waypoints_.expected_count(), 1);
  status_.progress = kWaypointsStart + kWaypointsSpan * std::min(1.0, (waypoints_.visited() + phase) / count);
}

const Waypoint* CalibrationStateMachine::current_waypoint() const {
  if (!at_waypoint(status_.state)) return nullptr;
  return after_job_ != AfterJob::kNone ? (job_waypoint_ ? &*job_waypoint_ : nullptr) : waypoints_.current();
}

void CalibrationStateMachine::update_waypoint_status() {
  status_.strategy = run_log_.strategy = waypoints_.strategy_name();
  status_.stop_reason = run_log_.stop = waypoints_.stop_reason();
  status_.target_anchor_sigma_m = options_.sequential.target_anchor_sigma_m;
  status_.target_offset_sigma_m = options_.sequential.target_offset_sigma_m;
  status_.largest_anchor_sigma_m = waypoints_.largest_anchor_sigma_m().value_or(-1.0);
  status_.largest_offset_sigma_m = waypoints_.largest_offset_sigma_m().value_or(-1.0);
  status_.time_left_s = waypoints_.current() ? waypoints_.time_left_s() : 0.0;
  status_.time_left_at_us = waypoints_.estimated_at_us();
}

}  // namespace cdpr::calibration
