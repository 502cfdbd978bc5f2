#include "drivers/can/cia402.h"

namespace cdpr::drivers::can::cia402 {

const char* to_string(PowerState state) {
  switch (state) {
    case PowerState::kNotReadyToSwitchOn: return "not ready to switch on";
    case PowerState::kSwitchOnDisabled: return "switch on disabled";
    case PowerState::kReadyToSwitchOn: return "ready to switch on";
    case PowerState::kSwitchedOn: return "switched on";
    case PowerState::kOperationEnabled: return "operation enabled";
    case PowerState::kQuickStopActive: return "quick stop active";
    case PowerState::kFaultReactionActive: return "fault reaction active";
    case PowerState::kFault: return "fault";
  }
  return "unknown";
}

PowerState decode_power_state(std::uint16_t sw) {
  // Bits: 0 ready to switch on, 1 switched on, 2 operation enabled, 3 fault,
  // 5 quick stop (active low), 6 switch on disabled.
  if ((sw & 0x004F) == 0x0000) return PowerState::kNotReadyToSwitchOn;
  if ((sw & 0x004F) == 0x0040) return PowerState::kSwitchOnDisabled;
  if ((sw & 0x006F) == 0x0021) return PowerState::kReadyToSwitchOn;
  if ((sw & 0x006F) == 0x0023) return PowerState::kSwitchedOn;
  if ((sw & 0x006F) == 0x0027) return PowerState::kOperationEnabled;
  if ((sw & 0x006F) == 0x0007) return PowerState::kQuickStopActive;
  if ((sw & 0x004F) == 0x000F) return PowerState::kFaultReactionActive;
  if ((sw & 0x004F) == 0x0008) return PowerState::kFault;
  return PowerState::kNotReadyToSwitchOn;  // undefined codings: treat as not ready
}

std::uint16_t statusword_of(PowerState state) {
  switch (state) {
    case PowerState::kNotReadyToSwitchOn: return 0x0000;
    case PowerState::kSwitchOnDisabled: return 0x0040;
    case PowerState::kReadyToSwitchOn: return 0x0021;
    case PowerState::kSwitchedOn: return 0x0033;
    case PowerState::kOperationEnabled: return 0x0037;
    case PowerState::kQuickStopActive: return 0x0017;
    case PowerState::kFaultReactionActive: return 0x001F;
    case PowerState::kFault: return 0x0008;
  }
  return 0x0000;
}

PowerState next_power_state(PowerState state, std::uint16_t cw, std::uint16_t previous_cw) {
  const bool fault_reset_edge = (cw & kCwFaultReset) != 0 && (previous_cw & kCwFaultReset) == 0;
  if (state == PowerState::kFault) return fault_reset_edge ? PowerState::kSwitchOnDisabled : state;
  if (state == PowerState::kFaultReactionActive || state == PowerState::kNotReadyToSwitchOn) return state;
  if ((cw & kCwFaultReset) != 0) return state;  // bit 7 set outside fault: no command
  const bool disable_voltage = (cw & 0x0002) == 0;             // xxxx xx0x
  const bool quick_stop = (cw & 0x0006) == 0x0002;             // xxxx x01x
  const bool shutdown = (cw & 0x0007) == 0x0006;               // xxxx x110
  const bool switch_on = (cw & 0x000F) == 0x0007;              // xxxx 0111
  const bool enable_operation = (cw & 0x000F) == 0x000F;       // xxxx 1111
  switch (state) {
    case PowerState::kSwitchOnDisabled:
      return shutdown ? PowerState::kReadyToSwitchOn : state;
    case PowerState::kReadyToSwitchOn:
      if (switch_on) return PowerState::kSwitchedOn;
      if (enable_operation) return PowerState::kOperationEnabled;  // transition 2+4 done by many drives
      if (disable_voltage || quick_stop) return PowerState::kSwitchOnDisabled;
      return state;
    case PowerState::kSwitchedOn:
      if (enable_operation) return PowerState::kOperationEnabled;
      if (shutdown) return PowerState::kReadyToSwitchOn;
      if (disable_voltage || quick_stop) return PowerState::kSwitchOnDisabled;
      return state;
    case PowerState::kOperationEnabled:
      if (quick_stop) return PowerState::kQuickStopActive;
      if (disable_voltage) return PowerState::kSwitchOnDisabled;
      if (shutdown) return PowerState::kReadyToSwitchOn;
      if (switch_on) return PowerState::kSwitchedOn;
      return state;
    case PowerState::kQuickStopActive:
      if (disable_voltage) return PowerState::kSwitchOnDisabled;
      return state;  // "enable operation" from quick stop is optional (transition 16): not supported
    default:
      return state;
  }
}

}  // namespace cdpr::drivers::can::cia402
