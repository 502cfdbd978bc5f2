#include "src/daemon/daemon_config.h"

#include <optional>

#include "src/daemon/config_checks.h"
#include "src/daemon/config_table.h"
#include "src/daemon/device_config_tables.h"
#include "src/formats/text_file.h"
#include "src/formats/toml_reader.h"

namespace cdpr::daemon {
namespace {

using calibration::CalibratorOptions;
using calibration::PlannerOptions;
using calibration::ValidationLimits;
using drivers::can::CanWinchConfig;
using formats::TomlReader;
constexpr TimeUnit kS = TimeUnit::kSeconds;

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

// ---- The tables, in the order of the file (the devices' in device_config_tables.cc) ----

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

Table<HistoryConfig> history_table() {
  Table<HistoryConfig> t("history");
  t.number("budget_mb", &HistoryConfig::budget_mb, 200.0, kNonNegative, "MB",
           "every run's data is kept in history/run-*; beyond this the oldest go, never the current "
           "calibration's run, a pending fit's nor the last run");
  t.boolean("model_check", &HistoryConfig::model_check, true,
            "after each solve, check the model on the run's data (cdpr-calib diagnose) and record the verdict");
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

// A [waypoints] row's field: a member of the planner's options.
template <class V>
auto planner(V PlannerOptions::*member) {
  return [member](auto& o) -> auto& { return o.planner.*member; };
}

Table<CalibratorOptions> waypoints_table() {
  Table<CalibratorOptions> t("waypoints");
  t.choice("strategy", &CalibratorOptions::strategy,
           {{"spread", calibration::WaypointStrategy::kSpread},
            {"informative", calibration::WaypointStrategy::kInformative},
            {"sequential", calibration::WaypointStrategy::kSequential}},
           calibration::WaypointStrategy::kSpread,
           "a fixed plan of `count` waypoints evenly over the feasible candidates, or those that determine anchors "
           "and offsets best; or sequential: re-solve after each sample, pick the next waypoint by the variance it "
           "removes per second of robot time, stop at the targets");
  t.choice("order", planner(&PlannerOptions::order),
           {{"tour", calibration::WaypointOrder::kTour}, {"selection", calibration::WaypointOrder::kSelection}},
           calibration::WaypointOrder::kTour,
           "spread, informative: driven as a short tour from where the platform starts, or in the order selected");
  t.integer("count", planner(&PlannerOptions::waypoint_count), 35, {1, 10'000}, "",
            "static poses per calibration (spread, informative)");
  t.number("target_anchor_sigma", [](auto& o) -> auto& { return o.sequential.target_anchor_sigma_m; }, 0.02,
           kPositive, "m", "sequential: stop when every anchor axis 1-sigma is at most this");
  t.number("target_offset_sigma", [](auto& o) -> auto& { return o.sequential.target_offset_sigma_m; }, 0.02,
           kPositive, "m", "sequential: ... and every encoder offset 1-sigma at most this");
  t.integer("max_count", [](auto& o) -> auto& { return o.sequential.max_count; }, 35, {1, 10'000}, "",
            "sequential: stop after this many samples whatever the sigmas");
  t.number("margin", planner(&PlannerOptions::margin_m), 20.0, kNonNegative, "m",
           "inset from the anchors' horizontal footprint");
  t.number("z_min", planner(&PlannerOptions::z_min_m), 5.0, kAnyNumber, "m", "world height band of the platform origin");
  t.number("z_max", planner(&PlannerOptions::z_max_m), 35.0, kAnyNumber, "m", "");
  t.integer("grid_xy", planner(&PlannerOptions::grid_xy), 8, {1, 1000}, "", "candidate grid per horizontal axis");
  t.integer("grid_z", planner(&PlannerOptions::grid_z), 4, {1, 1000}, "", "candidate grid along z");
  t.number("jitter", planner(&PlannerOptions::jitter_fraction), 0.3, {0.0, 0.5, false, true}, "",
           "candidate jitter, fraction of the grid step");
  t.integer("seed", planner(&PlannerOptions::seed), 1, {0, 2'147'483'647}, "", "same seed, same plan");
  t.number("min_tension", planner(&PlannerOptions::min_tension_n), 20.0, kNonNegative, "N",
           "every cable at every waypoint (catenary statics)");
  t.number("max_tension", planner(&PlannerOptions::max_tension_n), 3000.0, kPositive, "N", "");
  t.number("min_payout", planner(&PlannerOptions::min_payout_m), -1e9, kAnyNumber, "m",
           "winch travel limits in encoder units");
  t.number("max_payout", planner(&PlannerOptions::max_payout_m), 1e9, kAnyNumber, "m", "");
  t.number("max_sag_excess", planner(&PlannerOptions::max_sag_excess), 0.02, kPositive, "",
           "(arc length - chord) / chord of every cable at most this");
  return t;
}

Table<CalibratorOptions> equilibrium_table() {
  Table<CalibratorOptions> t("equilibrium");
  t.duration("window_s", [](auto& o) -> auto& { return o.equilibrium.window_us; }, 2.0, kS,
             "rest window averaged into one sample row, in the pose source's own time");
  t.integer("min_samples", [](auto& o) -> auto& { return o.equilibrium.min_samples; }, 100, {4, 1'000'000}, "",
            "poses in the window; it reaches further back to hold them (100: the 2 s window at the 50 Hz loop)");
  t.number("max_speed", [](auto& o) -> auto& { return o.equilibrium.max_speed_mps; }, 0.002, kPositive, "m/s",
           "platform speed");
  t.number("max_angular_rate", [](auto& o) -> auto& { return o.equilibrium.max_angular_rate_radps; }, 0.002,
           kPositive, "rad/s", "");
  t.number("max_tension_std", [](auto& o) -> auto& { return o.equilibrium.max_tension_std_n; }, 10.0, kPositive,
           "N", "load-cell standard deviation over the window");
  t.boolean("estimate_sway", [](auto& o) -> auto& { return o.equilibrium.estimate_sway; }, true,
            "a platform still swaying is fitted as a decaying oscillation about its rest, and the fitted rest is "
            "the sample; false: wait until it is at rest");
  t.duration("sway_window_s", [](auto& o) -> auto& { return o.equilibrium.sway_window_us; }, 40.0, kS,
             "the sway fit's window in the pose source's own time, >= 1.5 sway periods; also the return test's: "
             "nothing settles before it is covered (at least twice window_s)");
  t.number("max_sway_misfit", [](auto& o) -> auto& { return o.equilibrium.max_sway_misfit; }, 1.5, kPositive, "",
           "largest residual / noise variance of a sway fit: more is not one sway about a rest, and is waited out");
  t.integer("capacity", &CalibratorOptions::equilibrium_capacity,
            static_cast<std::int64_t>(calibration::kEquilibriumCapacity), {2, 10'000'000}, "",
            "ring size, >= the longer of window_s and sway_window_s x pose rate with margin");
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
  s.push_back(bind(history_table(), [](auto& c) -> auto& { return c.history; }));
  s.push_back(bind(control_table(), [](auto& c) -> auto& { return c; }));
  s.push_back(bind(loop_table(), [](auto& c) -> auto& { return c; }));
  s.push_back(bind(winches_table(), [](auto& c) -> auto& { return c.winches; }));
  s.push_back(bind(drive_table(), [](auto& c) -> auto& { return c.winches.drive; }));
  s.push_back(bind(encoder_table(), [](auto& c) -> auto& { return c.winches.encoder; }));
  s.push_back(bind(mechanics_table(), [](auto& c) -> auto& { return c.winches.mechanics; }));
  s.push_back(bind_cables(winch_table()));
  s.push_back(bind(load_cell_table(), [](auto& c) -> auto& { return c.load_cell; }));
  s.push_back(bind(pose_table(), [](auto& c) -> auto& { return c.pose; }));
  s.push_back(bind(button_table(), [](auto& c) -> auto& { return c.button; }));
  s.push_back(bind(limits_table(), [](auto& c) -> auto& { return c.calibrator; }));
  s.push_back(bind(waypoints_table(), [](auto& c) -> auto& { return c.calibrator; }));
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

// Settings one key gives to two modules: the planner's payout range is
// also the drives' software position limits (0x607D, with [winches]
// position_limit_margin_m around it).
void share_keys(DaemonConfig& c) {
  c.winches.min_payout_m = c.calibrator.planner.min_payout_m;
  c.winches.max_payout_m = c.calibrator.planner.max_payout_m;
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
  share_keys(c);
  return c;
}

}  // namespace

DaemonConfig default_daemon_config() {
  DaemonConfig c;
  for (const Section& section : sections()) section.set_defaults(c);
  share_keys(c);
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
