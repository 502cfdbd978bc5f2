#include "src/daemon/run_recorder.h"

#include <cstdio>
#include <utility>

#include "solver/diagnosis/diagnosis.h"
#include "src/calibration/model_check_verdict.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "src/report/calibration_report.h"
#include "src/store/atomic_file.h"
#include "src/store/calibration_store.h"
#include "src/store/pending_calibration.h"

namespace cdpr::daemon {

RunRecorder::RunRecorder(std::string state_dir, std::uintmax_t budget_bytes,
                         std::optional<DiagnosisOptions> model_check, std::optional<CalibrationOptions> report_fit)
    : history_(state_dir + "/" + store::CalibrationStore::kHistoryDir),
      state_dir_(std::move(state_dir)),
      budget_bytes_(budget_bytes),
      model_check_(std::move(model_check)),
      report_fit_(std::move(report_fit)),
      writer_([this] { writer_loop(); }) {}

RunRecorder::~RunRecorder() { finish(); }

void RunRecorder::finish() {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (writer_.joinable()) writer_.join();
}

void RunRecorder::post(Job job) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    jobs_.push_back(std::move(job));
  }
  wake_.notify_one();
}

void RunRecorder::writer_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
    if (jobs_.empty()) break;  // stopping, and everything written
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    busy_ = true;
    lock.unlock();
    job();
    lock.lock();
    busy_ = false;
    if (jobs_.empty()) idle_.notify_all();
  }
  idle_.notify_all();
}

void RunRecorder::wait_idle() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return (jobs_.empty() && !busy_) || !writer_.joinable(); });
}

std::vector<std::string> RunRecorder::take_messages() {
  std::lock_guard lock(mutex_);
  return std::exchange(messages_, {});
}

void RunRecorder::report(const std::string& message) {
  if (!reported_.insert(message).second) return;
  std::lock_guard lock(mutex_);
  messages_.push_back(message);
}

bool RunRecorder::write_file(int run, const char* name, const std::string& content) {
  const auto written = history_.write(run, name, content);
  if (!written) report("run history: " + written.error().message());
  return written.has_value();
}

void RunRecorder::note_run_write_failure(int run, const std::string& message) {
  std::lock_guard lock(mutex_);
  if (!write_failure_) write_failure_ = WriteFailure{run, message};
}

bool RunRecorder::write_run_file(int run, const char* name, const std::string& content) {
  const auto written = history_.write(run, name, content);
  if (written) return true;
  report("run history: " + written.error().message());
  note_run_write_failure(run, written.error().message());
  return false;
}

formats::RunLog RunRecorder::as_written(formats::RunLog log) const {
  // The log counts what samples.csv holds: a sample whose rewrite of the
  // file failed is not claimed.
  if (log.samples <= samples_written_) return log;
  log.samples = samples_written_;
  for (formats::RunWaypoint& w : log.waypoints) {
    if (w.sample < samples_written_) continue;
    w.sample = -1;
    w.why += std::string(w.why.empty() ? "" : "; ") + "not in samples.csv: its write failed";
  }
  return log;
}

void RunRecorder::prune() {
  // The current calibration's run and a pending fit's stay, whatever the budget.
  std::vector<std::string> spared;
  for (const std::string& path :
       {state_dir_ + "/" + store::CalibrationStore::kCurrentName,
        state_dir_ + "/" + store::PendingCalibration::kDirName + "/" + store::PendingCalibration::kCalibrationName}) {
    if (auto text = store::read_file(path)) spared.push_back(std::move(*text));
  }
  const auto removed = history_.prune(budget_bytes_, spared);
  if (!removed) {
    report("run history: pruning to the disk budget failed: " + removed.error().message());
    return;
  }
  if (removed->empty()) return;
  std::string runs;
  for (const int run : *removed) runs += (runs.empty() ? "" : ", ") + store::RunHistory::entry_name(run);
  report("run history: removed " + runs + " (oldest first) to keep within the disk budget");
}

std::vector<std::string> RunRecorder::recover(const std::string& finished, const std::string& why,
                                              const std::optional<store::RunProgress>& progress) {
  std::vector<std::string> messages;
  const auto changed = history_.recover_interrupted(finished, why, progress);
  if (!changed) {
    messages.push_back("run history: marking interrupted runs failed: " + changed.error().message());
  } else {
    for (const int run : *changed) messages.push_back("run history: " + history_.entry_path(run) + " was interrupted");
  }
  const auto next = history_.next_run();
  if (!next) messages.push_back("run history: " + next.error().message());
  next_run_ = next ? *next : 1;
  post([this] { prune(); });
  wait_idle();
  for (std::string& message : take_messages()) messages.push_back(std::move(message));
  return messages;
}

void RunRecorder::stop_on_write_failure(calibration::CalibrationStateMachine& machine, hal::TimeUs now_us) {
  std::optional<WriteFailure> failure;
  {
    std::lock_guard lock(mutex_);
    failure = std::exchange(write_failure_, std::nullopt);
  }
  if (!failure || failure->run != run_) return;
  // Status must not name a directory that is not there (a read-only history).
  if (!history_.exists(run_)) machine.note_run_entry("");
  machine.request_stop_for_store(now_us, failure->message);
}

void RunRecorder::track(calibration::CalibrationStateMachine& machine, const Robot& robot, hal::TimeUs now_us) {
  const calibration::CalibrationStatus& status = machine.status();
  if (status.started_us < 0) return;
  const formats::RunLog& log = machine.run_log();
  if (status.started_us != run_started_us_) {
    run_started_us_ = status.started_us;
    run_ = take_run_number();
    waypoints_queued_ = faults_queued_ = 0;
    planned_queued_ = 0;
    fit_queued_ = solved_ = false;
    report_result_.reset();
    outcome_queued_.clear();
    machine.note_run_entry(history_.entry_path(run_));
    post([this, run = run_, robot_text = formats::format_robot_toml(robot)] {
      reported_.clear();
      samples_written_ = 0;
      if (auto made = history_.create(run); !made) {
        report("run history: " + made.error().message());
        return note_run_write_failure(run, made.error().message());
      }
      write_run_file(run, store::RunHistory::kRobotName, robot_text);
    });
  }
  // After the switch to a new run: a late failure of the last one does not stop it.
  stop_on_write_failure(machine, now_us);
  solved_ = solved_ || status.state == calibration::CalibrationState::kSolve;
  if (status.run_diagnosis.empty()) {
    std::lock_guard lock(mutex_);
    if (checked_run_ == run_ && !checked_verdict_.empty()) machine.note_run_diagnosis(checked_verdict_);
  }
  // The plan's size too: a run interrupted before its first sample says what was planned.
  const bool changed = log.waypoints.size() != waypoints_queued_ || log.faults.size() != faults_queued_ ||
                       log.outcome != outcome_queued_ || log.waypoints_planned != planned_queued_ ||
                       (machine.validated_fit() && !fit_queued_);
  if (!changed) return;
  const bool samples_changed = outcome_queued_.empty() || log.waypoints.size() != waypoints_queued_;
  planned_queued_ = log.waypoints_planned;
  waypoints_queued_ = log.waypoints.size();
  faults_queued_ = log.faults.size();
  outcome_queued_ = log.outcome;
  std::string fit_text;
  if (machine.validated_fit() && !fit_queued_) {
    fit_queued_ = true;
    fit_text = formats::format_calibration_toml(*machine.validated_fit());
    if (report_fit_ && machine.validated_result()) report_result_ = *machine.validated_result();
  }
  formats::RunLog snapshot = log;
  snapshot.run = run_;
  const bool ended = log.outcome != formats::kRunRunning;
  const bool check = ended && solved_ && model_check_.has_value();
  const bool with_report = ended && report_result_.has_value();
  std::vector<Sample> samples;
  if (samples_changed || check || with_report) samples = machine.samples();
  // Copies: the model check below needs them too.
  post([this, run = run_, snapshot, samples, samples_changed,
        fit_text = std::move(fit_text), ended] {
    const auto write = [&](const char* name, const std::string& content) { return write_run_file(run, name, content); };
    // Samples before the log that counts them; the fit before the log that says it was committed.
    if (samples_changed && write(store::RunHistory::kSamplesName, formats::format_samples_csv(samples))) {
      samples_written_ = static_cast<int>(samples.size());
    }
    if (!fit_text.empty()) write(store::RunHistory::kCalibrationName, fit_text);
    write(store::RunHistory::kLogName, formats::format_run_log_toml(as_written(snapshot)));
    if (ended) prune();
  });
  if (with_report) {
    post([this, run = run_, snapshot, robot, samples, fit = std::move(*report_result_)] {
      write_report(run, snapshot, robot, samples, *report_fit_, fit);
    });
    report_result_.reset();
  }
  if (check) {
    post([this, run = run_, snapshot = std::move(snapshot), robot, samples = std::move(samples)] {
      check_model(run, snapshot, robot, samples);
    });
  }
}

int RunRecorder::take_run_number() {
  if (next_run_ <= 0) {
    const auto next = history_.next_run();
    next_run_ = next ? *next : 1;
  }
  return next_run_++;
}

std::string RunRecorder::keep_refit(CommittedRefit refit) {
  const int run = take_run_number();
  formats::RunLog log = refit.source_log;
  log.refit_of = refit.source_log.run;
  log.run = run;
  log.outcome = formats::kRunCommitted;
  log.reason = "refit of " + store::RunHistory::entry_name(log.refit_of) + " with the terms " + refit.terms +
               " (operator's choice): committed calibration " + std::to_string(refit.seq);
  log.calibration = refit.seq;
  log.diagnosis.clear();
  log.started = log.finished = refit.fit.calibration.created;
  post([this, run, log = std::move(log), refit = std::move(refit)] {
    reported_.clear();
    const auto write = [&](const char* name, const std::string& content) { write_file(run, name, content); };
    if (auto made = history_.create(run); !made) return report("run history: " + made.error().message());
    write(store::RunHistory::kRobotName, formats::format_robot_toml(refit.robot));
    write(store::RunHistory::kSamplesName, formats::format_samples_csv(refit.samples));
    write(store::RunHistory::kCalibrationName, formats::format_calibration_toml(refit.fit.calibration));
    write(store::RunHistory::kLogName, formats::format_run_log_toml(log));
    write_report(run, log, refit.robot, refit.samples, refit.options, refit.fit);
    prune();
  });
  return history_.entry_path(run);
}

void RunRecorder::check_model(int run, formats::RunLog log, const Robot& robot, const std::vector<Sample>& samples) {
  {
    // A stopping daemon writes the run's data but does not start a check
    // that may take minutes (one already running is finished).
    std::lock_guard lock(mutex_);
    if (stopping_) return;
  }
  // A run pruned meanwhile (a budget of nothing) has no log to add to.
  if (!history_.exists(run)) return;
  log.diagnosis = calibration::model_check_verdict(diagnose(robot, samples, *model_check_));
  write_file(run, store::RunHistory::kLogName, formats::format_run_log_toml(log));
  std::lock_guard lock(mutex_);
  messages_.push_back("model check of " + store::RunHistory::entry_name(run) + ": " + log.diagnosis);
  checked_run_ = run;
  checked_verdict_ = log.diagnosis;
}

namespace {

std::string seconds_text(double s) {
  char text[48];
  std::snprintf(text, sizeof text, "%.0f s (%.1f min)", s, s / 60.0);
  return text;
}

// The run's facts the report's card shows: time, waypoints, why some were skipped.
std::vector<std::pair<std::string, std::string>> run_facts(const formats::RunLog& log) {
  std::vector<std::pair<std::string, std::string>> facts;
  facts.emplace_back("run", store::RunHistory::entry_name(log.run) + ", " + log.outcome + ", started " + log.started);
  if (log.refit_of > 0) {
    facts.emplace_back("refit", "the samples of " + store::RunHistory::entry_name(log.refit_of) +
                                    " fitted again with the model above, committed by the operator's choice");
  }
  // run.toml's robot time is the daemon's monotonic clock from start to end:
  // the robot's own time only when the robot runs in real time (a virtual
  // robot's runs its time scale faster), so the card names the clock.
  facts.emplace_back("run time", seconds_text(log.robot_time_s) + " on the daemon's clock, start to end");
  facts.emplace_back("waypoints", std::to_string(log.waypoints_planned) + " planned, " + std::to_string(log.samples) +
                                      " sampled, " + std::to_string(log.skipped) + " skipped");
  for (const formats::RunWaypoint& w : log.waypoints) {
    if (w.outcome != "skipped") continue;
    facts.emplace_back("skipped waypoint " + std::to_string(w.index), w.why);
  }
  return facts;
}

}  // namespace

void RunRecorder::write_report(int run, const formats::RunLog& log, const Robot& robot,
                               const std::vector<Sample>& samples, const CalibrationOptions& options,
                               const CalibrationResult& fit) {
  // A run pruned meanwhile (a budget of nothing) has no entry to write into.
  if (!history_.exists(run)) return;
  const std::string html =
      report::fitted_calibration_report_html(robot, samples, options, fit, std::nullopt, run_facts(log));
  write_file(run, store::RunHistory::kReportName, html);
}

}  // namespace cdpr::daemon
