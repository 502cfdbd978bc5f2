#pragma once
// CiA 402 (drives and motion control) vocabulary: controlword commands,
// statusword bits, the power state machine. Both sides are here: the master
// side decodes statuswords, the device side (fake nodes in tests, the virtual
// robot) computes the next state from a controlword, so the two agree by
// construction and the tests check both against the standard's tables.
// Pure functions, no I/O.

#include <cstdint>

namespace cdpr::drivers::can::cia402 {

// Controlword (0x6040) commands, bits 0-3 and 7 (CiA 402 table "device control commands").
constexpr std::uint16_t kCwDisableVoltage = 0x0000;
constexpr std::uint16_t kCwQuickStop = 0x0002;
constexpr std::uint16_t kCwShutdown = 0x0006;
constexpr std::uint16_t kCwSwitchOn = 0x0007;
constexpr std::uint16_t kCwEnableOperation = 0x000F;
constexpr std::uint16_t kCwFaultReset = 0x0080;
// Profile position mode bits.
constexpr std::uint16_t kCwNewSetpoint = 0x0010;       // bit 4, rising edge takes the target
constexpr std::uint16_t kCwChangeImmediately = 0x0020; // bit 5, abort the running move
constexpr std::uint16_t kCwHalt = 0x0100;              // bit 8

// Statusword (0x6041) bits beyond the power state.
constexpr std::uint16_t kSwTargetReached = 1u << 10;
constexpr std::uint16_t kSwSetpointAcknowledge = 1u << 12;
constexpr std::uint16_t kSwFollowingError = 1u << 13;

enum class PowerState {
  kNotReadyToSwitchOn,
  kSwitchOnDisabled,
  kReadyToSwitchOn,
  kSwitchedOn,
  kOperationEnabled,
  kQuickStopActive,
  kFaultReactionActive,
  kFault,
};

const char* to_string(PowerState state);

// The power state a statusword reports (masks of CiA 402 table "state coding").
PowerState decode_power_state(std::uint16_t statusword);
// The power-state bits of a statusword in `state` (voltage enabled bit 4 set
// where the table says so); OR in kSwTargetReached etc. as needed.
std::uint16_t statusword_of(PowerState state);
// Device side: the state after receiving `controlword` in `state` (the
// transitions of the power state machine; commands not allowed in a state
// leave it unchanged). Fault reset needs a rising edge of bit 7: pass the
// previous controlword.
PowerState next_power_state(PowerState state, std::uint16_t controlword, std::uint16_t previous_controlword);

}  // namespace cdpr::drivers::can::cia402
