#pragma once
// cdpr-calibd's configuration file (/etc/cdpr-calib/cdpr-calibd.toml): the
// keys, tables, defaults and units are exactly those documented in
// systemd/cdpr-calibd.toml, the example that ships with the unit. Only
// `robot` is required; every other key has the default shown there.
//
// Errors (STYLE.md, chrony conf.c): unknown keys, wrong types and values out
// of range are refused at parse time with file, line and dotted key
// ("cdpr-calibd.toml:40: winches.winch[2].drive_node_id: ..."). Never throws.
//
// Driver settings are plain values here (src/ does not see drivers/);
// main() turns them into the drivers' own configurations.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hal/clock.h"
#include "solver/calibration/calibrate.h"
#include "solver/model/robot.h"
#include "src/calibration/calibration_state_machine.h"
#include "src/daemon/load_cell_presets.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"
#include "src/store/calibration_store.h"

namespace cdpr::daemon {

struct WinchNodes {
  int drive_node_id = 1;              // CiA 402 drive, 1..127
  int encoder_node_id = 11;           // CiA 406 encoder, 1..127; 0: use the drive's position
  double encoder_m_per_count = 1e-5;  // payout per encoder count [m], sign = direction, != 0
  double drive_m_per_count = 1e-5;    // payout per drive count [m], != 0
};

// What the master writes into every CiA 402 drive before starting it
// (drivers/can/device_configuration.h), in metres, seconds and CiA codes.
struct CanDriveDescription {
  std::int64_t vendor_id = 0;     // 0x1018:01 expected; 0: not checked
  std::int64_t product_code = 0;  // 0x1018:02 expected; 0: not checked
  int quick_stop_option = 6;        // 0x605A
  int abort_connection_option = 3;  // 0x6007: reaction to the master's heartbeat lost
  double following_error_window_m = 0.1;      // 0x6065
  double profile_velocity_mps = 2.0;          // 0x6081
  double profile_acceleration_mps2 = 1.0;     // 0x6083
  double profile_deceleration_mps2 = 1.0;     // 0x6084
  double quick_stop_deceleration_mps2 = 2.0;  // 0x6085
  hal::TimeUs heartbeat_producer_us = 100'000;  // 0x1017
  hal::TimeUs consumer_heartbeat_us = 500'000;  // 0x1016:01, monitoring the master
  hal::TimeUs pdo_event_timer_us = 20'000;      // TPDO1 0x1800:05
};

struct CanEncoderDescription {
  std::int64_t vendor_id = 0;
  std::int64_t product_code = 0;
  hal::TimeUs heartbeat_producer_us = 100'000;
  hal::TimeUs pdo_event_timer_us = 20'000;
};

struct WinchesConfig {
  std::string endpoint = "socketcan:can0";  // or "unix:<path>"
  hal::TimeUs heartbeat_timeout_us = 500'000;
  hal::TimeUs resend_interval_us = 100'000;
  double max_move_m = 250.0;    // largest |target - payout| of one command [m]
  double max_speed_mps = 10.0;  // fastest payout change; a larger jump between readings is a fault [m/s]
  int master_node_id = 127;     // heartbeat producer 0x700 + this
  hal::TimeUs master_heartbeat_us = 100'000;
  hal::TimeUs sdo_timeout_us = 200'000;
  CanDriveDescription drive;      // [winches.drive]
  CanEncoderDescription encoder;  // [winches.encoder]
  std::vector<WinchNodes> winches;  // in cable order; default: drives 1..4, encoders 11..14
};

struct LoadCellConfig {
  std::string endpoint = "rtu:/dev/ttyUSB0";  // or "tcp:<host>:<port>"
  int baud = 19200;
  char parity = 'N';  // 'N', 'E', 'O'
  int data_bits = 8;
  int stop_bits = 1;
  int slave_id = 1;                // RTU 1..247; TCP 0..247 or 255
  bool input_registers = false;  // register_kind = "input" (0x04) instead of "holding" (0x03)
  std::string preset = "legacy-float32";
  LoadCellMapConfig map;         // the preset's, with the keys given beside it
  hal::TimeUs response_timeout_us = 200'000;
  int retries = 2;
  hal::TimeUs poll_interval_us = 20'000;     // the reader thread's read period
  hal::TimeUs fault_timeout_us = 1'000'000;  // no good reading for this long: a fault
};

struct PoseConfig {
  std::string endpoint = "tcp:127.0.0.1:5600";  // or "unix:<path>"
  hal::TimeUs connect_timeout_us = 1'000'000;
};

struct ButtonConfig {
  bool gpio = true;  // kind = "gpio"; false: kind = "none" (calibctl start only)
  std::string chip = "gpiochip0";
  int line = 17;
  bool active_low = true;
  hal::TimeUs debounce_us = 50'000;
};

struct DaemonConfig {
  std::string robot_path;  // robot.toml
  store::StoreOptions store{"/var/lib/cdpr-calib", 10};
  std::string control_socket = "/run/cdpr-calib/control";
  // Group given the control socket (mode 0660): its members may control the
  // daemon. A group name or a numeric id; empty: the daemon's own group.
  std::string control_socket_group;
  hal::TimeUs loop_period_us = 20'000;
  WinchesConfig winches;
  LoadCellConfig load_cell;
  PoseConfig pose;
  ButtonConfig button;
  calibration::CalibratorOptions calibrator;  // [limits], [waypoints], [equilibrium], [validation]
  CalibrationOptions solver;                  // [solver]

  // Where the configuration came from and the line of every key it set
  // ("waypoints.z_max" -> 57), so that checks spanning several keys can
  // name a line too. Keys left at their default are absent.
  std::string source;
  std::map<std::string, int, std::less<>> key_lines;
};

// A DaemonConfig with the defaults of systemd/cdpr-calibd.toml.
DaemonConfig default_daemon_config();

// `source` names the input in messages (usually its path).
Expected<DaemonConfig, FormatError> parse_daemon_config(std::string_view text, const std::string& source);
Expected<DaemonConfig, FormatError> read_daemon_config(const std::string& path);

// The checks that need robot.toml (config_checks.cc): the workspace the
// margin leaves inside the anchors and the z band below them. nullopt when
// the configuration suits the robot.
std::optional<FormatError> check_config_against_robot(const DaemonConfig& config, const Robot& robot);

}  // namespace cdpr::daemon
