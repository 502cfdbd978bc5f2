#include "src/daemon/config_checks.h"

#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <string_view>

#include "src/calibration/message_text.h"
#include "src/calibration/waypoint_planner.h"

namespace cdpr::daemon {
namespace {

using calibration::significant;

int line_of(const DaemonConfig& config, std::string_view key) {
  const auto found = config.key_lines.find(key);
  return found == config.key_lines.end() ? 0 : found->second;
}

FormatError problem(const DaemonConfig& config, std::string_view key, std::string reason) {
  return FormatError{config.source, line_of(config, key), std::string(key), std::move(reason)};
}

// `low` must be below `high`; the refusal names whichever of the two the
// file set (the later one when both), since that is the one to look at.
std::optional<FormatError> ordered(const DaemonConfig& config, std::string_view low_key, double low,
                                   std::string_view high_key, double high, std::string_view unit) {
  if (low < high) return std::nullopt;
  const std::string_view blamed = line_of(config, high_key) >= line_of(config, low_key) ? high_key : low_key;
  return problem(config, blamed,
                 std::string(low_key) + " (" + significant(low) + " " + std::string(unit) + ") must be below " +
                     std::string(high_key) + " (" + significant(high) + " " + std::string(unit) + ")");
}

// `value` must be at least `factor` x `other`; blamed as `ordered` does.
std::optional<FormatError> at_least(const DaemonConfig& config, std::string_view key, double value, double factor,
                                    std::string_view other_key, double other, std::string_view unit,
                                    std::string_view why) {
  if (value >= factor * other) return std::nullopt;
  const std::string_view blamed = line_of(config, other_key) > line_of(config, key) ? other_key : key;
  const std::string times = factor == 1.0 ? "" : significant(factor) + " x ";
  return problem(config, blamed,
                 std::string(key) + " (" + significant(value) + " " + std::string(unit) + ") must be at least " +
                     times + std::string(other_key) + " (" + significant(other) + " " + std::string(unit) +
                     "): " + std::string(why));
}

double ms(hal::TimeUs us) { return 1e-3 * static_cast<double>(us); }

bool is_port(std::string_view digits) {
  int port = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), port);
  return error == std::errc() && end == digits.data() + digits.size() && port >= 1 && port <= 65535;
}

// "<host>:<port>" with a non-empty host and a port in 1..65535.
bool is_host_and_port(std::string_view text) {
  const std::size_t colon = text.rfind(':');
  return colon != std::string_view::npos && colon > 0 && is_port(text.substr(colon + 1));
}

// A path that fits a Unix socket address (sun_path, with its terminating NUL).
bool is_socket_path(std::string_view path) { return !path.empty() && path.size() < sizeof(sockaddr_un{}.sun_path); }

// A network interface name as the kernel takes it (IFNAMSIZ - 1 bytes, no '/' or blanks).
bool is_interface_name(std::string_view name) {
  return !name.empty() && name.size() <= 15 &&
         std::none_of(name.begin(), name.end(), [](char c) { return c == '/' || c == ' ' || c == '\t' || c == ':'; });
}

// The transports each endpoint key accepts: prefix and the form of the rest.
struct Transport {
  std::string_view prefix;
  bool (*valid)(std::string_view rest);
  std::string_view form;
};

std::optional<FormatError> endpoint(const DaemonConfig& config, std::string_view key, const std::string& value,
                                    std::initializer_list<Transport> transports) {
  std::string forms;
  for (const Transport& t : transports) {
    if (value.starts_with(t.prefix) && t.valid(std::string_view(value).substr(t.prefix.size()))) return std::nullopt;
    forms += (forms.empty() ? "\"" : " or \"") + std::string(t.prefix) + std::string(t.form) + "\"";
  }
  return problem(config, key, "\"" + value + "\" is not an endpoint: expected " + forms);
}

constexpr Transport kUnix{"unix:", is_socket_path, "<path> (at most 107 bytes)"};
constexpr Transport kTcp{"tcp:", is_host_and_port, "<host>:<port>"};
constexpr Transport kSocketCan{"socketcan:", is_interface_name, "<interface> (e.g. socketcan:can0)"};
constexpr Transport kRtu{"rtu:", [](std::string_view device) { return !device.empty(); }, "<serial device>"};

std::optional<FormatError> check_endpoints(const DaemonConfig& c) {
  if (auto p = endpoint(c, "winches.endpoint", c.winches.endpoint, {kSocketCan, kUnix})) return p;
  if (auto p = endpoint(c, "load_cell.endpoint", c.load_cell.endpoint, {kTcp, kRtu})) return p;
  if (auto p = endpoint(c, "pose.endpoint", c.pose.endpoint, {kUnix, kTcp})) return p;
  if (!is_socket_path(c.control_socket)) {
    return problem(c, "control.socket",
                   "\"" + c.control_socket + "\" is longer than a Unix socket path may be (107 bytes)");
  }
  return std::nullopt;
}

std::optional<FormatError> check_limits(const DaemonConfig& c) {
  const calibration::CalibratorOptions& o = c.calibrator;
  const calibration::PlannerOptions& w = o.planner;
  if (auto p = ordered(c, "limits.min_tension", o.monitor.min_tension_n, "limits.max_tension", o.monitor.max_tension_n,
                       "N")) {
    return p;
  }
  if (auto p = ordered(c, "waypoints.min_tension", w.min_tension_n, "waypoints.max_tension", w.max_tension_n, "N")) {
    return p;
  }
  if (auto p = ordered(c, "waypoints.z_min", w.z_min_m, "waypoints.z_max", w.z_max_m, "m")) return p;
  if (auto p = ordered(c, "waypoints.min_payout", w.min_payout_m, "waypoints.max_payout", w.max_payout_m, "m")) {
    return p;
  }
  // The monitor checks the reference cable during the run: a plan that
  // leaves its band would stop the run at that waypoint as a fault.
  if (w.min_tension_n < o.monitor.min_tension_n) {
    return problem(c, "waypoints.min_tension",
                   significant(w.min_tension_n) + " N is below limits.min_tension (" +
                       significant(o.monitor.min_tension_n) + " N): a planned waypoint would be a fault");
  }
  if (w.max_tension_n > o.monitor.max_tension_n) {
    return problem(c, "waypoints.max_tension",
                   significant(w.max_tension_n) + " N is above limits.max_tension (" +
                       significant(o.monitor.max_tension_n) + " N): a planned waypoint would be a fault");
  }
  return std::nullopt;
}

// The unit identifiers a transport takes: on a serial line 0 is broadcast
// (nobody answers) and 248-255 are reserved; a Modbus TCP device addressed
// directly takes 0 or 255 (libmodbus 3.1 refuses 248-254).
std::optional<FormatError> check_load_cell(const DaemonConfig& c) {
  const LoadCellConfig& cell = c.load_cell;
  const std::string got = ", got " + std::to_string(cell.slave_id);
  if (cell.endpoint.starts_with("rtu:") && (cell.slave_id < 1 || cell.slave_id > 247)) {
    return problem(c, "load_cell.slave_id", "must be in 1..247 on a serial line (0 is broadcast)" + got);
  }
  if (!cell.endpoint.starts_with("rtu:") && cell.slave_id > 247 && cell.slave_id < 255) {
    return problem(c, "load_cell.slave_id", "on TCP must be 0..247 or 255" + got);
  }
  const drivers::modbus::LoadCellMap& m = cell.map;
  if (m.status_address >= 0 && m.status_address >= m.value_address &&
      m.status_address < m.value_address + drivers::modbus::value_register_count(m.value_type)) {
    return problem(c, "load_cell.status_address",
                   std::to_string(m.status_address) + " overlaps the value's registers (from load_cell.value_address " +
                       std::to_string(m.value_address) + ")");
  }
  return std::nullopt;
}

std::optional<FormatError> check_counts_and_times(const DaemonConfig& c) {
  const calibration::CalibratorOptions& o = c.calibrator;
  // The waypoints a run can sample at most: the fixed plan's, or the sequential strategy's maximum.
  const bool sequential = o.strategy == calibration::WaypointStrategy::kSequential;
  const std::string count_key = sequential ? "waypoints.max_count" : "waypoints.count";
  const int count = sequential ? o.sequential.max_count : o.planner.waypoint_count;
  if (o.validation.min_samples > count) {
    return problem(c, line_of(c, "validation.min_samples") > 0 ? "validation.min_samples" : count_key,
                   "validation.min_samples (" + std::to_string(o.validation.min_samples) + ") is more than " +
                       count_key + " (" + std::to_string(count) + "): no run could be accepted");
  }
  if (static_cast<std::size_t>(o.equilibrium.min_samples) > o.equilibrium_capacity) {
    return problem(c, "equilibrium.min_samples",
                   std::to_string(o.equilibrium.min_samples) + " is more than equilibrium.capacity (" +
                       std::to_string(o.equilibrium_capacity) + "): no waypoint could settle");
  }
  if (o.settle_timeout_us <= o.equilibrium.window_us) {
    return problem(c, "limits.settle_timeout_s",
                   "must be longer than equilibrium.window_s (" +
                       significant(1e-6 * static_cast<double>(o.equilibrium.window_us)) +
                       " s): every waypoint would be skipped");
  }
  if (o.monitor.pose_stale_us <= c.loop_period_us) {
    return problem(c, "limits.pose_stale_ms",
                   "must be longer than loop.period_ms (" +
                       significant(1e-3 * static_cast<double>(c.loop_period_us)) + " ms): every pose would be stale");
  }
  return std::nullopt;
}

// CiA 301 heartbeat consumers: a window of 1.5 producer periods (the
// docs' rule) takes one late heartbeat without declaring the node lost.
std::optional<FormatError> check_heartbeats(const DaemonConfig& c) {
  const WinchesConfig& w = c.winches;
  if (auto p = at_least(c, "winches.drive.consumer_heartbeat_ms", ms(w.drive.consumer_heartbeat_us), 1.5,
                        "winches.master_heartbeat_ms", ms(w.master_heartbeat_us), "ms",
                        "the drives would stop between two of the daemon's heartbeats")) {
    return p;
  }
  if (auto p = at_least(c, "winches.heartbeat_timeout_ms", ms(w.heartbeat_timeout_us), 1.5,
                        "winches.drive.heartbeat_producer_ms", ms(w.drive.heartbeat_producer_us), "ms",
                        "a drive would be lost between two of its heartbeats")) {
    return p;
  }
  return at_least(c, "winches.heartbeat_timeout_ms", ms(w.heartbeat_timeout_us), 1.5,
                  "winches.encoder.heartbeat_producer_ms", ms(w.encoder.heartbeat_producer_us), "ms",
                  "an encoder would be lost between two of its heartbeats");
}

// The stop ramps and speeds of the drives against each other and the jump check.
std::optional<FormatError> check_motion(const DaemonConfig& c) {
  const drivers::can::DriveDescription& d = c.winches.drive;
  if (auto p = at_least(c, "winches.drive.quick_stop_deceleration_mps2", d.quick_stop_deceleration_mps2, 1.0,
                        "winches.drive.profile_deceleration_mps2", d.profile_deceleration_mps2, "m/s^2",
                        "a quick stop (abort, lost heartbeat) must not stop later than a planned stop")) {
    return p;
  }
  if (d.profile_velocity_mps >= c.winches.max_speed_mps) {
    return problem(c, line_of(c, "winches.drive.profile_velocity_mps") > line_of(c, "winches.max_speed_mps")
                          ? "winches.drive.profile_velocity_mps"
                          : "winches.max_speed_mps",
                   "winches.drive.profile_velocity_mps (" + significant(d.profile_velocity_mps) +
                       " m/s) must be below winches.max_speed_mps (" + significant(c.winches.max_speed_mps) +
                       " m/s): the encoder jump check would stop every move");
  }
  return std::nullopt;
}


}  // namespace

std::optional<FormatError> check_cross_keys(const DaemonConfig& config) {
  if (auto p = check_endpoints(config)) return p;
  if (auto p = check_load_cell(config)) return p;
  if (auto p = check_limits(config)) return p;
  if (auto p = check_heartbeats(config)) return p;
  if (auto p = check_motion(config)) return p;
  return check_counts_and_times(config);
}

std::optional<FormatError> check_config_against_robot(const DaemonConfig& config, const Robot& robot) {
  const calibration::PlannerOptions& w = config.calibrator.planner;
  if (std::string reason = calibration::check_planner_options(robot, w); !reason.empty()) {
    const bool workspace = reason.find("workspace") != std::string::npos;
    return problem(config, workspace ? "waypoints.margin" : "waypoints", reason + " of robot " + robot.name);
  }
  double lowest_anchor_m = robot.winches.front().anchor_world.z();
  for (const auto& winch : robot.winches) lowest_anchor_m = std::min(lowest_anchor_m, winch.anchor_world.z());
  if (w.z_max_m >= lowest_anchor_m) {
    return problem(config, "waypoints.z_max",
                   significant(w.z_max_m) + " m is not below the lowest anchor of robot " + robot.name + " (" +
                       significant(lowest_anchor_m) + " m): the platform hangs below its pulleys");
  }
  return std::nullopt;
}

}  // namespace cdpr::daemon

namespace cdpr::daemon {

std::optional<FormatError> check_config_paths(const DaemonConfig& config) {
  struct stat info {};
  if (stat(config.robot_path.c_str(), &info) != 0 || access(config.robot_path.c_str(), R_OK) != 0) {
    return problem(config, "robot", "cannot read \"" + config.robot_path + "\": " + std::strerror(errno));
  }
  if (!S_ISREG(info.st_mode)) return problem(config, "robot", "\"" + config.robot_path + "\" is not a file");
  const std::string& dir = config.store.state_dir;
  if (stat(dir.c_str(), &info) == 0 && !S_ISDIR(info.st_mode)) {
    return problem(config, "store.state_dir", "\"" + dir + "\" is not a directory");
  }
  return std::nullopt;
}

}  // namespace cdpr::daemon
