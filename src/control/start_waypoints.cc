#include "src/control/start_waypoints.h"

#include <filesystem>
#include <system_error>

#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "src/formats/waypoints_csv.h"
#include "src/store/run_history.h"

namespace cdpr::control {
namespace {

// A regular file small enough to read on the loop thread (not a FIFO or a
// device, which could block it); the reason when not.
std::string unreadable_reason(const std::string& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error && !std::filesystem::exists(status)) {
    // The usual cause: a file the daemon's unit cannot see (systemd/cdpr-calibd.service).
    return path + ": " + error.message() +
           " (the daemon reads it as its own user in its sandbox, which hides /home and /root and has its own "
           "/tmp and /var/tmp)";
  }
  if (error) return path + ": " + error.message();
  if (!std::filesystem::is_regular_file(status)) return path + ": not a regular file";
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (error) return path + ": " + error.message();
  if (bytes > kMaxWaypointsFileBytes) {
    return path + ": " + std::to_string(bytes) + " bytes, a waypoints file has at most " +
           std::to_string(kMaxWaypointsFileBytes);
  }
  return {};
}

// The rows of kept run `run` for the new run to begin with.
Expected<std::vector<Sample>, std::string> earlier_samples(int run, const std::string& history_dir,
                                                           const Robot& robot) {
  const store::RunHistory history(history_dir);
  const std::optional<store::RunEntry> entry = history.find(run);
  if (!entry || entry->run != run) {
    return Unexpected{"no such run: " + store::RunHistory::entry_name(run) + " is not in " + history_dir};
  }
  const std::string name = store::RunHistory::entry_name(run);
  if (!entry->valid) return Unexpected{name + " cannot be appended to: its log is unreadable: " + entry->problem};
  const std::string samples_path = entry->path + "/" + store::RunHistory::kSamplesName;
  std::error_code error;
  if (!std::filesystem::exists(samples_path, error)) {
    return Unexpected{name + " kept no samples (it ended before its first waypoint)"};
  }
  const auto measured_on = formats::read_robot_toml(entry->path + "/" + store::RunHistory::kRobotName);
  if (!measured_on) return Unexpected{name + " cannot be appended to: " + measured_on.error().message()};
  if (measured_on->name != robot.name) {
    return Unexpected{name + " was measured on robot '" + measured_on->name + "', this daemon calibrates '" +
                      robot.name + "'"};
  }
  auto samples = formats::read_samples_csv(samples_path, robot.cable_count());
  if (!samples) return Unexpected{name + " cannot be appended to: " + samples.error().message()};
  if (samples->empty()) return Unexpected{name + " has no samples to append to"};
  return std::move(*samples);
}

}  // namespace

Expected<calibration::GivenWaypoints, std::string> load_start_waypoints(const std::string& path, int run,
                                                                        const std::string& history_dir,
                                                                        const Robot& robot) {
  if (const std::string why = unreadable_reason(path); !why.empty()) return Unexpected{why};
  const auto waypoints = formats::read_waypoints_csv(path);
  if (!waypoints) return Unexpected{waypoints.error().message()};
  calibration::GivenWaypoints given;
  given.source = path;
  for (const formats::PlannedWaypoint& w : *waypoints) given.positions_world.push_back(w.position_world);
  if (run > 0) {
    auto samples = earlier_samples(run, history_dir, robot);
    if (!samples) return Unexpected{samples.error()};
    given.earlier_samples = std::move(*samples);
    given.earlier_run = run;
  }
  return given;
}

}  // namespace cdpr::control
