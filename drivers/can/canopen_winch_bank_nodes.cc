// The winch bank's per-node status for the operator (calibctl status): NMT
// state, CiA 402 power state, 0x603F, the last EMCY and the ages of the
// node's heartbeat and TPDO. Read only; the run decides on status().
#include <cstdlib>

#include "drivers/can/canopen_winch_bank.h"

namespace cdpr::drivers::can {
int CanopenWinchBank::node_count(int winch) const {
  if (winch < 0 || winch >= winch_count()) std::abort();  // caller's broken invariant (hal/winch_bank.h)
  return winches_[static_cast<std::size_t>(winch)].encoder_node.id != 0 ? 2 : 1;
}

hal::NodeStatus CanopenWinchBank::node_status(int winch, int index) const {
  if (index < 0 || index >= node_count(winch)) std::abort();
  const Winch& w = winches_[static_cast<std::size_t>(winch)];
  const bool drive = index == 0;
  const Node& node = drive ? w.drive_node : w.encoder_node;
  hal::NodeStatus s;
  s.role = drive ? "drive" : "encoder";
  s.node_id = node.id;
  s.configured = node.configured;
  const auto age = [this](hal::TimeUs last_us) { return last_us < 0 ? hal::TimeUs{-1} : now_us_ - last_us; };
  s.heartbeat_age_us = age(node.last_heartbeat_us);
  s.pdo_age_us = age(node.last_pdo_us);
  if (node.last_heartbeat_us >= 0) {
    s.nmt = s.heartbeat_age_us > config_.heartbeat_timeout_us ? "silent" : to_string(node.nmt_state);
  }
  if (drive && w.drive.has_status()) {
    s.power_state = cia402::to_string(w.drive.power_state());
    if (w.drive.drive_state() == hal::DriveState::kFault && w.error_code_value != 0) {
      s.error_code = w.error_code_value;
      s.error_text = emergency_text(w.error_code_value);
    }
  }
  if (node.emcy_code != 0) {
    s.emcy_code = node.emcy_code;
    s.emcy_register = node.emcy_register;
    s.emcy_text = emergency_text(node.emcy_code);
  }
  return s;
}

}  // namespace cdpr::drivers::can
