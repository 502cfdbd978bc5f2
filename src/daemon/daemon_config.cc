#include "src/daemon/daemon_config.h"

#include <algorithm>
#include <optional>

#include "src/daemon/config_checks.h"
#include "src/daemon/config_table.h"
#include "src/daemon/device_config_tables.h"
#include "src/daemon/operation_config_table.h"
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
  t.strings("unsafe_ok", &DaemonConfig::unsafe_ok,
            "keys allowed a value that defeats a safety function (the Range column says which values), e.g. "
            "[\"winches.drive.abort_connection_option\"]; the daemon names them at start");
  return t;
}

Table<store::StoreOptions> store_table() {
  Table<store::StoreOptions> t("store");
  t.string("state_dir", &store::StoreOptions::state_dir, "/var/lib/cdpr-calib",
           "state directory: calibration.toml, history/, pending/, the run marker and the lock");
  t.integer("history_depth", &store::StoreOptions::history_depth, 10, {0, 1000}, "",
            "previous calibrations kept besides the current one")
      .why("each is a few kB; more than 1000 is a typo");
  return t;
}

Table<HistoryConfig> history_table() {
  Table<HistoryConfig> t("history");
  t.number("budget_mb", &HistoryConfig::budget_mb, 200.0, {0.0, 1e6}, "MB",
           "every run's data is kept in history/run-*; beyond this the oldest go, never the current "
           "calibration's run, a pending fit's nor the last run")
      .why("more than 1 TB of run data is a typo");
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
  t.duration("period_ms", &DaemonConfig::loop_period_us, 20, kMs, {1, 100},
             "state-machine step; the watchdog is pinged every step")
      .why("the tension and pose checks run once a step: beyond 100 ms a 2 m/s cable runs 0.2 m between two");
  return t;
}

Table<CalibratorOptions> limits_table() {
  Table<CalibratorOptions> t("limits");
  t.number("min_tension", [](auto& o) -> auto& { return o.monitor.min_tension_n; }, 20.0, {0.0, 1e5}, "N",
           "reference cable (load cell), checked every step while the winches may move")
      .why("below it the run stops (slack cable); 100 kN is beyond any cable of a CDPR");
  t.number("max_tension", [](auto& o) -> auto& { return o.monitor.max_tension_n; }, 5000.0, {0.0, 1e5, true}, "N", "")
      .why("above it the run stops (overload); above 100 kN (10 t) the stop would never fire on a CDPR cable");
  t.duration("pose_stale_ms", [](auto& o) -> auto& { return o.monitor.pose_stale_us; }, 500, kMs, {1, 60'000},
             "oldest acceptable pose sample")
      .why("the winches move on a pose at most this old")
      .unsafe_unless_acknowledged("> 1000", [](const CalibratorOptions& o) -> std::string {
        if (o.monitor.pose_stale_us <= 1'000'000) return "";
        return "longer than 1000 ms: the winches would move on (2 m at 2 m/s) with the localization lost";
      });
  t.integer("max_consecutive_load_cell_errors",
            [](auto& o) -> auto& { return o.monitor.max_consecutive_load_cell_errors; }, 3, {0, 100}, "",
            "failed reads tolerated in a row")
      .why("each is a poll without a tension check; load_cell.fault_timeout_ms bounds them in time too");
  t.duration("first_contact_timeout_s", &CalibratorOptions::first_contact_timeout_us, 3.0, kS, {0.1, 600},
             "preflight waits this long for every node's first heartbeat, the first pose and load-cell reading")
      .why("nothing moves while it waits; beyond 10 minutes a missing device goes unreported");
  t.duration("enable_timeout_s", &CalibratorOptions::enable_timeout_us, 5.0, kS, {0.1, 600},
             "drives must reach \"operation enabled\" within this")
      .why("nothing moves while it waits; beyond 10 minutes a drive that never enables goes unreported");
  t.duration("move_timeout_s", &CalibratorOptions::move_timeout_us, 600.0, kS, {1, 3600},
             "winches must reach a waypoint within this (else a fault)")
      .why("a winch that stalls is a fault after this; an hour covers a 250 m move at any profile speed");
  t.duration("settle_timeout_s", &CalibratorOptions::settle_timeout_us, 60.0, kS, {0.1, 3600},
             "no equilibrium within this: the waypoint is skipped")
      .why("the winches hold still while it waits; beyond an hour a swaying platform stalls the run");
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
            "static poses per calibration (spread, informative)")
      .why("each is a move and a settle: 10 000 is days of robot time");
  t.number("target_anchor_sigma", [](auto& o) -> auto& { return o.sequential.target_anchor_sigma_m; }, 0.02,
           {0.0, 1.0, true}, "m", "sequential: stop when every anchor axis 1-sigma is at most this")
      .why("a target above 1 m calibrates nothing");
  t.number("target_offset_sigma", [](auto& o) -> auto& { return o.sequential.target_offset_sigma_m; }, 0.02,
           {0.0, 1.0, true}, "m", "sequential: ... and every encoder offset 1-sigma at most this")
      .why("a target above 1 m calibrates nothing");
  t.integer("max_count", [](auto& o) -> auto& { return o.sequential.max_count; }, 35, {1, 10'000}, "",
            "sequential: stop after this many samples whatever the sigmas")
      .why("each is a move and a settle: 10 000 is days of robot time");
  t.number("margin", planner(&PlannerOptions::margin_m), 20.0, {0.0, 1000.0}, "m",
           "inset from the anchors' horizontal footprint")
      .why("no CDPR is 2 km wide; the robot check refuses a margin that leaves no workspace");
  t.number("z_min", planner(&PlannerOptions::z_min_m), 5.0, {-1000.0, 1000.0}, "m",
           "world height band of the platform origin")
      .why("world heights of a CDPR; the robot check keeps the band below the anchors");
  t.number("z_max", planner(&PlannerOptions::z_max_m), 35.0, {-1000.0, 1000.0}, "m", "")
      .why("world heights of a CDPR; the robot check keeps the band below the anchors");
  t.integer("grid_xy", planner(&PlannerOptions::grid_xy), 8, {1, 1000}, "", "candidate grid per horizontal axis")
      .why("grid_xy^2 x grid_z equilibrium solves at plan time");
  t.integer("grid_z", planner(&PlannerOptions::grid_z), 4, {1, 1000}, "", "candidate grid along z")
      .why("grid_xy^2 x grid_z equilibrium solves at plan time");
  t.number("jitter", planner(&PlannerOptions::jitter_fraction), 0.3, {0.0, 0.5, false, true}, "",
           "candidate jitter, fraction of the grid step")
      .why("half a step or more lets neighbouring candidates swap");
  t.integer("seed", planner(&PlannerOptions::seed), 1, {0, 2'147'483'647}, "", "same seed, same plan")
      .why("any non-negative 32-bit seed");
  t.number("min_tension", planner(&PlannerOptions::min_tension_n), 20.0, {0.0, 1e5}, "N",
           "every cable at every waypoint (catenary statics)")
      .why("as limits.min_tension, which the plan must keep to");
  t.number("max_tension", planner(&PlannerOptions::max_tension_n), 3000.0, {0.0, 1e5, true}, "N", "")
      .why("as limits.max_tension, which the plan must keep to");
  t.number("min_payout", planner(&PlannerOptions::min_payout_m), -1e9, {-1e9, 1e9}, "m",
           "winch travel limits in encoder units")
      .why("+-1e9 m (the defaults) is no limit");
  t.number("max_payout", planner(&PlannerOptions::max_payout_m), 1e9, {-1e9, 1e9}, "m", "")
      .why("+-1e9 m (the defaults) is no limit");
  t.number("max_sag_excess", planner(&PlannerOptions::max_sag_excess), 0.02, {0.0, 1.0, true}, "",
           "(arc length - chord) / chord of every cable at most this")
      .why("1 is a cable twice as long as its chord: no longer a cable robot");
  return t;
}

Table<CalibratorOptions> equilibrium_table() {
  Table<CalibratorOptions> t("equilibrium");
  t.duration("window_s", [](auto& o) -> auto& { return o.equilibrium.window_us; }, 2.0, kS, {0.01, 600},
             "rest window averaged into one sample row, in the pose source's own time")
      .why("beyond 10 minutes per waypoint the run never ends");
  t.integer("min_samples", [](auto& o) -> auto& { return o.equilibrium.min_samples; }, 100, {4, 1'000'000}, "",
            "poses in the window; it reaches further back to hold them (100: the 2 s window at the 50 Hz loop)")
      .why("at least 4 for a mean and a spread; equilibrium.capacity bounds it");
  t.number("max_speed", [](auto& o) -> auto& { return o.equilibrium.max_speed_mps; }, 0.002, {0.0, 1.0, true},
           "m/s", "platform speed")
      .why("a platform at 1 m/s is not at rest");
  t.number("max_angular_rate", [](auto& o) -> auto& { return o.equilibrium.max_angular_rate_radps; }, 0.002,
           {0.0, 1.0, true}, "rad/s", "")
      .why("a platform turning at 1 rad/s is not at rest");
  t.number("max_tension_std", [](auto& o) -> auto& { return o.equilibrium.max_tension_std_n; }, 10.0,
           {0.0, 1e5, true}, "N", "load-cell standard deviation over the window")
      .why("as limits.max_tension: a spread beyond 100 kN is no rest");
  t.boolean("estimate_sway", [](auto& o) -> auto& { return o.equilibrium.estimate_sway; }, true,
            "a platform still swaying is fitted as a decaying oscillation about its rest, and the fitted rest is "
            "the sample; false: wait until it is at rest");
  t.duration("sway_window_s", [](auto& o) -> auto& { return o.equilibrium.sway_window_us; }, 40.0, kS, {0.1, 3600},
             "the sway fit's window in the pose source's own time, >= 1.5 sway periods; also the return test's: "
             "nothing settles before it is covered (at least twice window_s)")
      .why("beyond an hour per waypoint the run never ends");
  t.number("max_sway_misfit", [](auto& o) -> auto& { return o.equilibrium.max_sway_misfit; }, 1.5,
           {0.0, 1000.0, true}, "",
           "largest residual / noise variance of a sway fit: more is not one sway about a rest, and is waited out")
      .why("a misfit of 1000 noise variances takes anything for a sway");
  t.integer("capacity", &CalibratorOptions::equilibrium_capacity,
            static_cast<std::int64_t>(calibration::kEquilibriumCapacity), {2, 10'000'000}, "",
            "ring size, >= the longer of window_s and sway_window_s x pose rate with margin")
      .why("allocated at start, tens of bytes a pose: 10 million is the memory of a small board");
  return t;
}

Table<CalibrationOptions> solver_table() {
  Table<CalibrationOptions> t("solver");
  t.choice("cable_model", &CalibrationOptions::cable_model,
           {{"catenary", CableModelKind::kCatenary}, {"rigid", CableModelKind::kRigid}}, CableModelKind::kCatenary,
           "");
  t.number("huber_width", &CalibrationOptions::huber_width, 0.0, {0.0, 100.0}, "sigma",
           "robust loss width; 0: none")
      .why("beyond 100 sigmas the loss is quadratic for every residual: 0 says none more plainly");
  t.integer("max_iterations", &CalibrationOptions::max_iterations, 1000, {1, 100'000}, "",
            "stopping early refuses the fit")
      .why("an iteration is one sparse factorization: 100 000 is hours on a small board");
  return t;
}

Table<ValidationLimits> validation_table() {
  Table<ValidationLimits> t("validation");
  t.boolean("accept_max_iterations", &ValidationLimits::accept_max_iterations, false,
            "accept a fit that ran out of iterations");
  t.integer("min_samples", &ValidationLimits::min_samples, 10, {1, 100'000}, "", "settled waypoints needed")
      .why("no more than a run can sample (waypoints.count)");
  t.number("max_rms_encoder_sigmas", &ValidationLimits::max_rms_encoder_sigmas, 3.0, {0.0, 1000.0, true}, "sigma",
           "rms encoder residual, in robot.toml noise.encoder")
      .why("a fit 1000 noise sigmas off its data is no fit");
  t.number("max_rms_force_sigmas", &ValidationLimits::max_rms_force_sigmas, 3.0, {0.0, 1000.0, true}, "sigma",
           "rms force residual, in noise.force")
      .why("a fit 1000 noise sigmas off its data is no fit");
  t.number("max_anchor_sigma", &ValidationLimits::max_anchor_sigma_m, 0.05, {0.0, 10.0, true}, "m",
           "1-sigma per anchor axis")
      .why("an anchor known to 10 m is not calibrated");
  t.number("max_offset_sigma", &ValidationLimits::max_offset_sigma_m, 0.05, {0.0, 10.0, true}, "m",
           "1-sigma per encoder offset")
      .why("an offset known to 10 m is not calibrated");
  t.number("max_anchor_change", &ValidationLimits::max_anchor_change_m, 0.5, {0.0, 100.0}, "m",
           "per anchor, from the previous calibration; 0: not checked")
      .why("an anchor 100 m from where it was is another robot");
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
    table.read(reader, t, table.path(), access(c), c.key_lines, c.unsafe_accepted);
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
      table.read(reader, *tables[i], path, c.winches.winches[i], c.key_lines, c.unsafe_accepted);
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
  s.push_back(bind(operation_table(), [](auto& c) -> auto& { return c.operation; }));
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

// After the values given are checked: a required key that is absent (its
// table's header line, when there is one).
void refuse_missing_keys(TomlReader& reader, const toml::table& root) {
  for (const Section& section : sections()) {
    for (const KeyInfo& key : section.keys) {
      if (reader.failed() || !key.required) continue;
      const toml::table& table = table_at(reader, root, section.path);
      if (table.contains(key.name)) continue;
      const int line = table.source().begin.line > 0 ? TomlReader::line_of(table) : 0;
      reader.fail(line, formats::join_key(section.path, key.name), "missing required key: " + key.meaning);
    }
  }
}

// Each value that defeats a safety function needs its key in unsafe_ok; a
// name there that is no such key is refused (a typo would acknowledge nothing).
void refuse_unacknowledged(TomlReader& reader, const toml::table& root, const DaemonConfig& c) {
  if (reader.failed()) return;
  std::string acknowledgeable;
  for (const Section& section : sections()) {
    for (const KeyInfo& key : section.keys) {
      if (!key.unsafe_when.empty()) acknowledgeable += " \"" + formats::join_key(section.path, key.name) + "\"";
    }
  }
  const toml::node* listed = root.get("unsafe_ok");
  for (const std::string& name : c.unsafe_ok) {
    if (acknowledgeable.find(" \"" + name + "\"") == std::string::npos) {
      return reader.fail(TomlReader::line_of(*listed), "unsafe_ok",
                         "\"" + name + "\" is not a key whose unsafe values can be acknowledged; these are:" +
                             acknowledgeable);
    }
  }
  for (const UnsafeValue& value : c.unsafe_accepted) {
    if (std::find(c.unsafe_ok.begin(), c.unsafe_ok.end(), value.key) == c.unsafe_ok.end()) {
      return reader.fail(value.line, value.key,
                         value.reason + "; to run so all the same, list \"" + value.key + "\" in unsafe_ok");
    }
  }
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
  refuse_missing_keys(reader, root);
  refuse_unacknowledged(reader, root, c);
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
