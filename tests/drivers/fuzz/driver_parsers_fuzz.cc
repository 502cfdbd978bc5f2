// libFuzzer target for the drivers' parsers of outside input: pose lines,
// CAN wire records and CANopen frames, load-cell registers. The first byte
// picks the parser; the rest is the input. A crash or sanitizer report is a
// bug; refusals are the expected outcome.
//
// Build (not part of the default build; clang and its libFuzzer runtime):
//   clang++ -std=c++20 -g -O1 -fsanitize=fuzzer,address,undefined \
//     -I<build>/include_views/drivers -I<build>/include_views/hal \
//     tests/drivers/fuzz/driver_parsers_fuzz.cc drivers/pose/pose_line.cc \
//     drivers/can/canopen.cc drivers/can/cia402.cc drivers/can/fd_can_transport.cc \
//     drivers/common/*.cc drivers/modbus/tension_registers.cc -o driver_parsers_fuzz
//   ./driver_parsers_fuzz -max_total_time=60

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "drivers/can/canopen.h"
#include "drivers/can/cia402.h"
#include "drivers/can/fd_can_transport.h"
#include "drivers/modbus/tension_registers.h"
#include "drivers/pose/pose_line.h"

namespace {

using namespace cdpr::drivers;

void fuzz_pose_line(const std::uint8_t* data, std::size_t size) {
  cdpr::hal::PoseSample sample;
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  if (pose::parse_pose_line(line, sample) != pose::PoseLineResult::kSample) return;
  const auto& q = sample.world_R_platform;
  const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!std::isfinite(sample.platform_world.x + sample.platform_world.y + sample.platform_world.z) ||
      std::abs(norm - 1.0) > 1e-9) {
    std::abort();  // accepted values must be what the protocol promises
  }
}

void fuzz_can(const std::uint8_t* data, std::size_t size) {
  if (size < can::kWireFrameBytes) return;
  can::CanFrame frame;
  if (!can::decode_wire_frame(data, frame)) return;
  if (frame.len > 8 || frame.id > can::kMaxStandardId) std::abort();
  (void)can::parse_nmt(frame);
  (void)can::parse_heartbeat(frame);
  (void)can::parse_encoder_tpdo(frame);
  if (auto pdo = can::parse_drive_txpdo(frame)) (void)can::cia402::decode_power_state(pdo->statusword);
  if (auto pdo = can::parse_drive_rxpdo(frame)) {
    (void)can::cia402::next_power_state(can::cia402::PowerState::kOperationEnabled, pdo->controlword, 0);
  }
}

void fuzz_registers(const std::uint8_t* data, std::size_t size) {
  std::uint16_t registers[modbus::kTensionRegisterCount] = {};
  std::memcpy(registers, data, size < sizeof(registers) ? size : sizeof(registers));
  const auto decoded = modbus::decode_tension_registers(registers, modbus::WordOrder::kLowWordFirst);
  if (decoded.ok() && !std::isfinite(decoded.value().tension_n)) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  switch (data[0] % 3) {
    case 0: fuzz_pose_line(data + 1, size - 1); break;
    case 1: fuzz_can(data + 1, size - 1); break;
    default: fuzz_registers(data + 1, size - 1); break;
  }
  return 0;
}
