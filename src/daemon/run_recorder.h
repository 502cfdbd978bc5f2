#pragma once
// Keeps every calibration run's data in the store's history
// (store/run_history.h): the entry is made when a run starts (robot.toml,
// run.toml "running"), samples.csv and run.toml are rewritten at every
// waypoint sampled or skipped, calibration.toml when a fit is validated,
// and the final run.toml when the run ends, committed, failed or aborted.
// Then the history is pruned to its disk budget, sparing the current
// calibration's run and a fit waiting in pending/. When the run reached its
// solve and a model check is configured, the check (solver/diagnosis) runs
// on the run's samples and its verdict (model_check_verdict.h) is added to
// run.toml; the calibration committed is not changed by it. A run whose
// fit was validated also gets report.html (src/report/calibration_report.h:
// the verdict card with the run's robot time and waypoints, the anchors,
// the residuals) when it ends.
//
// The writes (each several fsyncs) run in order on a thread of their own,
// so that a slow or full disk (or a long model check) never stalls the loop
// that watches the winches: track() only copies the run's log and samples
// into a queue. A next run's writes wait behind a model check in progress.
// A failed write is reported by take_messages() (path and errno), once per
// file and run. The first failed write of a running run's record (its
// entry, robot.toml, samples.csv, calibration.toml, run.toml) also stops
// the run at the next track() (request_stop_for_store(): a run whose data
// cannot be kept is not worth the robot's time); and status then names no
// entry when its directory could not be made. A run.toml never counts more
// samples than its samples.csv holds. Writes after the run (its report,
// the model check's verdict, a refit's entry) are only reported.
//
// Thread-safety: track(), recover(), take_messages() and finish() from one
// thread (the daemon's loop); the writer thread is internal.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "solver/diagnosis/diagnosis_options.h"
#include "solver/model/robot.h"
#include "src/calibration/calibration_state_machine.h"
#include "src/daemon/run_refitter.h"
#include "src/store/run_history.h"

namespace cdpr::daemon {

class RunRecorder {
 public:
  // `state_dir`: the store's (its history/ holds the entries, its
  // calibration.toml and pending/ are what pruning spares).
  // `model_check`: the options of the check after each solve; none: no check.
  // `report_fit`: the solver options the fits were made with, for the
  // report's residuals; none: no report.
  RunRecorder(std::string state_dir, std::uintmax_t budget_bytes,
              std::optional<DiagnosisOptions> model_check = std::nullopt,
              std::optional<CalibrationOptions> report_fit = std::nullopt);
  ~RunRecorder();  // finish()
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  // At start-up, before the first run: entries a daemon that died left
  // "running" become "interrupted" (with `why`), then the history is pruned
  // to its budget. Synchronous. Returns one message per event or failure.
  // `progress`: what the run marker knew of the newest run (RunHistory::recover_interrupted).
  std::vector<std::string> recover(const std::string& finished, const std::string& why,
                                   const std::optional<store::RunProgress>& progress = std::nullopt);

  // After every step of `machine`: queues the writes the run's progress
  // calls for, names the entry in the machine's status and, once the model
  // check of its run is done, puts its verdict there too.
  // `now_us`: the loop's monotonic time, for stopping the run.
  void track(calibration::CalibrationStateMachine& machine, const Robot& robot, hal::TimeUs now_us);

  // Between runs (loop thread): keeps a refit the operator had committed
  // (run_refitter.h) as an entry of its own, so that `calibctl show` finds
  // its report like a run's: the refitted run's robot.toml, samples.csv and
  // log (run.toml `refit_of` names that run), the refit's calibration.toml
  // and its report.html. Returns the entry's path; written on the thread.
  std::string keep_refit(CommittedRefit refit);

  // Failed writes and prunings since the last call, one sentence each.
  std::vector<std::string> take_messages();

  // Waits until every queued write is done (tests; shutdown).
  void wait_idle();
  // Writes what is queued (a model check not yet started is skipped), then
  // stops the thread (idempotent).
  void finish();

  const store::RunHistory& history() const { return history_; }

 private:
  using Job = std::function<void()>;
  void post(Job job);
  void writer_loop();
  // On the writer thread: notes a failure once per message and run.
  void report(const std::string& message);
  void prune();
  // On the writer thread: file `name` of entry `run`, a failure reported.
  bool write_file(int run, const char* name, const std::string& content);
  // The same for a file of the run's record: a failure also stops the run.
  bool write_run_file(int run, const char* name, const std::string& content);
  void note_run_write_failure(int run, const std::string& message);
  // Writer thread: `log` claiming no more samples than samples.csv holds.
  formats::RunLog as_written(formats::RunLog log) const;
  // Loop thread: a failed write of the tracked run stops it.
  void stop_on_write_failure(calibration::CalibrationStateMachine& machine, hal::TimeUs now_us);
  // On the writer thread: the model check of a finished run, its verdict into run.toml.
  void check_model(int run, formats::RunLog log, const Robot& robot, const std::vector<Sample>& samples);
  // On the writer thread: report.html of a run that ended with a validated fit.
  // `options`: those the fit was made with.
  void write_report(int run, const formats::RunLog& log, const Robot& robot, const std::vector<Sample>& samples,
                    const CalibrationOptions& options, const CalibrationResult& fit);
  // Loop thread: the number of the next entry.
  int take_run_number();

  store::RunHistory history_;
  std::string state_dir_;
  std::uintmax_t budget_bytes_;
  std::optional<DiagnosisOptions> model_check_;
  std::optional<CalibrationOptions> report_fit_;

  // Loop thread: what of the tracked run has been queued.
  hal::TimeUs run_started_us_ = -1;
  int run_ = 0;
  int next_run_ = 0;
  std::size_t waypoints_queued_ = 0;
  std::size_t faults_queued_ = 0;
  int planned_queued_ = 0;
  std::string outcome_queued_;
  bool fit_queued_ = false;
  bool solved_ = false;  // the run reached its solve
  std::optional<CalibrationResult> report_result_;  // the run's validated fit, for its report

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  std::deque<Job> jobs_;
  bool busy_ = false;
  bool stopping_ = false;
  std::vector<std::string> messages_;
  int checked_run_ = 0;          // the run of the latest model check done
  std::string checked_verdict_;  // and its verdict
  std::set<std::string> reported_;  // this run's, writer thread only
  int samples_written_ = 0;          // rows of this run's samples.csv on disk, writer thread only
  struct WriteFailure {
    int run = 0;
    std::string message;  // "write <path>: No space left on device"
  };
  std::optional<WriteFailure> write_failure_;  // the first since the loop last looked
  std::thread writer_;
};

}  // namespace cdpr::daemon
