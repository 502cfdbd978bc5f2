#include "src/daemon/run_recorder.h"

#include <cstdio>
#include <filesystem>
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

std::vector<std::string> RunRecorder::recover(const std::string& finished, const std::string& why) {
  std::vector<std::string> messages;
  const auto changed = history_.recover_interrupted(finished, why);
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

void RunRecorder::track(calibration::CalibrationStateMachine& machine, const Robot& robot) {
  const calibration::CalibrationStatus& status = machine.status();
  if (status.started_us < 0) return;
  const formats::RunLog& log = machine.run_log();
  if (status.started_us != run_started_us_) {
    if (next_run_ <= 0) {
      const auto next = history_.next_run();
      next_run_ = next ? *next : 1;
    }
    run_started_us_ = status.started_us;
    run_ = next_run_++;
    waypoints_queued_ = faults_queued_ = 0;
    fit_queued_ = solved_ = false;
    report_result_.reset();
    outcome_queued_.clear();
    machine.note_run_entry(history_.entry_path(run_));
    post([this, run = run_, robot_text = formats::format_robot_toml(robot)] {
      reported_.clear();
      if (auto made = history_.create(run); !made) return report("run history: " + made.error().message());
      if (auto written = history_.write(run, store::RunHistory::kRobotName, robot_text); !written) {
        report("run history: " + written.error().message());
      }
    });
  }
  solved_ = solved_ || status.state == calibration::CalibrationState::kSolve;
  if (status.run_diagnosis.empty()) {
    std::lock_guard lock(mutex_);
    if (checked_run_ == run_ && !checked_verdict_.empty()) machine.note_run_diagnosis(checked_verdict_);
  }
  const bool changed = log.waypoints.size() != waypoints_queued_ || log.faults.size() != faults_queued_ ||
                       log.outcome != outcome_queued_ || (machine.validated_fit() && !fit_queued_);
  if (!changed) return;
  const bool samples_changed = outcome_queued_.empty() || log.waypoints.size() != waypoints_queued_;
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
    const auto write = [&](const char* name, const std::string& content) {
      if (auto written = history_.write(run, name, content); !written) {
        report("run history: " + written.error().message());
      }
    };
    // Samples before the log that counts them; the fit before the log that says it was committed.
    if (samples_changed) write(store::RunHistory::kSamplesName, formats::format_samples_csv(samples));
    if (!fit_text.empty()) write(store::RunHistory::kCalibrationName, fit_text);
    write(store::RunHistory::kLogName, formats::format_run_log_toml(snapshot));
    if (ended) prune();
  });
  if (with_report) {
    post([this, run = run_, snapshot, robot, samples, fit = std::move(*report_result_)] {
      write_report(run, snapshot, robot, samples, fit);
    });
    report_result_.reset();
  }
  if (check) {
    post([this, run = run_, snapshot = std::move(snapshot), robot, samples = std::move(samples)] {
      check_model(run, snapshot, robot, samples);
    });
  }
}

void RunRecorder::check_model(int run, formats::RunLog log, const Robot& robot, const std::vector<Sample>& samples) {
  {
    // A stopping daemon writes the run's data but does not start a check
    // that may take minutes (one already running is finished).
    std::lock_guard lock(mutex_);
    if (stopping_) return;
  }
  // A run pruned meanwhile (a budget of nothing) has no log to add to.
  std::error_code error;
  if (!std::filesystem::is_directory(history_.entry_path(run), error)) return;
  log.diagnosis = calibration::model_check_verdict(diagnose(robot, samples, *model_check_));
  if (auto written = history_.write(run, store::RunHistory::kLogName, formats::format_run_log_toml(log)); !written) {
    report("run history: " + written.error().message());
  }
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
  facts.emplace_back("robot time", seconds_text(log.robot_time_s));
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
                               const std::vector<Sample>& samples, const CalibrationResult& fit) {
  // A run pruned meanwhile (a budget of nothing) has no entry to write into.
  std::error_code error;
  if (!std::filesystem::is_directory(history_.entry_path(run), error)) return;
  const HeldOutEvaluation residuals = report::fitted_residuals(robot, samples, *report_fit_, fit);
  const report::CalibrationReport content{"Calibration of robot " + robot.name, &robot, &fit, &residuals,
                                          std::nullopt, run_facts(log)};
  if (auto written = history_.write(run, store::RunHistory::kReportName, report::calibration_report_html(content));
      !written) {
    report("run history: " + written.error().message());
  }
}

}  // namespace cdpr::daemon
