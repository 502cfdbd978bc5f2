#pragma once
// cdpr-calibd's configuration file (/etc/cdpr-calib/cdpr-calibd.toml). Every
// key is one row of the tables in daemon_config.cc, with its type, unit,
// range, default and meaning; docs/configuration.md lists them and the
// example systemd/cdpr-calibd.toml shows each with its default (tests hold
// both to the tables). `robot` and the three device endpoints are required.
//
// Errors (chrony conf.c): unknown keys (with the nearest known name), wrong
// types and values out of range are refused at parse time with file, line
// and dotted key ("cdpr-calibd.toml:40: winches.winch[2].drive_node_id:
// must be in 1..127, got 300"), then missing required keys, then values
// that defeat a safety function unless `unsafe_ok` lists their key, then
// keys that disagree with each other (config_checks.h). Never throws.
//
// The drivers' settings are the drivers' own configurations, which main()
// hands over as they are.

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/can/canopen_winch_bank.h"
#include "drivers/can/listening_winch_bank.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "hal/clock.h"
#include "solver/calibration/calibrate.h"
#include "solver/model/robot.h"
#include "src/calibration/calibration_state_machine.h"
#include "src/formats/expected.h"
#include "src/formats/format_error.h"
#include "src/store/calibration_store.h"

namespace cdpr::daemon {

// [winches], [winches.drive], [winches.encoder] and [[winches.winch]].
struct WinchesConfig : drivers::can::CanWinchBankConfig {
  std::string endpoint;  // "socketcan:<interface>" or "unix:<path>"
};

// [load_cell]: the Modbus driver's settings, and how the daemon polls it.
struct LoadCellConfig : drivers::modbus::ModbusLoadCellConfig {
  std::string preset;                // the register map `map` started from; the keys beside it override it
  hal::TimeUs poll_interval_us = 0;  // the reader thread's read period
  hal::TimeUs fault_timeout_us = 0;  // no good reading for this long: a fault
};

struct PoseConfig {
  std::string endpoint;  // "tcp:<host>:<port>" or "unix:<path>"
  hal::TimeUs connect_timeout_us = 0;
};

struct ButtonConfig {
  bool gpio = false;  // kind = "gpio"; false: kind = "none" (calibctl start only)
  std::string chip;
  int line = 0;
  bool active_low = false;
  hal::TimeUs debounce_us = 0;
};

// [operation]: the daemon between calibration runs, next to the robot's
// own controller (docs/operation.md). watch = true: the CAN bus
// is only listened to (the listener's layout below), every rest the
// platform makes is checked against the committed calibration, and its
// pose from the cables is served on pose_output.
struct OperationConfig {
  bool watch = false;
  // Where the pose from the cables goes: "unix:<path>" (the daemon listens,
  // every client gets a line per rest, docs/FORMATS.md "Pose from the
  // cables"); empty: not served.
  std::string pose_output;
  // The watch's rest detection: the [equilibrium] thresholds with these
  // windows (a production rest is seconds, a calibration waypoint's minutes).
  hal::TimeUs rest_window_us = 2'000'000;
  hal::TimeUs return_window_us = 6'000'000;
  // Health watch: the designed false-alarm rate, one per this many clean rests.
  double clean_rests_per_false_alarm = 1000.0;
  drivers::can::ListenLayout listen;
};

// [history]: every run's data kept in the store's history (run_recorder.h).
struct HistoryConfig {
  double budget_mb = 0.0;    // disk budget of history/run-* [MB]
  bool model_check = false;  // run the model check after each solve
};

using KeyLines = std::map<std::string, int, std::less<>>;

// A value given in the file that defeats a safety function (the row says
// which values do): refused unless unsafe_ok names its key.
struct UnsafeValue {
  std::string key;     // dotted, as unsafe_ok names it
  int line = 0;
  std::string reason;  // what the value gives up
};

// The daemon's defaults are the tables' (default_daemon_config()); a
// value-initialized DaemonConfig has only the libraries' own defaults.
struct DaemonConfig {
  std::string robot_path;  // robot.toml
  // Keys allowed a value that defeats a safety function (unsafe_ok); the
  // values so accepted, which the daemon names at start.
  std::vector<std::string> unsafe_ok;
  std::vector<UnsafeValue> unsafe_accepted;
  store::StoreOptions store;
  HistoryConfig history;
  std::string control_socket;
  // Group given the control socket (mode 0660): its members may control the
  // daemon. A group name or a numeric id; empty: the daemon's own group.
  std::string control_socket_group;
  hal::TimeUs loop_period_us = 0;
  WinchesConfig winches;
  LoadCellConfig load_cell;
  PoseConfig pose;
  ButtonConfig button;
  calibration::CalibratorOptions calibrator;  // [limits], [waypoints], [equilibrium], [validation]
  CalibrationOptions solver;                  // [solver]
  OperationConfig operation;                  // [operation]

  // Where the configuration came from and the line of every key it set
  // ("waypoints.z_max" -> 57), so that checks spanning several keys can
  // name a line too. Keys left at their default are absent.
  std::string source;
  KeyLines key_lines;
};

// One key of the file, as its table row describes it.
struct KeyInfo {
  std::string table;         // dotted TOML table ("winches.drive"; "" at the top)
  std::string name;
  std::string type;          // "integer", "number", "string", "boolean", or the choices
  std::string unit;          // "m", "N", "ms", ...; empty: none
  std::string range;         // "1..127", "> 0", "[0, 0.5)", ...; empty: any value of its type
  std::string range_reason;  // why the range is what it is
  std::string unsafe_when;   // the values inside the range that need unsafe_ok; empty: none
  std::string default_text;  // as TOML text; empty: none
  std::string meaning;
  bool required = false;
};

// A DaemonConfig with the tables' defaults.
DaemonConfig default_daemon_config();

// Every key, table by table in the order of the example, with its default.
std::vector<KeyInfo> daemon_config_keys();
// Every key's value in `config` as TOML text, by dotted key
// ("winches.winch[2].drive_node_id"; "robot" too).
std::map<std::string, std::string> daemon_config_values(const DaemonConfig& config);

// `source` names the input in messages (usually its path).
Expected<DaemonConfig, FormatError> parse_daemon_config(std::string_view text, const std::string& source);
Expected<DaemonConfig, FormatError> read_daemon_config(const std::string& path);

// The checks that need robot.toml (config_checks.cc): the workspace the
// margin leaves inside the anchors and the z band below them. nullopt when
// the configuration suits the robot.
std::optional<FormatError> check_config_against_robot(const DaemonConfig& config, const Robot& robot);

// The checks that look at the file system, before anything is opened
// (config_checks.cc): robot names a readable file, store.state_dir is a
// directory or absent. nullopt when both hold.
std::optional<FormatError> check_config_paths(const DaemonConfig& config);

}  // namespace cdpr::daemon
