#include "src/calibration/hardware_monitor.h"

#include "src/calibration/message_text.h"

namespace cdpr::calibration {
namespace {

std::string milliseconds(hal::TimeUs duration_us) { return significant(1e-3 * static_cast<double>(duration_us)) + " ms"; }

}  // namespace

HardwareMonitor::HardwareMonitor(hal::WinchBank& winches, hal::LoadCell& load_cell, hal::PoseSource& pose,
                                 const MonitorLimits& limits)
    : winches_(winches), load_cell_(load_cell), pose_(pose), limits_(limits) {}

void HardwareMonitor::reset() {
  readings_ = Readings{};
  last_pose_received_us_ = -1;
  load_cell_errors_in_row_ = 0;
  load_cell_first_error_.clear();
}

std::string HardwareMonitor::poll(hal::TimeUs now_us) {
  if (const hal::Status s = winches_.update(now_us); !s.ok()) return "winch bus: " + s.to_string();
  for (int i = 0; i < kCableCount && i < winches_.winch_count(); ++i) readings_.winches[i] = winches_.status(i);

  if (const hal::Status s = pose_.update(0); !s.ok()) return "pose source: " + s.to_string();
  readings_.pose = pose_.latest();
  readings_.pose_is_new = readings_.pose && readings_.pose->received_us != last_pose_received_us_;
  if (readings_.pose) last_pose_received_us_ = readings_.pose->received_us;

  readings_.tension_is_new = false;
  const hal::Result<hal::TensionSample> tension = load_cell_.read();
  if (tension.ok()) {
    readings_.tension_is_new = !readings_.tension || readings_.tension->time_us != tension.value().time_us;
    readings_.tension = tension.value();
    load_cell_errors_in_row_ = 0;
  } else if (!readings_.tension) {
    // Not heard from yet: preflight's first-contact wait decides, and check() names this cause.
    load_cell_first_error_ = tension.status().to_string();
  } else if (++load_cell_errors_in_row_ > limits_.max_consecutive_load_cell_errors) {
    return "load cell: " + tension.status().to_string() + " (" + std::to_string(load_cell_errors_in_row_) +
           " failed reads in a row)";
  }
  return {};
}

std::string HardwareMonitor::not_yet_heard() const {
  std::string missing;
  const auto add = [&missing](const std::string& what) { missing += (missing.empty() ? "" : ", ") + what; };
  for (int i = 0; i < kCableCount && i < winches_.winch_count(); ++i) {
    if (readings_.winches[i].heartbeat_age_us < 0) add("winch " + std::to_string(i) + " node");
  }
  if (!readings_.pose) add("pose");
  if (!readings_.tension) add("load cell");
  return missing;
}

std::string HardwareMonitor::check(hal::TimeUs now_us, bool drives_enabled) const {
  if (winches_.winch_count() != kCableCount) {
    return "winch bank has " + std::to_string(winches_.winch_count()) + " winches, robot has 4";
  }
  for (int i = 0; i < kCableCount; ++i) {
    const hal::WinchStatus& w = readings_.winches[i];
    const std::string winch = "winch " + std::to_string(i);
    if (!w.alive) {
      return winch + " node silent (" +
             (w.heartbeat_age_us < 0 ? std::string("never heard") : "last heard " + milliseconds(w.heartbeat_age_us) +
                                                                         " ago") +
             ")";
    }
    if (w.fault) return winch + ": " + winches_.fault_text(i);
    if (w.drive == hal::DriveState::kFault) {
      const std::string cause = winches_.fault_text(i);
      return winch + " drive fault" + (cause.empty() ? std::string() : ": " + cause);
    }
    if (drives_enabled && w.drive != hal::DriveState::kEnabled) {
      return winch + " drive left operation enabled (now " + hal::to_string(w.drive) + ")";
    }
  }
  if (!readings_.pose) return "pose stale: no pose received";
  const hal::TimeUs pose_age_us = now_us - readings_.pose->received_us;
  if (pose_age_us > limits_.pose_stale_us) {
    return "pose stale: last pose " + milliseconds(pose_age_us) + " old (limit " +
           milliseconds(limits_.pose_stale_us) + ")";
  }
  if (!readings_.pose->valid) return "pose source reports tracking lost";
  if (!readings_.tension) {
    return "load cell: no reading yet" + (load_cell_first_error_.empty() ? "" : " (" + load_cell_first_error_ + ")");
  }
  const double tension_n = readings_.tension->tension_n;
  if (tension_n < limits_.min_tension_n || tension_n > limits_.max_tension_n) {
    return "tension out of limits: " + significant(tension_n) + " N outside [" + significant(limits_.min_tension_n) +
           ", " + significant(limits_.max_tension_n) + "] N";
  }
  return {};
}

}  // namespace cdpr::calibration
