#include "src/daemon/daemon_config.h"

#include <cmath>
#include <optional>

#include "src/daemon/config_checks.h"
#include "src/formats/text_file.h"
#include "src/formats/toml_reader.h"

namespace cdpr::daemon {
namespace {

using formats::Bound;
using formats::join_key;
using formats::KeySpec;
using formats::Presence;
using formats::TomlReader;
constexpr Presence kOptional = Presence::kOptional;

// Optional keys with defaults and ranges, on top of TomlReader (which reads
// required keys and numbers). A value outside its range fails naming it.
class ConfigReader {
 public:
  ConfigReader(TomlReader& reader, std::map<std::string, int, std::less<>>& key_lines)
      : reader_(reader), key_lines_(key_lines) {}

  void integer(const toml::table& t, std::string_view key, std::string_view path, int& out, long lo, long hi) {
    note_line(t, key, path);
    if (!t.contains(key) || reader_.failed()) return;
    const std::int64_t value = reader_.integer(t, key, path);
    if (reader_.failed()) return;
    if (value < lo || value > hi) {
      fail(t, key, path, "must be in " + std::to_string(lo) + ".." + std::to_string(hi));
      return;
    }
    out = static_cast<int>(value);
  }
  // An UNSIGNED32 (CANopen identity values).
  void unsigned32(const toml::table& t, std::string_view key, std::string_view path, std::int64_t& out) {
    if (!t.contains(key) || reader_.failed()) return;
    const std::int64_t value = reader_.integer(t, key, path);
    if (reader_.failed()) return;
    if (value < 0 || value > 0xFFFFFFFFll) return fail(t, key, path, "must be in 0..0xFFFFFFFF");
    out = value;
  }
  void number(const toml::table& t, std::string_view key, std::string_view path, double& out, Bound bound) {
    note_line(t, key, path);
    if (const auto value = reader_.optional_number(t, key, path, bound)) out = *value;
  }
  // A duration key in the unit its name gives (`_ms` or `_s`), > 0.
  void duration_us(const toml::table& t, std::string_view key, std::string_view path, hal::TimeUs& out,
                   double us_per_unit) {
    note_line(t, key, path);
    if (const auto value = reader_.optional_number(t, key, path, Bound::kPositive)) {
      out = static_cast<hal::TimeUs>(std::llround(*value * us_per_unit));
    }
  }
  void string(const toml::table& t, std::string_view key, std::string_view path, std::string& out) {
    note_line(t, key, path);
    if (!t.contains(key) || reader_.failed()) return;
    std::string value = reader_.string(t, key, path);
    if (!reader_.failed() && value.empty()) fail(t, key, path, "must not be empty");
    if (!reader_.failed()) out = std::move(value);
  }
  void boolean(const toml::table& t, std::string_view key, std::string_view path, bool& out) {
    note_line(t, key, path);
    const toml::node* node = t.get(key);
    if (node == nullptr || reader_.failed()) return;
    if (!node->is_boolean()) {
      fail(t, key, path, "expected true or false");
      return;
    }
    out = node->as_boolean()->get();
  }
  // One of `choices`; returns its index, or -1 when absent.
  int choice(const toml::table& t, std::string_view key, std::string_view path,
             std::initializer_list<std::string_view> choices) {
    std::string value;
    string(t, key, path, value);
    if (value.empty()) return -1;
    int index = 0;
    std::string allowed;
    for (const std::string_view c : choices) {
      if (c == value) return index;
      allowed += (index++ ? ", \"" : "\"") + std::string(c) + "\"";
    }
    fail(t, key, path, "\"" + value + "\" is not one of " + allowed);
    return -1;
  }
  void fail(const toml::table& t, std::string_view key, std::string_view path, const std::string& reason) {
    const toml::node* node = t.get(key);
    reader_.fail(node ? TomlReader::line_of(*node) : TomlReader::line_of(t), join_key(path, key), reason);
  }

 private:
  void note_line(const toml::table& t, std::string_view key, std::string_view path) {
    if (const toml::node* node = t.get(key)) key_lines_[join_key(path, key)] = TomlReader::line_of(*node);
  }

  TomlReader& reader_;
  std::map<std::string, int, std::less<>>& key_lines_;
};

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

void read_can_devices(TomlReader& reader, ConfigReader& r, const toml::table& winches, WinchesConfig& out) {
  const toml::table& d = reader.table(winches, "drive", "winches", kOptional);
  const char* dp = "winches.drive";
  reader.check_keys(d, dp, {{"vendor_id", kOptional}, {"product_code", kOptional}, {"quick_stop_option", kOptional},
                            {"abort_connection_option", kOptional}, {"following_error_window_m", kOptional},
                            {"profile_velocity_mps", kOptional}, {"profile_acceleration_mps2", kOptional},
                            {"profile_deceleration_mps2", kOptional}, {"quick_stop_deceleration_mps2", kOptional},
                            {"heartbeat_producer_ms", kOptional}, {"consumer_heartbeat_ms", kOptional},
                            {"pdo_event_timer_ms", kOptional}});
  CanDriveDescription& drive = out.drive;
  r.unsigned32(d, "vendor_id", dp, drive.vendor_id);
  r.unsigned32(d, "product_code", dp, drive.product_code);
  r.integer(d, "quick_stop_option", dp, drive.quick_stop_option, 0, 6);
  if (drive.quick_stop_option == 3 || drive.quick_stop_option == 4) {
    r.fail(d, "quick_stop_option", dp, "must be 0, 1, 2, 5 or 6 (3 and 4 stop at a current or voltage limit)");
  }
  r.integer(d, "abort_connection_option", dp, drive.abort_connection_option, 0, 3);
  r.number(d, "following_error_window_m", dp, drive.following_error_window_m, Bound::kPositive);
  r.number(d, "profile_velocity_mps", dp, drive.profile_velocity_mps, Bound::kPositive);
  r.number(d, "profile_acceleration_mps2", dp, drive.profile_acceleration_mps2, Bound::kPositive);
  r.number(d, "profile_deceleration_mps2", dp, drive.profile_deceleration_mps2, Bound::kPositive);
  r.number(d, "quick_stop_deceleration_mps2", dp, drive.quick_stop_deceleration_mps2, Bound::kPositive);
  r.duration_us(d, "heartbeat_producer_ms", dp, drive.heartbeat_producer_us, 1e3);
  r.duration_us(d, "consumer_heartbeat_ms", dp, drive.consumer_heartbeat_us, 1e3);
  r.duration_us(d, "pdo_event_timer_ms", dp, drive.pdo_event_timer_us, 1e3);
  if (drive.consumer_heartbeat_us <= out.master_heartbeat_us) {
    r.fail(d, "consumer_heartbeat_ms", dp, "must exceed winches.master_heartbeat_ms");
  }

  const toml::table& e = reader.table(winches, "encoder", "winches", kOptional);
  const char* ep = "winches.encoder";
  reader.check_keys(e, ep, {{"vendor_id", kOptional}, {"product_code", kOptional}, {"heartbeat_producer_ms", kOptional},
                            {"pdo_event_timer_ms", kOptional}});
  r.unsigned32(e, "vendor_id", ep, out.encoder.vendor_id);
  r.unsigned32(e, "product_code", ep, out.encoder.product_code);
  r.duration_us(e, "heartbeat_producer_ms", ep, out.encoder.heartbeat_producer_us, 1e3);
  r.duration_us(e, "pdo_event_timer_ms", ep, out.encoder.pdo_event_timer_us, 1e3);
}

void read_winches(TomlReader& reader, ConfigReader& r, const toml::table& root, WinchesConfig& out) {
  const toml::table& t = reader.table(root, "winches", "", kOptional);
  reader.check_keys(t, "winches", {{"endpoint", kOptional}, {"heartbeat_timeout_ms", kOptional},
                                   {"resend_interval_ms", kOptional}, {"winch", kOptional},
                                   {"max_move_m", kOptional}, {"max_speed_mps", kOptional},
                                   {"master_node_id", kOptional}, {"master_heartbeat_ms", kOptional},
                                   {"sdo_timeout_ms", kOptional}, {"drive", kOptional}, {"encoder", kOptional}});
  r.string(t, "endpoint", "winches", out.endpoint);
  r.duration_us(t, "heartbeat_timeout_ms", "winches", out.heartbeat_timeout_us, 1e3);
  r.duration_us(t, "resend_interval_ms", "winches", out.resend_interval_us, 1e3);
  r.number(t, "max_move_m", "winches", out.max_move_m, Bound::kPositive);
  r.number(t, "max_speed_mps", "winches", out.max_speed_mps, Bound::kPositive);
  r.integer(t, "master_node_id", "winches", out.master_node_id, 1, 127);
  r.duration_us(t, "master_heartbeat_ms", "winches", out.master_heartbeat_us, 1e3);
  r.duration_us(t, "sdo_timeout_ms", "winches", out.sdo_timeout_us, 1e3);
  read_can_devices(reader, r, t, out);
  if (!t.contains("winch")) return;
  const auto tables = reader.tables(t, "winch", "winches");
  if (!reader.failed() && tables.size() != static_cast<std::size_t>(kCableCount)) {
    r.fail(t, "winch", "winches", "found " + std::to_string(tables.size()) + " [[winches.winch]] tables, need " +
                                      std::to_string(kCableCount) + " (one per cable)");
  }
  out.winches.assign(tables.size(), WinchNodes{});
  for (std::size_t i = 0; i < tables.size(); ++i) {
    const std::string path = "winches.winch[" + std::to_string(i) + "]";
    reader.check_keys(*tables[i], path, {{"drive_node_id", kOptional}, {"encoder_node_id", kOptional},
                                         {"encoder_m_per_count", kOptional}, {"drive_m_per_count", kOptional}});
    WinchNodes& w = out.winches[i];
    w.drive_node_id = static_cast<int>(i) + 1;
    w.encoder_node_id = static_cast<int>(i) + 11;
    r.integer(*tables[i], "drive_node_id", path, w.drive_node_id, 1, 127);
    r.integer(*tables[i], "encoder_node_id", path, w.encoder_node_id, 0, 127);
    r.number(*tables[i], "encoder_m_per_count", path, w.encoder_m_per_count, Bound::kAny);
    r.number(*tables[i], "drive_m_per_count", path, w.drive_m_per_count, Bound::kAny);
    if (w.encoder_m_per_count == 0.0 || w.drive_m_per_count == 0.0) {
      r.fail(*tables[i], "drive_m_per_count", path, "metres per count must not be 0");
    }
  }
}

// The register map: a preset, then any key beside it overrides its value.
void read_load_cell_map(ConfigReader& r, const toml::table& t, LoadCellConfig& out) {
  const char* p = "load_cell";
  std::string preset;
  r.string(t, "preset", p, preset);
  if (!preset.empty()) {
    const std::optional<LoadCellMapConfig> map = load_cell_preset(preset);
    if (map) {
      out.preset = preset;
      out.map = *map;
    } else {
      std::string names;
      for (const std::string_view name : load_cell_preset_names()) names += (names.empty() ? "\"" : ", \"") + std::string(name) + "\"";
      r.fail(t, "preset", p, "\"" + preset + "\" is not one of " + names);
    }
  }
  LoadCellMapConfig& m = out.map;
  r.integer(t, "value_address", p, m.value_address, 0, 65535);
  if (const int type = r.choice(t, "value_type", p, {"float32", "int32", "uint32", "int16", "uint16"}); type >= 0) {
    r.string(t, "value_type", p, m.value_type);
  }
  if (const int order = r.choice(t, "byte_order", p, {"ABCD", "CDAB", "BADC", "DCBA"}); order >= 0) {
    r.string(t, "byte_order", p, m.byte_order);
  }
  r.integer(t, "decimals", p, m.decimals, 0, 9);
  r.number(t, "scale", p, m.scale, Bound::kAny);
  if (m.scale == 0.0) r.fail(t, "scale", p, "must not be 0");
  if (const int unit = r.choice(t, "unit", p, {"N", "kg", "lbf"}); unit >= 0) r.string(t, "unit", p, m.unit);
  r.integer(t, "status_address", p, m.status_address, -1, 65535);
  r.integer(t, "stable_mask", p, m.stable_mask, 0, 0xFFFF);
  if (const int when = r.choice(t, "stable_when", p, {"set", "clear"}); when >= 0) m.stable_when_set = when == 0;
  r.integer(t, "error_mask", p, m.error_mask, 0, 0xFFFF);
  if (const int when = r.choice(t, "error_when", p, {"set", "clear"}); when >= 0) m.error_when_set = when == 0;
  r.integer(t, "sign_mask", p, m.sign_mask, 0, 0xFFFF);
  if (m.status_address >= 0 && m.status_address >= m.value_address &&
      m.status_address < m.value_address + (m.value_type.ends_with("16") ? 1 : 2)) {
    r.fail(t, "status_address", p, "overlaps the value's registers");
  }
}

void read_load_cell(TomlReader& reader, ConfigReader& r, const toml::table& root, LoadCellConfig& out) {
  const toml::table& t = reader.table(root, "load_cell", "", kOptional);
  const char* p = "load_cell";
  reader.check_keys(t, p, {{"endpoint", kOptional}, {"baud", kOptional}, {"parity", kOptional},
                           {"data_bits", kOptional}, {"stop_bits", kOptional}, {"slave_id", kOptional},
                           {"register_kind", kOptional}, {"preset", kOptional}, {"value_address", kOptional},
                           {"value_type", kOptional}, {"byte_order", kOptional}, {"decimals", kOptional},
                           {"scale", kOptional}, {"unit", kOptional}, {"status_address", kOptional},
                           {"stable_mask", kOptional}, {"stable_when", kOptional}, {"error_mask", kOptional},
                           {"error_when", kOptional}, {"sign_mask", kOptional},
                           {"response_timeout_ms", kOptional}, {"retries", kOptional},
                           {"poll_interval_ms", kOptional}, {"fault_timeout_ms", kOptional}});
  r.string(t, "endpoint", p, out.endpoint);
  r.integer(t, "baud", p, out.baud, 300, 4'000'000);
  if (const int parity = r.choice(t, "parity", p, {"N", "E", "O"}); parity >= 0) out.parity = "NEO"[parity];
  r.integer(t, "data_bits", p, out.data_bits, 5, 8);
  r.integer(t, "stop_bits", p, out.stop_bits, 1, 2);
  // Unit identifiers per transport: on a serial line 0 is broadcast (nobody
  // answers) and 248-255 are reserved; a Modbus TCP device addressed
  // directly takes 0 or 255 (libmodbus 3.1 refuses 248-254).
  if (out.endpoint.starts_with("rtu:")) {
    r.integer(t, "slave_id", p, out.slave_id, 1, 247);
  } else {
    r.integer(t, "slave_id", p, out.slave_id, 0, 255);
    if (out.slave_id > 247 && out.slave_id < 255) r.fail(t, "slave_id", p, "on TCP must be 0..247 or 255");
  }
  if (const int kind = r.choice(t, "register_kind", p, {"holding", "input"}); kind >= 0) out.input_registers = kind;
  read_load_cell_map(r, t, out);
  r.duration_us(t, "response_timeout_ms", p, out.response_timeout_us, 1e3);
  r.integer(t, "retries", p, out.retries, 0, 10);
  r.duration_us(t, "poll_interval_ms", p, out.poll_interval_us, 1e3);
  r.duration_us(t, "fault_timeout_ms", p, out.fault_timeout_us, 1e3);
}

void read_io(TomlReader& reader, ConfigReader& r, const toml::table& root, DaemonConfig& c) {
  const toml::table& store = reader.table(root, "store", "", kOptional);
  reader.check_keys(store, "store", {{"state_dir", kOptional}, {"history_depth", kOptional}});
  r.string(store, "state_dir", "store", c.store.state_dir);
  r.integer(store, "history_depth", "store", c.store.history_depth, 0, 1000);

  const toml::table& control = reader.table(root, "control", "", kOptional);
  reader.check_keys(control, "control", {{"socket", kOptional}, {"group", kOptional}});
  r.string(control, "socket", "control", c.control_socket);
  r.string(control, "group", "control", c.control_socket_group);
  if (!c.control_socket_group.empty() && !is_group_name_or_id(c.control_socket_group)) {
    r.fail(control, "group", "control",
           "\"" + c.control_socket_group + "\" is not a group name (letters, digits, '.', '_', '-'; at most 32) "
           "or a numeric group id");
  }

  const toml::table& loop = reader.table(root, "loop", "", kOptional);
  reader.check_keys(loop, "loop", {{"period_ms", kOptional}});
  r.duration_us(loop, "period_ms", "loop", c.loop_period_us, 1e3);

  read_winches(reader, r, root, c.winches);
  read_load_cell(reader, r, root, c.load_cell);

  const toml::table& pose = reader.table(root, "pose", "", kOptional);
  reader.check_keys(pose, "pose", {{"endpoint", kOptional}, {"connect_timeout_ms", kOptional}});
  r.string(pose, "endpoint", "pose", c.pose.endpoint);
  r.duration_us(pose, "connect_timeout_ms", "pose", c.pose.connect_timeout_us, 1e3);

  const toml::table& button = reader.table(root, "button", "", kOptional);
  reader.check_keys(button, "button", {{"kind", kOptional}, {"chip", kOptional}, {"line", kOptional},
                                       {"active_low", kOptional}, {"debounce_ms", kOptional}});
  if (const int kind = r.choice(button, "kind", "button", {"gpio", "none"}); kind >= 0) c.button.gpio = kind == 0;
  r.string(button, "chip", "button", c.button.chip);
  r.integer(button, "line", "button", c.button.line, 0, 65535);
  r.boolean(button, "active_low", "button", c.button.active_low);
  r.duration_us(button, "debounce_ms", "button", c.button.debounce_us, 1e3);
}

void read_calibration(TomlReader& reader, ConfigReader& r, const toml::table& root, DaemonConfig& c) {
  calibration::CalibratorOptions& o = c.calibrator;
  const toml::table& limits = reader.table(root, "limits", "", kOptional);
  const char* p = "limits";
  reader.check_keys(limits, p, {{"min_tension", kOptional}, {"max_tension", kOptional}, {"pose_stale_ms", kOptional},
                                {"max_consecutive_load_cell_errors", kOptional}, {"first_contact_timeout_s", kOptional},
                                {"enable_timeout_s", kOptional},
                                {"move_timeout_s", kOptional}, {"settle_timeout_s", kOptional}});
  r.number(limits, "min_tension", p, o.monitor.min_tension_n, Bound::kNonNegative);
  r.number(limits, "max_tension", p, o.monitor.max_tension_n, Bound::kPositive);
  r.duration_us(limits, "pose_stale_ms", p, o.monitor.pose_stale_us, 1e3);
  r.integer(limits, "max_consecutive_load_cell_errors", p, o.monitor.max_consecutive_load_cell_errors, 0, 1000);
  r.duration_us(limits, "first_contact_timeout_s", p, o.first_contact_timeout_us, 1e6);
  r.duration_us(limits, "enable_timeout_s", p, o.enable_timeout_us, 1e6);
  r.duration_us(limits, "move_timeout_s", p, o.move_timeout_us, 1e6);
  r.duration_us(limits, "settle_timeout_s", p, o.settle_timeout_us, 1e6);

  calibration::PlannerOptions& w = o.planner;
  const toml::table& waypoints = reader.table(root, "waypoints", "", kOptional);
  p = "waypoints";
  reader.check_keys(waypoints, p, {{"count", kOptional}, {"margin", kOptional}, {"z_min", kOptional},
                                   {"z_max", kOptional}, {"grid_xy", kOptional}, {"grid_z", kOptional},
                                   {"jitter", kOptional}, {"seed", kOptional}, {"min_tension", kOptional},
                                   {"max_tension", kOptional}, {"min_payout", kOptional}, {"max_payout", kOptional},
                                   {"max_sag_excess", kOptional}, {"selection", kOptional}});
  r.integer(waypoints, "count", p, w.waypoint_count, 1, 10'000);
  r.number(waypoints, "margin", p, w.margin_m, Bound::kNonNegative);
  r.number(waypoints, "z_min", p, w.z_min_m, Bound::kAny);
  r.number(waypoints, "z_max", p, w.z_max_m, Bound::kAny);
  r.integer(waypoints, "grid_xy", p, w.grid_xy, 1, 1000);
  r.integer(waypoints, "grid_z", p, w.grid_z, 1, 1000);
  r.number(waypoints, "jitter", p, w.jitter_fraction, Bound::kNonNegative);
  int seed = static_cast<int>(w.seed);
  r.integer(waypoints, "seed", p, seed, 0, 2'147'483'647);
  w.seed = static_cast<std::uint32_t>(seed);
  r.number(waypoints, "min_tension", p, w.min_tension_n, Bound::kNonNegative);
  r.number(waypoints, "max_tension", p, w.max_tension_n, Bound::kPositive);
  r.number(waypoints, "min_payout", p, w.min_payout_m, Bound::kAny);
  r.number(waypoints, "max_payout", p, w.max_payout_m, Bound::kAny);
  r.number(waypoints, "max_sag_excess", p, w.max_sag_excess, Bound::kPositive);
  if (w.jitter_fraction >= 0.5) r.fail(waypoints, "jitter", p, "must be in [0, 0.5)");
  if (const int selection = r.choice(waypoints, "selection", p, {"spread", "informative"}); selection >= 0) {
    w.selection = selection == 0 ? calibration::WaypointSelection::kSpread : calibration::WaypointSelection::kInformative;
  }

  const toml::table& eq = reader.table(root, "equilibrium", "", kOptional);
  p = "equilibrium";
  reader.check_keys(eq, p, {{"window_s", kOptional}, {"min_samples", kOptional}, {"max_speed", kOptional},
                            {"max_angular_rate", kOptional}, {"max_tension_std", kOptional}, {"capacity", kOptional}});
  r.duration_us(eq, "window_s", p, o.equilibrium.window_us, 1e6);
  r.integer(eq, "min_samples", p, o.equilibrium.min_samples, 4, 1'000'000);
  r.number(eq, "max_speed", p, o.equilibrium.max_speed_mps, Bound::kPositive);
  r.number(eq, "max_angular_rate", p, o.equilibrium.max_angular_rate_radps, Bound::kPositive);
  r.number(eq, "max_tension_std", p, o.equilibrium.max_tension_std_n, Bound::kPositive);
  int capacity = static_cast<int>(o.equilibrium_capacity);
  r.integer(eq, "capacity", p, capacity, 2, 10'000'000);
  o.equilibrium_capacity = static_cast<std::size_t>(capacity);

  const toml::table& solver = reader.table(root, "solver", "", kOptional);
  reader.check_keys(solver, "solver",
                    {{"cable_model", kOptional}, {"huber_width", kOptional}, {"max_iterations", kOptional}});
  if (const int model = r.choice(solver, "cable_model", "solver", {"catenary", "rigid"}); model >= 0) {
    c.solver.cable_model = model == 0 ? CableModelKind::kCatenary : CableModelKind::kRigid;
  }
  r.number(solver, "huber_width", "solver", c.solver.huber_width, Bound::kNonNegative);
  r.integer(solver, "max_iterations", "solver", c.solver.max_iterations, 1, 100'000);

  calibration::ValidationLimits& v = o.validation;
  const toml::table& validation = reader.table(root, "validation", "", kOptional);
  p = "validation";
  reader.check_keys(validation, p,
                    {{"accept_max_iterations", kOptional}, {"min_samples", kOptional},
                     {"max_rms_encoder_sigmas", kOptional}, {"max_rms_force_sigmas", kOptional},
                     {"max_anchor_sigma", kOptional}, {"max_offset_sigma", kOptional},
                     {"max_anchor_change", kOptional}});
  r.boolean(validation, "accept_max_iterations", p, v.accept_max_iterations);
  r.integer(validation, "min_samples", p, v.min_samples, 1, 100'000);
  r.number(validation, "max_rms_encoder_sigmas", p, v.max_rms_encoder_sigmas, Bound::kPositive);
  r.number(validation, "max_rms_force_sigmas", p, v.max_rms_force_sigmas, Bound::kPositive);
  r.number(validation, "max_anchor_sigma", p, v.max_anchor_sigma_m, Bound::kPositive);
  r.number(validation, "max_offset_sigma", p, v.max_offset_sigma_m, Bound::kPositive);
  r.number(validation, "max_anchor_change", p, v.max_anchor_change_m, Bound::kNonNegative);
}

DaemonConfig read_config(TomlReader& reader, const toml::table& root) {
  DaemonConfig c = default_daemon_config();
  reader.check_keys(root, "",
                    {{"robot", Presence::kRequired}, {"store", kOptional}, {"control", kOptional},
                     {"loop", kOptional}, {"winches", kOptional}, {"load_cell", kOptional}, {"pose", kOptional},
                     {"button", kOptional}, {"limits", kOptional}, {"waypoints", kOptional},
                     {"equilibrium", kOptional}, {"solver", kOptional}, {"validation", kOptional}});
  c.robot_path = reader.string(root, "robot", "");
  ConfigReader r(reader, c.key_lines);
  read_io(reader, r, root, c);
  read_calibration(reader, r, root, c);
  return c;
}

}  // namespace

DaemonConfig default_daemon_config() {
  DaemonConfig c;
  for (int i = 0; i < kCableCount; ++i) c.winches.winches.push_back(WinchNodes{i + 1, i + 11, 1e-5, 1e-5});
  // The example's values where they differ from the library defaults.
  c.calibrator.planner.margin_m = 20.0;
  c.calibrator.planner.z_max_m = 35.0;
  c.calibrator.planner.max_tension_n = 3000.0;
  return c;
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
