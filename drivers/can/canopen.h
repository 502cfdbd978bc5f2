#pragma once
// CANopen (CiA 301) frames this driver uses, and the PDO mappings it
// configures in every node over SDO (device_configuration.h) before starting
// it. All multi-byte values little-endian, as CiA 301 requires.
//
//   NMT command      COB-ID 0x000           [command, node id (0 = all)]
//   Heartbeat        COB-ID 0x700 + node    [NMT state]
//   Encoder TPDO1    COB-ID 0x180 + node    CiA 406: [position value 0x6004 uint32,
//                                                     wraps at 0x6002]
//   Drive TxPDO1     COB-ID 0x180 + node    CiA 402: [statusword 0x6041 uint16,
//                                                     position actual 0x6064 int32]
//   Drive RxPDO1     COB-ID 0x200 + node    CiA 402: [controlword 0x6040 uint16,
//                                                     target position 0x607A int32]
//   EMCY             COB-ID 0x080 + node    [error code uint16, error register, 5 vendor bytes]
// Drives run in profile position mode (0x6060 = 1), written and checked
// before every enable.
// Pure functions, no I/O.

#include <cstdint>
#include <optional>

#include "drivers/can/can_frame.h"

namespace cdpr::drivers::can {

constexpr std::uint32_t kNmtCobId = 0x000;
constexpr std::uint32_t kTpdo1Base = 0x180;
constexpr std::uint32_t kRpdo1Base = 0x200;
constexpr std::uint32_t kHeartbeatBase = 0x700;
constexpr std::uint32_t kEmergencyBase = 0x080;
constexpr int kMaxNodeId = 127;

enum class NmtCommand : std::uint8_t {
  kStart = 0x01,
  kStop = 0x02,
  kEnterPreOperational = 0x80,
  kResetNode = 0x81,
  kResetCommunication = 0x82,
};

enum class NmtState : std::uint8_t {
  kBootUp = 0x00,
  kStopped = 0x04,
  kOperational = 0x05,
  kPreOperational = 0x7F,
};

// "boot-up", "stopped", "operational", "pre-operational".
const char* to_string(NmtState state);

// Node id of a frame in the function-code range `base` (e.g. kHeartbeatBase),
// or nullopt when the frame is of another kind.
std::optional<int> node_of(const CanFrame& frame, std::uint32_t base);

CanFrame make_nmt(NmtCommand command, int node_id);
CanFrame make_heartbeat(int node_id, NmtState state);
CanFrame make_encoder_tpdo(int node_id, std::uint32_t position_counts);
CanFrame make_drive_txpdo(int node_id, std::uint16_t statusword, std::int32_t actual_counts);
CanFrame make_drive_rxpdo(int node_id, std::uint16_t controlword, std::int32_t target_counts);

// The class or meaning of an EMCY error code (CiA 301 error code table, CiA
// 402 and 406 additions): "following error", "voltage", ...
const char* emergency_text(std::uint16_t code);

// Decoders: nullopt when the length is wrong (the id is the caller's check).
struct NmtCommandFrame {
  NmtCommand command;
  int node_id;  // 0 = all nodes
};
std::optional<NmtCommandFrame> parse_nmt(const CanFrame& frame);
std::optional<NmtState> parse_heartbeat(const CanFrame& frame);
std::optional<std::uint32_t> parse_encoder_tpdo(const CanFrame& frame);
struct DriveTxPdo {
  std::uint16_t statusword;
  std::int32_t actual_counts;
};
std::optional<DriveTxPdo> parse_drive_txpdo(const CanFrame& frame);
struct DriveRxPdo {
  std::uint16_t controlword;
  std::int32_t target_counts;
};
std::optional<DriveRxPdo> parse_drive_rxpdo(const CanFrame& frame);

}  // namespace cdpr::drivers::can
