#pragma once
// What the master writes into and checks in each node before it is started
// (CiA 301 configure-and-verify in pre-operational), from a small
// description per device type taken from the daemon's configuration.
//
// Drive (CiA 402, profile position):
//   identity 0x1018:01/02 (when given), RPDO1 = controlword 0x6040 +
//   target position 0x607A on 0x200 + node, TPDO1 = statusword 0x6041 +
//   position actual 0x6064 on 0x180 + node (type 255, event timer, inhibit
//   time a quarter of it so a moving position is not sent every cycle), PDOs 2-4
//   invalid; 0x605A, 0x6007, 0x6065, 0x607D, 0x6081, 0x6083, 0x6084, 0x6085
//   in the drive's units (drive_units.h: 0x60A9 and 0x6080 read first by
//   drive_probe());
//   heartbeat producer 0x1017 and consumer 0x1016:01 of the master.
//   Before every enable: 0x6060 = 1 written, 0x6061 = 1 checked.
// Encoder (CiA 406): identity, TPDO1 = position value 0x6004 on
//   0x180 + node (type 254, event timer), PDOs 2-4 invalid, 0x1017, the
//   code sequence 0x6000 bit 0 and resolution 0x6001 compared with the
//   configuration (when given), and the total measuring range 0x6002 read
//   (0x6004 wraps there) and compared (when given).
// Each PDO is invalidated (COB-ID bit 31) before its mapping changes, as
// CiA 301 requires. Devices differ (docs/fieldbus.md, "Vendor quirks"): an
// unused PDO the device does not have (abort 0x06020000) is skipped;
// COB-ID bit 30 is compared on read back only as the device keeps it;
// transmission type 255 refused is written as 254. Units: descriptions in metres and seconds, converted
// to the node's counts with the winch's m_per_count.

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/can/drive_units.h"
#include "drivers/can/node_configurator.h"
#include "hal/clock.h"

namespace cdpr::drivers::can {

struct DriveDescription {
  std::string eds;                  // the drives' EDS/DCF file (eds.h); empty: CiA 402 defaults assumed
  std::uint32_t vendor_id = 0;      // 0x1018:01 expected; 0: not checked
  std::uint32_t product_code = 0;   // 0x1018:02 expected; 0: not checked
  int quick_stop_option = 6;        // 0x605A: 6 = quick-stop ramp, stay in quick stop active
  int abort_connection_option = 3;  // 0x6007: 3 = quick stop when the master's heartbeat is lost
  double following_error_window_m = 0.1;      // 0x6065
  double profile_velocity_mps = 2.0;          // 0x6081
  double profile_acceleration_mps2 = 1.0;     // 0x6083
  double profile_deceleration_mps2 = 1.0;     // 0x6084
  double quick_stop_deceleration_mps2 = 2.0;  // 0x6085
  std::int32_t position_limit_min_counts = INT32_MIN;  // 0x607D:01
  std::int32_t position_limit_max_counts = INT32_MAX;  // 0x607D:02
  hal::TimeUs heartbeat_producer_us = 100'000;  // 0x1017
  hal::TimeUs consumer_heartbeat_us = 500'000;  // 0x1016:01: the drive stops when the master is silent this long
  hal::TimeUs pdo_event_timer_us = 20'000;      // 0x1800:05
};

struct EncoderDescription {
  std::string eds;  // the encoders' EDS/DCF file; empty: CiA 406 defaults assumed
  // Checked against the device (a replacement encoder set up differently
  // would silently reverse or rescale the payout): -1 / 0: not checked.
  int code_sequence = -1;                  // 0x6000 bit 0: 0 counts up clockwise, 1 counter-clockwise
  std::uint32_t counts_per_revolution = 0; // 0x6001 measuring units per revolution
  std::uint32_t measuring_range = 0;       // 0x6002 total measuring range
  std::uint32_t vendor_id = 0;
  std::uint32_t product_code = 0;
  hal::TimeUs heartbeat_producer_us = 100'000;
  hal::TimeUs pdo_event_timer_us = 20'000;
};

// Empty when valid, else the first problem.
std::string validate(const DriveDescription& drive);
std::string validate(const EncoderDescription& encoder);

// What the drive is asked first: identity, 0x60A9 and 0x6080 (both
// optional: kRead steps without a value when the drive lacks them).
std::vector<SdoStep> drive_probe(const DriveDescription& drive);
// The rest, once the units are known from the probe.
std::vector<SdoStep> drive_configuration(int node_id, int master_node_id, double m_per_count, const DriveUnits& units,
                                         const DriveDescription& drive);
std::vector<SdoStep> encoder_configuration(int node_id, const EncoderDescription& encoder);
// Profile position mode, written and checked before every enable.
std::vector<SdoStep> drive_mode_check();

}  // namespace cdpr::drivers::can
