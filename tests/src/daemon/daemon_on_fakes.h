#pragma once
// A daemon loop on behavioural fakes (no robot behind them), configured like
// the real daemon: for tests of what the loop does around the state machine
// (control socket, start-up reports).

#include <string>
#include <vector>

#include "../../fakes/fake_load_cell.h"
#include "../../fakes/fake_pose_source.h"
#include "../../fakes/fake_winch_bank.h"
#include "../../fakes/manual_clock.h"
#include "../../solver/model/test_robots.h"
#include "src/daemon/daemon_loop.h"

namespace cdpr::daemon::test {

class SilentNotifier final : public ServiceNotifier {
 public:
  void ready() override {}
  void status(const std::string&) override {}
  void watchdog() override {}
  void stopping() override {}
};

// A daemon loop on fakes, configured from cdpr-calibd.toml text.
class DaemonOnFakes {
 public:
  explicit DaemonOnFakes(const DaemonConfig& config)
      : load_cell_(clock_), pose_(clock_), store_(config.store),
        loop_(config, cdpr::test::large_robot(), DaemonDevices{winches_, load_cell_, pose_, nullptr}, store_, clock_,
              notifier_, [this](const std::string& line) { log_.push_back(line); }) {}
  hal::Status start() {
    if (!store_.open()) return hal::Status(hal::ErrorCode::kIoError, "store");
    return loop_.start();
  }
  DaemonLoop& loop() { return loop_; }
  fakes::FakeWinchBank& winches() { return winches_; }
  fakes::ManualClock& clock() { return clock_; }
  // Every line the loop logged, in order.
  const std::vector<std::string>& log() const { return log_; }

 private:
  fakes::ManualClock clock_{1'000'000};
  fakes::FakeWinchBank winches_;
  fakes::FakeLoadCell load_cell_;
  fakes::FakePoseSource pose_;
  SilentNotifier notifier_;
  store::CalibrationStore store_;
  std::vector<std::string> log_;
  DaemonLoop loop_;
};

}  // namespace cdpr::daemon::test
