#include "src/daemon/daemon_config.h"

#include <optional>

#include "src/daemon/config_checks.h"
#include "src/daemon/config_table.h"
#include "src/daemon/load_cell_presets.h"
#include "src/formats/text_file.h"
#include "src/formats/toml_reader.h"

namespace cdpr::daemon {
namespace {

using calibration::CalibratorOptions;
using calibration::PlannerOptions;
using calibration::ValidationLimits;
using drivers::can::CanWinchConfig;
using drivers::can::DriveDescription;
using drivers::can::EncoderDescription;
using drivers::modbus::ByteOrder;
using drivers::modbus::ForceUnit;
using drivers::modbus::RegisterKind;
using drivers::modbus::ValueType;
using formats::TomlReader;
constexpr TimeUnit kMs = TimeUnit::kMilliseconds;
constexpr TimeUnit kS = TimeUnit::kSeconds;
constexpr IntRange kNodeId{1, 127};
constexpr IntRange kUnsigned32{0, 0xFFFFFFFFll, true};
constexpr IntRange kRegister{0, 65535};
constexpr IntRange kMask16{0, 0xFFFF, true};

// What getgrnam() can be asked for and chown() given: a portable group name
// (useradd's rules, Samba's trailing '$' included) or a decimal id.
bool is_group_name_or_id(const std::string& group) {
  if (group.size() > 32 || group.front() == '-') return false;
  const std::size_t last = group.back() == '$' ? group.size() - 1 : group.size();
  for (std::size_t i = 0; i < last; ++i) {
    const char c = group[i];
    const bool allowed = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                         c == '_' || c == '-';
    if (!allowed) return false;
  }
  return last > 0;
}

// ---- The tables, in the order of the file ----

Table<DaemonConfig> top_table() {
  Table<DaemonConfig> t("");
  t.string("robot", &DaemonConfig::robot_path, "", "robot.toml: nominal geometry, cable data and sensor noise")
      .required();
  return t;
}

Table<store::StoreOptions> store_table() {
  Table<store::StoreOptions> t("store");
  t.string("state_dir", &store::StoreOptions::state_dir, "/var/lib/cdpr-calib",
           "state directory: calibration.toml, history/, pending/, the run marker and the lock");
  t.integer("history_depth", &store::StoreOptions::history_depth, 10, {0, 1000}, "",
            "previous calibrations kept besides the current one");
  return t;
}

Table<DaemonConfig> control_table() {
  Table<DaemonConfig> t("control");
  t.string("socket", &DaemonConfig::control_socket, "/run/cdpr-calib/control",
           "calibctl's Unix stream socket (mode 0660)");
  t.string("group", &DaemonConfig::control_socket_group, "",
           "the socket's group; absent: the daemon's own group (the unit's Group=)")
      .refusing("group name or numeric id", [](const DaemonConfig& c) -> std::string {
        if (is_group_name_or_id(c.control_socket_group)) return "";
        return "\"" + c.control_socket_group +
               "\" is not a group name (letters, digits, '.', '_', '-'; at most 32) or a numeric group id";
      });
  return t;
}

Table<DaemonConfig> loop_table() {
  Table<DaemonConfig> t("loop");
  t.duration("period_ms", &DaemonConfig::loop_period_us, 20, kMs,
             "state-machine step; the watchdog is pinged every step");
  return t;
}

Table<WinchesConfig> winches_table() {
  Table<WinchesConfig> t("winches");
  t.string("endpoint", &WinchesConfig::endpoint, "socketcan:can0",
           "\"socketcan:<interface>\", or \"unix:<path>\" for CAN frames over a Unix socket (the virtual robot)");
  t.duration("heartbeat_timeout_ms", &WinchesConfig::heartbeat_timeout_us, 500, kMs,
             "a node silent this long is lost (>= 1.5 x its producer period)");
  t.duration("resend_interval_ms", &WinchesConfig::resend_interval_us, 100, kMs,
             "NMT start / controlword resend while nothing moves on");
  t.number("max_move_m", &WinchesConfig::max_move_m, 250.0, kPositive, "m",
           "a target farther than this from the payout is refused");
  t.number("max_speed_mps", &WinchesConfig::max_speed_mps, 10.0, kPositive, "m/s",
           "an encoder change faster than this between two readings is a fault (real time)");
  t.integer("master_node_id", &WinchesConfig::master_node_id, 127, kNodeId, "",
            "the daemon's CANopen node id: heartbeat 0x700 + this");
  t.duration("master_heartbeat_ms", &WinchesConfig::master_heartbeat_us, 100, kMs,
             "the daemon's heartbeat period; the drives stop when it stays away");
  t.duration("sdo_timeout_ms", &WinchesConfig::sdo_timeout_us, 200, kMs,
             "an SDO transfer without an answer this long is aborted");
  return t;
}

// The CiA 301 identity (0x1018) a node must report, drive and encoder alike.
template <class Description>
void identity_rows(Table<Description>& t) {
  t.integer("vendor_id", &Description::vendor_id, 0, kUnsigned32, "", "0x1018:01 expected; 0: not checked");
  t.integer("product_code", &Description::product_code, 0, kUnsigned32, "", "0x1018:02 expected; 0: not checked");
}

Table<DriveDescription> drive_table() {
  Table<DriveDescription> t("winches.drive");
  identity_rows(t);
  t.integer("quick_stop_option", &DriveDescription::quick_stop_option, 6, {0, 6}, "",
            "0x605A: 0, 1, 2 (end switched off) or 5, 6 (stay in quick stop)")
      .refusing("0, 1, 2, 5, 6", [](const DriveDescription& d) -> std::string {
        if (d.quick_stop_option != 3 && d.quick_stop_option != 4) return "";
        return "must be 0, 1, 2, 5 or 6 (3 and 4 stop at a current or voltage limit), got " +
               std::to_string(d.quick_stop_option);
      });
  t.integer("abort_connection_option", &DriveDescription::abort_connection_option, 3, {0, 3}, "",
            "0x6007, the reaction to the daemon's heartbeat lost: 0 none, 1 fault, 2 off, 3 quick stop");
  t.number("following_error_window_m", &DriveDescription::following_error_window_m, 0.1, kPositive, "m",
           "0x6065, of payout");
  t.number("profile_velocity_mps", &DriveDescription::profile_velocity_mps, 2.0, kPositive, "m/s",
           "0x6081 of the longest winch of a move; the others are scaled down");
  t.number("profile_acceleration_mps2", &DriveDescription::profile_acceleration_mps2, 1.0, kPositive, "m/s^2",
           "0x6083, scaled the same way");
  t.number("profile_deceleration_mps2", &DriveDescription::profile_deceleration_mps2, 1.0, kPositive, "m/s^2",
           "0x6084, scaled the same way");
  t.number("quick_stop_deceleration_mps2", &DriveDescription::quick_stop_deceleration_mps2, 2.0, kPositive, "m/s^2",
           "0x6085");
  t.duration("heartbeat_producer_ms", &DriveDescription::heartbeat_producer_us, 100, kMs, "0x1017 of the drive");
  t.duration("consumer_heartbeat_ms", &DriveDescription::consumer_heartbeat_us, 500, kMs,
             "0x1016: the drive quick-stops when the daemon is silent this long (> master_heartbeat_ms)");
  t.duration("pdo_event_timer_ms", &DriveDescription::pdo_event_timer_us, 20, kMs,
             "TPDO1 (statusword + position) at least this often");
  return t;
}

Table<EncoderDescription> encoder_table() {
  Table<EncoderDescription> t("winches.encoder");
  identity_rows(t);
  t.duration("heartbeat_producer_ms", &EncoderDescription::heartbeat_producer_us, 100, kMs,
             "0x1017 of the encoder");
  t.duration("pdo_event_timer_ms", &EncoderDescription::pdo_event_timer_us, 20, kMs,
             "TPDO1 (position value 0x6004) period");
  return t;
}

// One table per cable, in robot.toml's [[winch]] order.
Table<CanWinchConfig> winch_table() {
  Table<CanWinchConfig> t("winches.winch");
  t.integer("drive_node_id", &CanWinchConfig::drive_node_id, IntDefault::per_cable(1), kNodeId, "",
            "CiA 402 drive");
  t.integer("encoder_node_id", &CanWinchConfig::encoder_node_id, IntDefault::per_cable(11), {0, 127}, "",
            "CiA 406 encoder; 0: use the drive's position");
  t.number("encoder_m_per_count", &CanWinchConfig::encoder_m_per_count, 1e-5, kNonZero, "m",
           "payout per encoder count; the sign gives the direction");
  t.number("drive_m_per_count", &CanWinchConfig::drive_m_per_count, 1e-5, kNonZero, "m",
           "payout per drive position count");
  return t;
}

Table<LoadCellConfig> load_cell_table() {
  Table<LoadCellConfig> t("load_cell");
  t.string("endpoint", &LoadCellConfig::endpoint, "rtu:/dev/ttyUSB0",
           "\"tcp:<host>:<port>\" (Modbus TCP) or \"rtu:<serial device>\" (Modbus RTU)");
  t.integer("baud", &LoadCellConfig::baud, 19200, {300, 4'000'000}, "bit/s", "RTU only");
  t.choice("parity", &LoadCellConfig::parity, {{"N", 'N'}, {"E", 'E'}, {"O", 'O'}}, 'N', "RTU only");
  t.integer("data_bits", &LoadCellConfig::data_bits, 8, {5, 8}, "", "RTU only");
  t.integer("stop_bits", &LoadCellConfig::stop_bits, 1, {1, 2}, "", "RTU only");
  t.integer("slave_id", &LoadCellConfig::slave_id, 1, {0, 255}, "",
            "unit identifier: RTU 1..247 (0 is broadcast); TCP 0..247 or 255");
  t.choice("register_kind", &LoadCellConfig::register_kind,
           {{"holding", RegisterKind::kHolding}, {"input", RegisterKind::kInput}}, RegisterKind::kHolding,
           "read holding (function 0x03) or input (0x04) registers");
  std::vector<std::pair<std::string, std::string>> presets;
  for (const std::string_view name : load_cell_preset_names()) presets.emplace_back(name, name);
  t.choice("preset", &LoadCellConfig::preset, presets, std::string("legacy-float32"),
           "the transmitter's register map (docs/fieldbus.md); the keys below override its values")
      .then([](LoadCellConfig& c) { c.map = *load_cell_preset(c.preset); });
  // The map's keys; their defaults are those of the default preset.
  t.integer("value_address", [](auto& c) -> auto& { return c.map.value_address; }, 0, kRegister, "",
            "protocol address (0-based: a manual's 40001 is 0); within 16 registers of the status");
  t.choice("value_type", [](auto& c) -> auto& { return c.map.value_type; },
           {{"float32", ValueType::kFloat32}, {"int32", ValueType::kInt32}, {"uint32", ValueType::kUint32},
            {"int16", ValueType::kInt16}, {"uint16", ValueType::kUint16}},
           ValueType::kFloat32, "the value's encoding");
  t.choice("byte_order", [](auto& c) -> auto& { return c.map.byte_order; },
           {{"ABCD", ByteOrder::kABCD}, {"CDAB", ByteOrder::kCDAB}, {"BADC", ByteOrder::kBADC},
            {"DCBA", ByteOrder::kDCBA}},
           ByteOrder::kABCD, "bytes A (most significant) .. D as the registers carry them");
  t.integer("decimals", [](auto& c) -> auto& { return c.map.decimals; }, 0, {0, 9}, "",
            "integer values: the number / 10^decimals");
  t.number("scale", [](auto& c) -> auto& { return c.map.scale; }, 1.0, kNonZero, "",
           "times the value, before the unit (-1 for a reversed cell)");
  t.choice("unit", [](auto& c) -> auto& { return c.map.unit; },
           {{"N", ForceUnit::kNewton}, {"kg", ForceUnit::kKilogram}, {"lbf", ForceUnit::kPoundForce}},
           ForceUnit::kNewton, "the value's unit (kg: kilogram-force)");
  t.integer("status_address", [](auto& c) -> auto& { return c.map.status_address; }, 2, {-1, 65535}, "",
            "-1: the device has no status register");
  t.integer("stable_mask", [](auto& c) -> auto& { return c.map.stable.mask; }, 0x0001, kMask16, "",
            "status bits meaning \"stable\"; 0: always stable");
  t.choice("stable_when", [](auto& c) -> auto& { return c.map.stable.active_when_set; },
           {{"set", true}, {"clear", false}}, true, "stable when a bit is set, or when all are clear");
  t.integer("error_mask", [](auto& c) -> auto& { return c.map.error.mask; }, 0x0002, kMask16, "",
            "status bits meaning \"error\"; 0: never an error");
  t.choice("error_when", [](auto& c) -> auto& { return c.map.error.active_when_set; },
           {{"set", true}, {"clear", false}}, true, "an error when any is set, or when all are clear (\"data ok\")");
  t.integer("sign_mask", [](auto& c) -> auto& { return c.map.sign_mask; }, 0, kMask16, "",
            "the value is a magnitude, negative when one of these bits is set; 0: signed value");
  t.duration("response_timeout_ms", &LoadCellConfig::response_timeout_us, 200, kMs, "per try of a read");
  t.integer("retries", &LoadCellConfig::retries, 2, {0, 10}, "",
            "per read on timeouts, CRC or framing errors, lost connections (never on an exception reply)");
  t.duration("poll_interval_ms", &LoadCellConfig::poll_interval_us, 20, kMs,
             "one read every this long, on a thread of its own");
  t.duration("fault_timeout_ms", &LoadCellConfig::fault_timeout_us, 1000, kMs,
             "no good reading for this long stops a run");
  return t;
}

Table<PoseConfig> pose_table() {
  Table<PoseConfig> t("pose");
  t.string("endpoint", &PoseConfig::endpoint, "tcp:127.0.0.1:5600",
           "the localization system's pose stream: \"tcp:<host>:<port>\" or \"unix:<path>\"");
  t.duration("connect_timeout_ms", &PoseConfig::connect_timeout_us, 1000, kMs, "");
  return t;
}

Table<ButtonConfig> button_table() {
  Table<ButtonConfig> t("button");
  t.choice("kind", &ButtonConfig::gpio, {{"gpio", true}, {"none", false}}, true,
           "a GPIO line (libgpiod), or none: start only with `calibctl start`");
  t.string("chip", &ButtonConfig::chip, "gpiochip0", "name, number or /dev path");
  t.integer("line", &ButtonConfig::line, 17, {0, 65535}, "", "line offset on the chip");
  t.boolean("active_low", &ButtonConfig::active_low, true, "");
  t.duration("debounce_ms", &ButtonConfig::debounce_us, 50, kMs, "");
  return t;
}

Table<CalibratorOptions> limits_table() {
  Table<CalibratorOptions> t("limits");
  t.number("min_tension", [](auto& o) -> auto& { return o.monitor.min_tension_n; }, 20.0, kNonNegative, "N",
           "reference cable (load cell), checked every step while the winches may move");
  t.number("max_tension", [](auto& o) -> auto& { return o.monitor.max_tension_n; }, 5000.0, kPositive, "N", "");
  t.duration("pose_stale_ms", [](auto& o) -> auto& { return o.monitor.pose_stale_us; }, 500, kMs,
             "oldest acceptable pose sample");
  t.integer("max_consecutive_load_cell_errors",
            [](auto& o) -> auto& { return o.monitor.max_consecutive_load_cell_errors; }, 3, {0, 1000}, "",
            "failed reads tolerated in a row");
  t.duration("first_contact_timeout_s", &CalibratorOptions::first_contact_timeout_us, 3.0, kS,
             "preflight waits this long for every node's first heartbeat, the first pose and load-cell reading");
  t.duration("enable_timeout_s", &CalibratorOptions::enable_timeout_us, 5.0, kS,
             "drives must reach \"operation enabled\" within this");
  t.duration("move_timeout_s", &CalibratorOptions::move_timeout_us, 600.0, kS,
             "winches must reach a waypoint within this (else a fault)");
  t.duration("settle_timeout_s", &CalibratorOptions::settle_timeout_us, 60.0, kS,
             "no equilibrium within this: the waypoint is skipped");
  return t;
}

Table<PlannerOptions> waypoints_table() {
  Table<PlannerOptions> t("waypoints");
  t.integer("count", &PlannerOptions::waypoint_count, 35, {1, 10'000}, "", "static poses per calibration");
  t.number("margin", &PlannerOptions::margin_m, 20.0, kNonNegative, "m",
           "inset from the anchors' horizontal footprint");
  t.number("z_min", &PlannerOptions::z_min_m, 5.0, kAnyNumber, "m", "world height band of the platform origin");
  t.number("z_max", &PlannerOptions::z_max_m, 35.0, kAnyNumber, "m", "");
  t.integer("grid_xy", &PlannerOptions::grid_xy, 8, {1, 1000}, "", "candidate grid per horizontal axis");
  t.integer("grid_z", &PlannerOptions::grid_z, 4, {1, 1000}, "", "candidate grid along z");
  t.number("jitter", &PlannerOptions::jitter_fraction, 0.3, {0.0, 0.5, false, true}, "",
           "candidate jitter, fraction of the grid step");
  t.integer("seed", &PlannerOptions::seed, 1, {0, 2'147'483'647}, "", "same seed, same plan");
  t.number("min_tension", &PlannerOptions::min_tension_n, 20.0, kNonNegative, "N",
           "every cable at every waypoint (catenary statics)");
  t.number("max_tension", &PlannerOptions::max_tension_n, 3000.0, kPositive, "N", "");
  t.number("min_payout", &PlannerOptions::min_payout_m, -1e9, kAnyNumber, "m",
           "winch travel limits in encoder units");
  t.number("max_payout", &PlannerOptions::max_payout_m, 1e9, kAnyNumber, "m", "");
  t.number("max_sag_excess", &PlannerOptions::max_sag_excess, 0.02, kPositive, "",
           "(arc length - chord) / chord of every cable at most this");
  t.choice("selection", &PlannerOptions::selection,
           {{"spread", calibration::WaypointSelection::kSpread},
            {"informative", calibration::WaypointSelection::kInformative}},
           calibration::WaypointSelection::kSpread,
           "evenly over the feasible candidates, or those that determine anchors and offsets best");
  return t;
}

Table<CalibratorOptions> equilibrium_table() {
  Table<CalibratorOptions> t("equilibrium");
  t.duration("window_s", [](auto& o) -> auto& { return o.equilibrium.window_us; }, 2.0, kS,
             "rest window averaged into one sample row, in the pose source's own time");
  t.integer("min_samples", [](auto& o) -> auto& { return o.equilibrium.min_samples; }, 20, {4, 1'000'000}, "",
            "poses in the window; it reaches further back to hold them");
  t.number("max_speed", [](auto& o) -> auto& { return o.equilibrium.max_speed_mps; }, 0.002, kPositive, "m/s",
           "platform speed");
  t.number("max_angular_rate", [](auto& o) -> auto& { return o.equilibrium.max_angular_rate_radps; }, 0.002,
           kPositive, "rad/s", "");
  t.number("max_tension_std", [](auto& o) -> auto& { return o.equilibrium.max_tension_std_n; }, 10.0, kPositive,
           "N", "load-cell standard deviation over the window");
  t.integer("capacity", &CalibratorOptions::equilibrium_capacity, 1024, {2, 10'000'000}, "",
            "ring size, >= window x pose rate with margin");
  return t;
}

Table<CalibrationOptions> solver_table() {
  Table<CalibrationOptions> t("solver");
  t.choice("cable_model", &CalibrationOptions::cable_model,
           {{"catenary", CableModelKind::kCatenary}, {"rigid", CableModelKind::kRigid}}, CableModelKind::kCatenary,
           "");
  t.number("huber_width", &CalibrationOptions::huber_width, 0.0, kNonNegative, "sigma",
           "robust loss width; 0: none");
  t.integer("max_iterations", &CalibrationOptions::max_iterations, 1000, {1, 100'000}, "",
            "stopping early refuses the fit");
  return t;
}

Table<ValidationLimits> validation_table() {
  Table<ValidationLimits> t("validation");
  t.boolean("accept_max_iterations", &ValidationLimits::accept_max_iterations, false,
            "accept a fit that ran out of iterations");
  t.integer("min_samples", &ValidationLimits::min_samples, 10, {1, 100'000}, "", "settled waypoints needed");
  t.number("max_rms_encoder_sigmas", &ValidationLimits::max_rms_encoder_sigmas, 3.0, kPositive, "sigma",
           "rms encoder residual, in robot.toml noise.encoder");
  t.number("max_rms_force_sigmas", &ValidationLimits::max_rms_force_sigmas, 3.0, kPositive, "sigma",
           "rms force residual, in noise.force");
  t.number("max_anchor_sigma", &ValidationLimits::max_anchor_sigma_m, 0.05, kPositive, "m",
           "1-sigma per anchor axis");
  t.number("max_offset_sigma", &ValidationLimits::max_offset_sigma_m, 0.05, kPositive, "m",
           "1-sigma per encoder offset");
  t.number("max_anchor_change", &ValidationLimits::max_anchor_change_m, 0.5, kNonNegative, "m",
           "per anchor, from the previous calibration; 0: not checked");
  return t;
}

// ---- The tables bound to DaemonConfig ----

using Values = std::map<std::string, std::string>;

// One table of the file and where in DaemonConfig its values go.
struct Section {
  std::string path;
  std::vector<KeyInfo> keys;  // with their defaults
  std::vector<std::string> sub_tables;  // names of the tables inside it
  std::function<void(DaemonConfig&)> set_defaults;
  // Reads the section's TOML table (already looked up, its keys checked).
  std::function<void(TomlReader&, const toml::table&, DaemonConfig&)> read;
  std::function<void(const DaemonConfig&, Values&)> values;
  bool array = false;  // [[path]]: one table per cable
};

template <class T>
std::vector<KeyInfo> infos(const Table<T>& table) {
  std::vector<KeyInfo> keys;
  for (const Row<T>& row : table.rows()) {
    KeyInfo info = row.info;
    T value{};
    row.set_default(value, 0);
    info.default_text = row.show(value);
    T second{};
    row.set_default(second, 1);
    if (row.show(second) != info.default_text) info.default_text += ", " + row.show(second) + ", ... by cable";
    if (info.default_text == "\"\"") info.default_text.clear();
    keys.push_back(std::move(info));
  }
  return keys;
}

template <class T>
void add_values(const Table<T>& table, const std::string& path, const T& target, Values& out) {
  for (const Row<T>& row : table.rows()) out[formats::join_key(path, row.info.name)] = row.show(target);
}

// `access` takes a DaemonConfig (const or not) to the table's struct.
template <class T, class Access>
Section bind(Table<T> table, Access access) {
  Section s;
  s.path = table.path();
  s.keys = infos(table);
  s.set_defaults = [table, access](DaemonConfig& c) { table.set_defaults(access(c)); };
  s.read = [table, access](TomlReader& reader, const toml::table& t, DaemonConfig& c) {
    table.read(reader, t, table.path(), access(c), c.key_lines);
  };
  s.values = [table, access](const DaemonConfig& c, Values& out) { add_values(table, table.path(), access(c), out); };
  return s;
}

// [[winches.winch]]: none given, the defaults; else exactly one per cable.
Section bind_cables(Table<CanWinchConfig> table) {
  Section s;
  s.path = table.path();
  s.keys = infos(table);
  s.array = true;
  s.set_defaults = [table](DaemonConfig& c) {
    c.winches.winches.assign(kCableCount, CanWinchConfig{});
    for (int i = 0; i < kCableCount; ++i) table.set_defaults(c.winches.winches[static_cast<std::size_t>(i)], i);
  };
  s.read = [table](TomlReader& reader, const toml::table& parent, DaemonConfig& c) {
    const std::string_view name = "winch";
    if (!parent.contains(name)) return;
    const auto tables = reader.tables(parent, name, "winches");
    if (!reader.failed() && tables.size() != static_cast<std::size_t>(kCableCount)) {
      reader.fail(TomlReader::line_of(*parent.get(name)), table.path(),
                  "found " + std::to_string(tables.size()) + " [[winches.winch]] tables, need " +
                      std::to_string(kCableCount) + " (one per cable)");
    }
    std::vector<std::string_view> names;
    for (const Row<CanWinchConfig>& row : table.rows()) names.push_back(row.info.name);
    c.winches.winches.assign(tables.size(), CanWinchConfig{});
    for (std::size_t i = 0; i < tables.size(); ++i) {
      const std::string path = table.path() + "[" + std::to_string(i) + "]";
      refuse_unknown_keys(reader, *tables[i], path, names);
      table.set_defaults(c.winches.winches[i], static_cast<int>(i));
      table.read(reader, *tables[i], path, c.winches.winches[i], c.key_lines);
    }
  };
  s.values = [table](const DaemonConfig& c, Values& out) {
    for (std::size_t i = 0; i < c.winches.winches.size(); ++i) {
      add_values(table, table.path() + "[" + std::to_string(i) + "]", c.winches.winches[i], out);
    }
  };
  return s;
}

std::vector<Section> make_sections() {
  std::vector<Section> s;
  s.push_back(bind(top_table(), [](auto& c) -> auto& { return c; }));
  s.push_back(bind(store_table(), [](auto& c) -> auto& { return c.store; }));
  s.push_back(bind(control_table(), [](auto& c) -> auto& { return c; }));
  s.push_back(bind(loop_table(), [](auto& c) -> auto& { return c; }));
  s.push_back(bind(winches_table(), [](auto& c) -> auto& { return c.winches; }));
  s.push_back(bind(drive_table(), [](auto& c) -> auto& { return c.winches.drive; }));
  s.push_back(bind(encoder_table(), [](auto& c) -> auto& { return c.winches.encoder; }));
  s.push_back(bind_cables(winch_table()));
  s.push_back(bind(load_cell_table(), [](auto& c) -> auto& { return c.load_cell; }));
  s.push_back(bind(pose_table(), [](auto& c) -> auto& { return c.pose; }));
  s.push_back(bind(button_table(), [](auto& c) -> auto& { return c.button; }));
  s.push_back(bind(limits_table(), [](auto& c) -> auto& { return c.calibrator; }));
  s.push_back(bind(waypoints_table(), [](auto& c) -> auto& { return c.calibrator.planner; }));
  s.push_back(bind(equilibrium_table(), [](auto& c) -> auto& { return c.calibrator; }));
  s.push_back(bind(solver_table(), [](auto& c) -> auto& { return c.solver; }));
  s.push_back(bind(validation_table(), [](auto& c) -> auto& { return c.calibrator.validation; }));
  // Each table's sub-tables are keys it allows.
  for (Section& parent : s) {
    for (const Section& child : s) {
      const std::size_t dot = child.path.rfind('.');
      const std::string child_parent = dot == std::string::npos ? "" : child.path.substr(0, dot);
      if (&child != &parent && !child.path.empty() && child_parent == parent.path) {
        parent.sub_tables.push_back(dot == std::string::npos ? child.path : child.path.substr(dot + 1));
      }
    }
  }
  return s;
}

const std::vector<Section>& sections() {
  static const std::vector<Section> all = make_sections();
  return all;
}

// The TOML table at dotted `path` ("" is the root); an empty one when absent.
const toml::table& table_at(TomlReader& reader, const toml::table& root, std::string_view path) {
  const toml::table* table = &root;
  std::size_t begin = 0;
  while (begin < path.size()) {
    const std::size_t dot = std::min(path.find('.', begin), path.size());
    table = &reader.table(*table, path.substr(begin, dot - begin), path.substr(0, begin == 0 ? 0 : begin - 1),
                          formats::Presence::kOptional);
    begin = dot + 1;
  }
  return *table;
}

DaemonConfig read_config(TomlReader& reader, const toml::table& root) {
  DaemonConfig c = default_daemon_config();
  for (const Section& section : sections()) {
    if (reader.failed()) break;
    if (section.array) {
      section.read(reader, table_at(reader, root, section.path.substr(0, section.path.rfind('.'))), c);
      continue;
    }
    const toml::table& table = table_at(reader, root, section.path);
    std::vector<std::string_view> names;
    for (const KeyInfo& key : section.keys) names.push_back(key.name);
    for (const std::string& sub : section.sub_tables) names.push_back(sub);
    refuse_unknown_keys(reader, table, section.path, names);
    section.read(reader, table, c);
  }
  return c;
}

}  // namespace

DaemonConfig default_daemon_config() {
  DaemonConfig c;
  for (const Section& section : sections()) section.set_defaults(c);
  return c;
}

std::vector<KeyInfo> daemon_config_keys() {
  std::vector<KeyInfo> keys;
  for (const Section& section : sections()) keys.insert(keys.end(), section.keys.begin(), section.keys.end());
  return keys;
}

std::map<std::string, std::string> daemon_config_values(const DaemonConfig& config) {
  Values values;
  for (const Section& section : sections()) section.values(config, values);
  return values;
}

Expected<DaemonConfig, FormatError> parse_daemon_config(std::string_view text, const std::string& source) {
  auto config = formats::parse_toml<DaemonConfig>(text, source, read_config);
  if (!config) return config;
  config->source = source;
  if (std::optional<FormatError> problem = check_cross_keys(*config)) return Unexpected{std::move(*problem)};
  return config;
}

Expected<DaemonConfig, FormatError> read_daemon_config(const std::string& path) {
  return formats::parse_file(path, parse_daemon_config);
}

}  // namespace cdpr::daemon
