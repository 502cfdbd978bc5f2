#pragma once
// Reads the robot's sensors once per control cycle during a calibration run
// and says when it is no longer safe to go on: a winch node silent, a drive
// fault, the pose stale or lost, the load cell failing repeatedly, the
// reference tension outside its limits. I/O goes through the hal interfaces
// only; time is passed in.
//
// Load-cell errors: the driver has already retried (hal/load_cell.h), so an
// error is a failed transaction or, behind drivers/common/load_cell_reader.h,
// a cell silent past its fault timeout; a few in a row are tolerated (a CRC
// error on a noisy RS-485 line), `max_consecutive_load_cell_errors` + 1 are a
// fault. Errors before the first reading are not counted: preflight waits
// for first contact, then check() says "no reading yet" with their cause.
// A reading whose time_us equals the previous one's is not new.
// Not thread-safe; one instance per run loop.

#include <array>
#include <optional>
#include <string>

#include "hal/load_cell.h"
#include "hal/pose_source.h"
#include "hal/winch_bank.h"
#include "solver/model/robot.h"

namespace cdpr::calibration {

struct MonitorLimits {
  hal::TimeUs pose_stale_us = 500'000;       // oldest acceptable pose sample [us]
  double min_tension_n = 20.0;               // reference cable, load cell [N]
  double max_tension_n = 5000.0;
  int max_consecutive_load_cell_errors = 3;  // tolerated in a row
};

struct Readings {
  std::optional<hal::PoseSample> pose;         // latest, fresh or not
  bool pose_is_new = false;                    // arrived during the last poll
  std::optional<hal::TensionSample> tension;   // latest good load-cell reading
  bool tension_is_new = false;
  std::array<hal::WinchStatus, kCableCount> winches{};
};

class HardwareMonitor {
 public:
  HardwareMonitor(hal::WinchBank& winches, hal::LoadCell& load_cell, hal::PoseSource& pose,
                  const MonitorLimits& limits);

  // Forgets readings and error counts (start of a run).
  void reset();
  // Polls every device once (winch update, pose update without waiting, one
  // load-cell read). Returns a fault reason, empty when none.
  std::string poll(hal::TimeUs now_us);
  // Safety checks on the latest readings; with `drives_enabled` every drive
  // must be in operation enabled, otherwise only a fault is one. Returns a
  // fault reason, empty when safe.
  std::string check(hal::TimeUs now_us, bool drives_enabled) const;
  // The devices not heard from at all since reset() (a winch node without a
  // heartbeat yet, no pose, no load-cell reading), as "winch 2 node, pose";
  // empty when every device has spoken. Right after the daemon or a sensor
  // starts that is a matter of waiting, not a fault.
  std::string not_yet_heard() const;

  const Readings& readings() const { return readings_; }
  const MonitorLimits& limits() const { return limits_; }

 private:
  hal::WinchBank& winches_;
  hal::LoadCell& load_cell_;
  hal::PoseSource& pose_;
  MonitorLimits limits_;
  Readings readings_;
  hal::TimeUs last_pose_received_us_ = -1;
  int load_cell_errors_in_row_ = 0;
  std::string load_cell_first_error_;  // the latest error before the first reading
};

}  // namespace cdpr::calibration
