#pragma once
// The CANopen winch bank's configuration from the daemon's [winches] keys:
// shared by main() and the integration tests, which wire the same drivers.
// Header-only: src/'s library does not see drivers/, only the programs do.

#include "drivers/can/canopen_winch_bank.h"
#include "src/daemon/daemon_config.h"

namespace cdpr {

inline drivers::can::CanWinchBankConfig winch_bank_config(const daemon::WinchesConfig& c) {
  drivers::can::CanWinchBankConfig out;
  out.heartbeat_timeout_us = c.heartbeat_timeout_us;
  out.resend_interval_us = c.resend_interval_us;
  out.max_move_m = c.max_move_m;
  out.max_speed_mps = c.max_speed_mps;
  out.master_node_id = c.master_node_id;
  out.master_heartbeat_us = c.master_heartbeat_us;
  out.sdo_timeout_us = c.sdo_timeout_us;
  const daemon::CanDriveDescription& d = c.drive;
  out.drive.vendor_id = static_cast<std::uint32_t>(d.vendor_id);
  out.drive.product_code = static_cast<std::uint32_t>(d.product_code);
  out.drive.quick_stop_option = d.quick_stop_option;
  out.drive.abort_connection_option = d.abort_connection_option;
  out.drive.following_error_window_m = d.following_error_window_m;
  out.drive.profile_velocity_mps = d.profile_velocity_mps;
  out.drive.profile_acceleration_mps2 = d.profile_acceleration_mps2;
  out.drive.profile_deceleration_mps2 = d.profile_deceleration_mps2;
  out.drive.quick_stop_deceleration_mps2 = d.quick_stop_deceleration_mps2;
  out.drive.heartbeat_producer_us = d.heartbeat_producer_us;
  out.drive.consumer_heartbeat_us = d.consumer_heartbeat_us;
  out.drive.pdo_event_timer_us = d.pdo_event_timer_us;
  out.encoder.vendor_id = static_cast<std::uint32_t>(c.encoder.vendor_id);
  out.encoder.product_code = static_cast<std::uint32_t>(c.encoder.product_code);
  out.encoder.heartbeat_producer_us = c.encoder.heartbeat_producer_us;
  out.encoder.pdo_event_timer_us = c.encoder.pdo_event_timer_us;
  for (const daemon::WinchNodes& w : c.winches) {
    out.winches.push_back({w.drive_node_id, w.encoder_node_id, w.encoder_m_per_count, w.drive_m_per_count});
  }
  return out;
}

}  // namespace cdpr
