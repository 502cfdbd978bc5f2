#pragma once
// The operator's explicit choice to commit a calibration with an extra
// model term (`calibctl commit --with-term NAME [RUN]`, the control
// request `refit <terms> [<run>]`): when the model check of a run names an
// effect the daemon's model lacks, its kept samples (store/run_history.h)
// are fitted again with the catenary plus that term and, when the fit
// passes the same validation as a run's (validate_fit: convergence, noise,
// the model-fit test, sigmas, change from the current calibration), it is
// committed with `model = ["catenary", NAME]` and its [effects]. Nothing
// else ever commits a model term: the runs keep the daemon's model.
//
// The request is checked at once on the loop thread (known terms that can
// be fitted together, the entry is there, its samples.csv and robot.toml
// read and describe the daemon's robot, no other refit running); the fit
// runs on a worker of its own, so that the state machine and the control
// socket never wait for it. poll() on the loop thread takes its result:
// refused when a calibration started meanwhile (its validation and commit
// would race this one), else validated and committed. The owner keeps a
// committed refit in the history (RunRecorder::keep_refit: a new entry with
// its report.html) and logs its outcome; refit_status() says what became of
// the last refit.
//
// Thread-safety: everything from one thread (the daemon's loop); the worker
// only runs calibrate() on copies.

#include <functional>
#include <future>
#include <optional>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/model/robot.h"
#include "src/calibration/fit_validation.h"
#include "src/control/refit_service.h"
#include "src/formats/run_log_toml.h"
#include "src/store/calibration_store.h"
#include "src/store/run_history.h"

namespace cdpr::daemon {

// A refit poll() committed, for the history.
struct CommittedRefit {
  formats::RunLog source_log;  // the refitted run's log (its run number included)
  Robot robot;                 // its robot.toml
  std::vector<Sample> samples; // its samples.csv
  CalibrationOptions options;  // the fit's: the catenary plus the terms
  CalibrationResult fit;       // as committed (created, robot, samples filled in)
  int seq = 0;                 // the store's sequence number of it
  std::string terms;           // as requested, "load_cell_bias"
};

class RunRefitter : public control::RefitService {
 public:
  // `robot`: the daemon's (a run measured on another robot is refused);
  // `fit`: the daemon's solver options, the terms are added to them;
  // `utc_now_text`: calibration.toml's `created`; `log` (may be empty): a
  // line when a refit starts and when it ends.
  RunRefitter(Robot robot, std::string history_dir, store::CalibrationStore& store, CalibrationOptions fit,
              calibration::ValidationLimits limits, std::function<std::string()> utc_now_text,
              std::function<void(const std::string&)> log = {});
  ~RunRefitter() override;  // waits for a fit in progress (its result is dropped)
  RunRefitter(const RunRefitter&) = delete;
  RunRefitter& operator=(const RunRefitter&) = delete;

  Expected<std::string, std::string> start_refit(int run, const std::string& terms) override;
  std::optional<control::RefitStatus> refit_status() const override { return status_; }

  // True while a fit runs on the worker.
  bool busy() const { return fitting_; }
  // Loop thread, every step: once the worker's fit is done, refuses it when
  // `calibration_running`, else validates and commits it. Returns true when
  // the refit ended in this call (refit_status() says how); take_committed()
  // then has it when it was committed.
  bool poll(bool calibration_running);
  std::optional<CommittedRefit> take_committed();
  // The history entry the owner kept the committed refit in.
  void note_entry(std::string entry) { status_->entry = std::move(entry); }

 private:
  void finish(const char* state, std::string message);

  Robot robot_;
  store::RunHistory history_;
  store::CalibrationStore& store_;
  CalibrationOptions fit_options_;
  calibration::ValidationLimits limits_;
  std::function<std::string()> utc_now_text_;
  std::function<void(const std::string&)> log_;

  std::optional<control::RefitStatus> status_;
  bool fitting_ = false;
  std::future<CalibrationResult> fit_;
  CommittedRefit job_;  // the refit in progress (fit empty until done)
  std::optional<CommittedRefit> committed_;
};

}  // namespace cdpr::daemon
