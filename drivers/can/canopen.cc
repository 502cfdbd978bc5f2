#include "drivers/can/canopen.h"

namespace cdpr::drivers::can {
namespace {

void put_u16(CanFrame& frame, int at, std::uint16_t value) {
  frame.data[at] = static_cast<std::uint8_t>(value & 0xFF);
  frame.data[at + 1] = static_cast<std::uint8_t>(value >> 8);
}

void put_i32(CanFrame& frame, int at, std::int32_t value) {
  const auto bits = static_cast<std::uint32_t>(value);
  for (int i = 0; i < 4; ++i) frame.data[at + i] = static_cast<std::uint8_t>(bits >> (8 * i));
}

std::uint16_t get_u16(const CanFrame& frame, int at) {
  return static_cast<std::uint16_t>(frame.data[at] | (frame.data[at + 1] << 8));
}

std::uint32_t get_u32(const CanFrame& frame, int at) {
  std::uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= static_cast<std::uint32_t>(frame.data[at + i]) << (8 * i);
  return bits;
}

std::int32_t get_i32(const CanFrame& frame, int at) { return static_cast<std::int32_t>(get_u32(frame, at)); }

CanFrame frame_of(std::uint32_t id, std::uint8_t len) {
  CanFrame frame;
  frame.id = id;
  frame.len = len;
  return frame;
}

}  // namespace

const char* to_string(NmtState state) {
  switch (state) {
    case NmtState::kBootUp: return "boot-up";
    case NmtState::kStopped: return "stopped";
    case NmtState::kOperational: return "operational";
    case NmtState::kPreOperational: return "pre-operational";
  }
  return "unknown";
}

std::optional<int> node_of(const CanFrame& frame, std::uint32_t base) {
  if (frame.id <= base || frame.id > base + kMaxNodeId) return std::nullopt;
  return static_cast<int>(frame.id - base);
}

CanFrame make_nmt(NmtCommand command, int node_id) {
  CanFrame frame = frame_of(kNmtCobId, 2);
  frame.data[0] = static_cast<std::uint8_t>(command);
  frame.data[1] = static_cast<std::uint8_t>(node_id);
  return frame;
}

CanFrame make_heartbeat(int node_id, NmtState state) {
  CanFrame frame = frame_of(kHeartbeatBase + static_cast<std::uint32_t>(node_id), 1);
  frame.data[0] = static_cast<std::uint8_t>(state);
  return frame;
}

CanFrame make_encoder_tpdo(int node_id, std::uint32_t position_counts) {
  CanFrame frame = frame_of(kTpdo1Base + static_cast<std::uint32_t>(node_id), 4);
  put_i32(frame, 0, static_cast<std::int32_t>(position_counts));
  return frame;
}

CanFrame make_drive_txpdo(int node_id, std::uint16_t statusword, std::int32_t actual_counts) {
  CanFrame frame = frame_of(kTpdo1Base + static_cast<std::uint32_t>(node_id), 6);
  put_u16(frame, 0, statusword);
  put_i32(frame, 2, actual_counts);
  return frame;
}

CanFrame make_drive_rxpdo(int node_id, std::uint16_t controlword, std::int32_t target_counts) {
  CanFrame frame = frame_of(kRpdo1Base + static_cast<std::uint32_t>(node_id), 6);
  put_u16(frame, 0, controlword);
  put_i32(frame, 2, target_counts);
  return frame;
}

const char* emergency_text(std::uint16_t code) {
  switch (code) {
    case 0x0000: return "error reset";
    case 0x8110: return "CAN overrun";
    case 0x8120: return "CAN error passive";
    case 0x8130: return "life guard or heartbeat error";
    case 0x8140: return "recovered from bus off";
    case 0x8210: return "PDO not processed: length error";
    case 0x8220: return "PDO length exceeded";
    case 0x8611: return "following error";
    case 0x8612: return "reference limit";
    default: break;
  }
  switch (code >> 12) {
    case 0x1: return "generic error";
    case 0x2: return "current";
    case 0x3: return "voltage";
    case 0x4: return "temperature";
    case 0x5: return "device hardware";
    case 0x6: return "device software";
    case 0x7: return "additional modules";
    case 0x8: return "monitoring";
    case 0x9: return "external error";
    case 0xF: return code >= 0xFF00 ? "device specific" : "additional functions";
    default: return "unknown error code";
  }
}

std::optional<NmtCommandFrame> parse_nmt(const CanFrame& frame) {
  if (frame.id != kNmtCobId || frame.len != 2 || frame.data[1] > kMaxNodeId) return std::nullopt;
  switch (static_cast<NmtCommand>(frame.data[0])) {
    case NmtCommand::kStart:
    case NmtCommand::kStop:
    case NmtCommand::kEnterPreOperational:
    case NmtCommand::kResetNode:
    case NmtCommand::kResetCommunication:
      return NmtCommandFrame{static_cast<NmtCommand>(frame.data[0]), frame.data[1]};
  }
  return std::nullopt;
}

std::optional<NmtState> parse_heartbeat(const CanFrame& frame) {
  if (frame.len != 1) return std::nullopt;
  switch (static_cast<NmtState>(frame.data[0] & 0x7F)) {  // bit 7: toggle of node guarding
    case NmtState::kBootUp:
    case NmtState::kStopped:
    case NmtState::kOperational:
    case NmtState::kPreOperational:
      return static_cast<NmtState>(frame.data[0] & 0x7F);
  }
  return std::nullopt;
}

std::optional<std::uint32_t> parse_encoder_tpdo(const CanFrame& frame) {
  if (frame.len < 4) return std::nullopt;
  return get_u32(frame, 0);
}

std::optional<DriveTxPdo> parse_drive_txpdo(const CanFrame& frame) {
  if (frame.len != 6) return std::nullopt;
  return DriveTxPdo{get_u16(frame, 0), get_i32(frame, 2)};
}

std::optional<DriveRxPdo> parse_drive_rxpdo(const CanFrame& frame) {
  if (frame.len != 6) return std::nullopt;
  return DriveRxPdo{get_u16(frame, 0), get_i32(frame, 2)};
}

}  // namespace cdpr::drivers::can
