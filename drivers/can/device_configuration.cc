#include "drivers/can/device_configuration.h"

#include <cmath>
#include <string>

namespace cdpr::drivers::can {
namespace {

using Kind = SdoStep::Kind;
constexpr std::uint32_t kInvalid = 0x80000000u;
// COB-ID bit 30 (TPDO: no RTR; RPDO: reserved) is the device's to keep:
// devices without RTR hold it at 1 whatever is written (Lika, CiA 406
// encoders), so a read back compares the rest.
constexpr std::uint32_t kCobIdCompared = ~0x40000000u;
constexpr std::uint8_t kTypeEventDriven = 254;
constexpr std::uint8_t kTypeEventDrivenProfile = 255;

std::uint32_t mapping(std::uint16_t index, std::uint8_t subindex, std::uint8_t bits) {
  return static_cast<std::uint32_t>(index) << 16 | static_cast<std::uint32_t>(subindex) << 8 | bits;
}

std::uint32_t milliseconds(hal::TimeUs us) { return static_cast<std::uint32_t>(us / 1000); }

std::uint32_t counts(double metres, double m_per_count) {
  return static_cast<std::uint32_t>(std::llround(metres / std::abs(m_per_count)));
}

SdoStep cob_id_step(SdoStep::Kind kind, std::uint16_t index, std::uint32_t value, const char* what, bool optional) {
  SdoStep step{kind, index, 1, 4, value, what};
  step.optional = optional;
  step.compare_mask = kCobIdCompared;
  return step;
}

void identity(std::vector<SdoStep>& steps, std::uint32_t vendor, std::uint32_t product) {
  if (vendor != 0) steps.push_back({Kind::kExpect, 0x1018, 1, 4, vendor, "vendor id"});
  if (product != 0) steps.push_back({Kind::kExpect, 0x1018, 2, 4, product, "product code"});
}

// One PDO: invalid, mapping cleared, entries, count, transmission type,
// event timer (TPDOs), valid on `cob_id`.
void pdo(std::vector<SdoStep>& steps, bool transmit, int number, std::uint32_t cob_id,
         const std::vector<std::uint32_t>& entries, std::uint8_t type, std::uint32_t event_ms) {
  const auto communication = static_cast<std::uint16_t>((transmit ? 0x1800 : 0x1400) + number - 1);
  const auto map = static_cast<std::uint16_t>(communication + 0x200);
  const char* cob = transmit ? "TPDO COB-ID" : "RPDO COB-ID";
  steps.push_back(cob_id_step(Kind::kWrite, communication, kInvalid | cob_id, cob, false));
  steps.push_back({Kind::kWriteVerify, map, 0, 1, 0, "PDO mapping count"});
  for (std::size_t i = 0; i < entries.size(); ++i) {
    steps.push_back({Kind::kWriteVerify, map, static_cast<std::uint8_t>(i + 1), 4, entries[i], "PDO mapping entry"});
  }
  steps.push_back({Kind::kWriteVerify, map, 0, 1, static_cast<std::uint32_t>(entries.size()), "PDO mapping count"});
  SdoStep transmission{Kind::kWriteVerify, communication, 2, 1, type, "PDO transmission type"};
  // 255 (device profile specific) and 254 (manufacturer specific) are both
  // event-driven; devices that lack 255 refuse it (Lika).
  transmission.has_fallback = type == kTypeEventDrivenProfile;
  transmission.fallback = kTypeEventDriven;
  steps.push_back(transmission);
  if (transmit) {
    // Changes (a moving position changes every cycle) at most 4 times per event period.
    steps.push_back({Kind::kWriteVerify, communication, 3, 2, event_ms * 10 / 4, "TPDO inhibit time"});
    steps.push_back({Kind::kWriteVerify, communication, 5, 2, event_ms, "TPDO event timer"});
  }
  steps.push_back(cob_id_step(Kind::kWriteVerify, communication, cob_id, cob, false));
}

void disable_pdos(std::vector<SdoStep>& steps, int node_id, bool receive) {
  const auto id = static_cast<std::uint32_t>(node_id);
  for (int n = 1; n < 4; ++n) {
    const auto offset = static_cast<std::uint32_t>(0x100 * n);
    // Optional: a device with fewer PDOs (2-TPDO encoders) has no object to switch off.
    if (receive) {
      steps.push_back(cob_id_step(Kind::kWriteVerify, static_cast<std::uint16_t>(0x1400 + n),
                                  kInvalid | (0x200 + offset + id), "unused RPDO COB-ID", true));
    }
    steps.push_back(cob_id_step(Kind::kWriteVerify, static_cast<std::uint16_t>(0x1800 + n),
                                kInvalid | (0x180 + offset + id), "unused TPDO COB-ID", true));
  }
}

}  // namespace

std::string validate(const DriveDescription& d) {
  const int q = d.quick_stop_option;
  if (q != 0 && q != 1 && q != 2 && q != 5 && q != 6) return "quick_stop_option must be 0, 1, 2, 5 or 6";
  if (d.abort_connection_option < 0 || d.abort_connection_option > 3) return "abort_connection_option must be 0..3";
  for (double v : {d.following_error_window_m, d.profile_velocity_mps, d.profile_acceleration_mps2,
                   d.profile_deceleration_mps2, d.quick_stop_deceleration_mps2}) {
    if (!(v > 0.0) || !std::isfinite(v)) return "following error window, profile and quick-stop values must be positive";
  }
  if (d.position_limit_min_counts >= d.position_limit_max_counts) return "position limits: min must be below max";
  if (d.heartbeat_producer_us < 1000 || d.heartbeat_producer_us > 65'535'000) return "heartbeat producer time out of 1..65535 ms";
  if (d.consumer_heartbeat_us < 1000 || d.consumer_heartbeat_us > 65'535'000) return "consumer heartbeat time out of 1..65535 ms";
  if (d.pdo_event_timer_us < 1000 || d.pdo_event_timer_us > 65'535'000) return "PDO event timer out of 1..65535 ms";
  return {};
}

std::string validate(const EncoderDescription& e) {
  if (e.code_sequence < -1 || e.code_sequence > 1) return "code_sequence must be -1 (not checked), 0 or 1";
  if (e.heartbeat_producer_us < 1000 || e.heartbeat_producer_us > 65'535'000) return "heartbeat producer time out of 1..65535 ms";
  if (e.pdo_event_timer_us < 1000 || e.pdo_event_timer_us > 65'535'000) return "PDO event timer out of 1..65535 ms";
  return {};
}

std::vector<SdoStep> drive_probe(const DriveDescription& d) {
  std::vector<SdoStep> steps;
  identity(steps, d.vendor_id, d.product_code);
  SdoStep units{Kind::kRead, 0x60A9, 0, 4, 0, "SI unit velocity"};
  units.optional = true;
  SdoStep max_speed{Kind::kRead, 0x6080, 0, 4, 0, "max motor speed"};
  max_speed.optional = true;
  steps.push_back(units);
  steps.push_back(max_speed);
  // The rest of the unit objects (drive_units.h), each where the drive has it.
  for (const SdoStep& s : {SdoStep{Kind::kRead, 0x60AA, 0, 4, 0, "SI unit acceleration"},
                           SdoStep{Kind::kRead, 0x6091, 1, 4, 0, "gear ratio motor revolutions"},
                           SdoStep{Kind::kRead, 0x6091, 2, 4, 0, "gear ratio shaft revolutions"},
                           SdoStep{Kind::kRead, 0x6096, 1, 4, 0, "velocity factor numerator"},
                           SdoStep{Kind::kRead, 0x6096, 2, 4, 0, "velocity factor divisor"},
                           SdoStep{Kind::kRead, 0x6097, 1, 4, 0, "acceleration factor numerator"},
                           SdoStep{Kind::kRead, 0x6097, 2, 4, 0, "acceleration factor divisor"}}) {
    steps.push_back(s);
    steps.back().optional = true;
  }
  return steps;
}

std::vector<SdoStep> drive_configuration(int node_id, int master_node_id, double m_per_count, const DriveUnits& units,
                                         const DriveDescription& d) {
  const auto id = static_cast<std::uint32_t>(node_id);
  std::vector<SdoStep> steps;
  pdo(steps, false, 1, 0x200 + id, {mapping(0x6040, 0, 16), mapping(0x607A, 0, 32)}, kTypeEventDrivenProfile, 0);
  pdo(steps, true, 1, 0x180 + id, {mapping(0x6041, 0, 16), mapping(0x6064, 0, 32)}, kTypeEventDrivenProfile,
      milliseconds(d.pdo_event_timer_us));
  disable_pdos(steps, node_id, true);
  steps.push_back({Kind::kWriteVerify, 0x605A, 0, 2, static_cast<std::uint32_t>(d.quick_stop_option), "quick stop option code"});
  steps.push_back({Kind::kWriteVerify, 0x6007, 0, 2, static_cast<std::uint32_t>(d.abort_connection_option),
                   "abort connection option code"});
  steps.push_back({Kind::kWriteVerify, 0x6065, 0, 4, counts(d.following_error_window_m, m_per_count), "following error window"});
  steps.push_back({Kind::kWriteVerify, 0x607D, 1, 4, static_cast<std::uint32_t>(d.position_limit_min_counts),
                   "software position limit min"});
  steps.push_back({Kind::kWriteVerify, 0x607D, 2, 4, static_cast<std::uint32_t>(d.position_limit_max_counts),
                   "software position limit max"});
  steps.push_back({Kind::kWriteVerify, 0x6081, 0, 4, drive_value(units, d.profile_velocity_mps), "profile velocity"});
  steps.push_back(
      {Kind::kWriteVerify, 0x6083, 0, 4, drive_acceleration(units, d.profile_acceleration_mps2), "profile acceleration"});
  steps.push_back(
      {Kind::kWriteVerify, 0x6084, 0, 4, drive_acceleration(units, d.profile_deceleration_mps2), "profile deceleration"});
  steps.push_back({Kind::kWriteVerify, 0x6085, 0, 4, drive_acceleration(units, d.quick_stop_deceleration_mps2),
                   "quick stop deceleration"});
  steps.push_back({Kind::kWriteVerify, 0x1017, 0, 2, milliseconds(d.heartbeat_producer_us), "producer heartbeat time"});
  steps.push_back({Kind::kWriteVerify, 0x1016, 1, 4,
                   static_cast<std::uint32_t>(master_node_id) << 16 | milliseconds(d.consumer_heartbeat_us),
                   "consumer heartbeat time of the master"});
  return steps;
}

std::vector<SdoStep> encoder_configuration(int node_id, const EncoderDescription& e) {
  const auto id = static_cast<std::uint32_t>(node_id);
  std::vector<SdoStep> steps;
  identity(steps, e.vendor_id, e.product_code);
  pdo(steps, true, 1, 0x180 + id, {mapping(0x6004, 0, 32)}, kTypeEventDriven, milliseconds(e.pdo_event_timer_us));
  disable_pdos(steps, node_id, false);
  steps.push_back({Kind::kWriteVerify, 0x1017, 0, 2, milliseconds(e.heartbeat_producer_us), "producer heartbeat time"});
  if (e.code_sequence >= 0) {
    SdoStep code{Kind::kExpect, 0x6000, 0, 2, static_cast<std::uint32_t>(e.code_sequence), "code sequence (bit 0)"};
    code.compare_mask = 0x0001;
    steps.push_back(code);
  }
  if (e.counts_per_revolution != 0) {
    steps.push_back({Kind::kExpect, 0x6001, 0, 4, e.counts_per_revolution, "measuring units per revolution"});
  }
  if (e.measuring_range != 0) steps.push_back({Kind::kExpect, 0x6002, 0, 4, e.measuring_range, "total measuring range"});
  steps.push_back({Kind::kRead, 0x6002, 0, 4, 0, "total measuring range"});
  return steps;
}

std::vector<SdoStep> drive_mode_check() {
  return {{Kind::kWrite, 0x6060, 0, 1, 1, "modes of operation"},
          {Kind::kExpect, 0x6061, 0, 1, 1, "modes of operation display (1 = profile position)"}};
}

}  // namespace cdpr::drivers::can
