#pragma once
// Watch mode's OS wiring ([operation] watch = true,
// docs/operation.md): between calibration runs, every loop step
// hands the devices' latest readings (the listen-only winch bank's
// payouts, the onboard pose, the load cell) to the pure OperationWatch
// (src/operation/operation_watch.h); at each rest it serves the pose from
// the cables on [operation] pose_output and logs the rest. The committed
// calibration is read from the store at start and whenever its sequence
// number changes (a run or `calibctl commit`).
// The devices are the loop's: it opens, updates and reconnects them; this
// only reads what they hold. Not thread-safe (the loop thread).

#include <functional>
#include <memory>
#include <string>

#include "src/daemon/daemon_config.h"
#include "src/daemon/pose_output_server.h"
#include "src/operation/operation_watch.h"
#include "src/store/calibration_store.h"

namespace cdpr::daemon {

struct DaemonDevices;

class WatchService {
 public:
  WatchService(const DaemonConfig& config, const Robot& robot, store::CalibrationStore& store,
               std::function<void(const std::string&)> log);

  // Binds the pose output (when configured) and reads the calibration.
  hal::Status start();
  // One loop step while no run owns the devices.
  void step(const DaemonDevices& devices, hal::TimeUs now_us);
  // Reads the committed calibration again (after a commit or a rollback).
  void reload_calibration();
  const operation::OperationStatus& status() const { return watch_.status(); }
  // True once after a re-fit was put into pending/ (the owner refreshes the machine's view of the store).
  bool take_pending_offered();

 private:
  void on_rest(const operation::RestOutcome& outcome);
  // The test has just fired: logs the finding, keeps the re-fit in pending/.
  void offer_refit();
  void log_finding();

  const DaemonConfig& config_;
  store::CalibrationStore& store_;
  std::function<void(const std::string&)> log_;
  operation::OperationWatch watch_;
  std::unique_ptr<PoseOutputServer> output_;
  bool pending_offered_ = false;
};

}  // namespace cdpr::daemon
